"""Drawings of the split housings: valid and deterministic PNGs, every bolt hole drawn, a figure
per housing of a real build."""

import struct

import numpy as np
import pytest

from cadgen.machine.model import Bearing, BearingSeat
from cadgen.report.plots.base import _figure
from cadgen.report.plots.housings import (
    _draw_plan,
    _section,
    _section_line,
    housing_figure,
    housing_figure_jobs,
)
from cadgen.solids.split_housing import split_housing

BEARING = Bearing("6001", 12.0, 28.0, 8.0, 5.07, 2.36)
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _seat(shaft, xy, wall, through):
    return BearingSeat(shaft, "box", 1, xy, wall, BEARING, BEARING.outside + 0.0105, through,
                       12.5 if through else 0.0, 100.0, 10.0, 1e5, 5000.0)


#: name: (gear discs (cx, cy, r), seats): a long box with its seats on x (drawn stacked), a
#: squarish one with its seats off one line (side by side), one seat (the section along x)
CASES = {
    "long": ([(0.0, 0.0, 30.0), (70.0, 0.0, 25.0), (120.0, 0.0, 20.0)],
             (_seat("C2", (0.0, 0.0), "floor", True), _seat("C2", (0.0, 0.0), "roof", False),
              _seat("D", (70.0, 0.0), "floor", False), _seat("D", (70.0, 0.0), "roof", False),
              _seat("E", (120.0, 0.0), "floor", False), _seat("E", (120.0, 0.0), "roof", True))),
    "square": ([(0.0, 0.0, 40.0), (60.0, 40.0, 30.0), (60.0, -30.0, 25.0)],
               (_seat("P", (0.0, 0.0), "floor", True), _seat("Q", (60.0, 40.0), "roof", True),
                _seat("R", (60.0, -30.0), "floor", False))),
    "single": ([(0.0, 0.0, 40.0)], (_seat("P", (0.0, 0.0), "floor", True),
                                    _seat("P", (0.0, 0.0), "roof", False))),
}


def _build(case):
    circles, seats = CASES[case]
    return split_housing(circles, clearance=2.0, wall=4.0, floor_wall=11.0, roof_wall=11.0,
                         cavity_height=30.0, z_cavity_bottom=0.0, parting_z=12.0, seats=seats,
                         bolt_size="M4", bolt_hole_diameter=4.5, segments=64)


@pytest.fixture(scope="module", params=list(CASES), ids=list(CASES))
def housing(request):
    return request.param, _build(request.param)


def test_png_valid_and_deterministic(housing):
    case, built = housing
    first = housing_figure(case, built)
    assert first[:8] == PNG_SIGNATURE and first[12:16] == b"IHDR"
    width, height = struct.unpack(">II", first[16:24])
    assert 600 <= width <= 2000 and 300 <= height <= 2500
    assert housing_figure(case, built) == first


def test_texts_inside_the_figure_and_apart(housing, monkeypatch):
    """Seat labels, dimensions, tick labels, titles and the legend: none clipped, none on
    another (the section's and the plan's labels measured after the draw)."""
    import cadgen.report.plots.housings as module
    from test_plots_layout import assert_texts_clear

    drawn = []
    real = module._png
    monkeypatch.setattr(module, "_png", lambda figure: (drawn.append(figure), real(figure))[1])
    case, built = housing
    housing_figure(case, built)
    assert_texts_clear(drawn[0], case)


def test_plan_draws_every_bolt_hole_and_seat(housing):
    case, built = housing
    figure, ax = _figure()
    drawn = _draw_plan(ax, built, turned=False, scale=0.02)
    assert len(drawn["bolt_holes"]) == len(built.bolt_positions) >= 4
    centres = np.array([patch.center for patch in drawn["bolt_holes"]])
    assert np.allclose(centres, built.bolt_positions)
    assert all(np.isclose(p.radius, built.bolt_hole_diameter / 2) for p in drawn["bolt_holes"])
    positions = {tuple(np.round(seat.xy, 6)) for seat in built.seats}
    assert len(drawn["labels"]) == len(positions)
    assert len(drawn["through_holes"]) == sum(seat.through for seat in built.seats)
    assert {text.get_text() for text in drawn["labels"]} >= {
        f"{seat.shaft} 6001" for seat in built.seats}
    # the holes' extents given, not walked: the drawing's limits hold every bolt hole
    (x0, y0), (x1, y1) = ax.dataLim.get_points()
    holes = np.asarray(built.bolt_positions)
    radius = built.bolt_hole_diameter / 2
    assert x0 <= holes[:, 0].min() - radius and holes[:, 0].max() + radius <= x1
    assert y0 <= holes[:, 1].min() - radius and holes[:, 1].max() + radius <= y1


def test_section_follows_the_seat_line():
    """The long box's seats lie on x: the section runs along x, cuts every seat at full width,
    and its base and cover meet at the parting plane."""
    built = _build("long")
    centre, direction = _section_line(built)
    assert np.allclose(direction, [1.0, 0.0])
    section = _section(built, centre, direction)
    assert len(section["seats"]) == len(built.seats)
    for seat, s, (s0, s1), (z0, z1), hole in section["seats"]:
        assert np.isclose(s1 - s0, seat.seat_diameter) and np.isclose(z1 - z0, 8.0)
        assert (hole is not None) == seat.through
    assert np.isclose(section["base"].bounds[3], built.parting_z)
    assert np.isclose(section["cover"].bounds[1], built.parting_z)
    assert np.isclose(section["base"].bounds[1], built.z_bottom)
    assert np.isclose(section["cover"].bounds[3], built.z_top)


def test_jobs_skip_housings_without_seats():
    jobs = housing_figure_jobs({"box": _build("single"), "shell": object()})
    assert list(jobs) == ["housing-box.png"]


def test_build_has_a_figure_per_gearbox(planting_solids, monkeypatch):
    import cadgen.report.plots.housings as module
    from test_plots_layout import assert_texts_clear

    drawn = []
    real = module._png
    monkeypatch.setattr(module, "_png", lambda figure: (drawn.append(figure), real(figure))[1])
    housings = planting_solids[6]
    jobs = housing_figure_jobs({"gearbox1": housings[0], "gearbox2": housings[1]})
    assert {"housing-gearbox1.png", "housing-gearbox2.png"} <= set(jobs)
    assert jobs["housing-gearbox1.png"]()[:8] == PNG_SIGNATURE
    assert_texts_clear(drawn[0], "gearbox1")    # the long one: its plan over its section
