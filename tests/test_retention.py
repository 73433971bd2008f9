"""Axial location along the shafts: DIN 471 figures, stacks by hand, and the sliding check
against a second method (a linear programme over the parts' axial displacements)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from cadgen.assembly.axial import AxialGraph, axial_check
from cadgen.assembly.machine import _axial_stack, _Builder
from cadgen.machine.catalogue import CatalogueError, bearings_with_bore, shaft_ring
from cadgen.machine.model import BearingSeat, GearMount, HousingStack, Shaft
from cadgen.machine.retention import AXIAL_PLAY, RING_CLEARANCE, ring_room, shaft_retention


def test_din_471_rings_as_the_standard_prints_them():
    # DIN 471 table 1, normal type: s, d2 (groove), m (groove width), n, d4
    assert {k: shaft_ring(15)[k] for k in ("s", "d2", "m", "n", "d4")} == {
        "s": 1.0, "d2": 14.3, "m": 1.1, "n": 1.1, "d4": 22.6}
    assert (shaft_ring(20)["s"], shaft_ring(20)["d2"], shaft_ring(20)["m"]) == (1.2, 19.0, 1.3)
    assert (shaft_ring(30)["s"], shaft_ring(30)["d2"], shaft_ring(30)["m"]) == (1.5, 28.6, 1.6)
    assert shaft_ring(17)["designation"] == "DIN 471 17 x 1"
    # the groove beyond the part and the shaft past it, to the half millimetre: 1.1 + 1.1
    assert ring_room(15) == 2.5
    with pytest.raises(CatalogueError, match="16 mm shaft"):
        shaft_ring(16)


def test_every_catalogue_shaft_diameter_has_its_ring():
    # a shaft is sized to a catalogue bearing's bore: each such diameter takes a DIN 471 ring
    # (a sleeve grows to 45 mm when an optimised arm loads the drive more)
    from cadgen.machine.catalogue import preferred_diameters

    for d in preferred_diameters():
        ring = shaft_ring(d)
        assert ring["d2"] < d and ring["m"] > ring["s"] and ring["d4"] > d, d
    assert (shaft_ring(45)["s"], shaft_ring(45)["d2"]) == (1.75, 42.5)


def _shaft(faces, *, d=20.0, cavity=56.0, name="A", floor_through=False, roof_through=False,
           above=0.0):
    """A shaft in one housing on two bearings of bore ``d``, with keyed gears at ``faces``
    (``(z_bottom, face width)`` from the cavity floor)."""
    bearing = bearings_with_bore(d)[0]
    seats = tuple(BearingSeat(name, "box", 1, (0.0, 0.0), wall, bearing, bearing.outside,
                              through, d + 1.0 if through else 0.0, 0.0, 0.0, math.inf, 0.0)
                  for wall, through in (("floor", floor_through), ("roof", roof_through)))
    mounts = tuple(GearMount(f"gear{k}", z, w, 0.0, 0.0, d, None, 0.0, 0.0)
                   for k, (z, w) in enumerate(faces))
    shaft = Shaft(name, "box", 1, (0.0, 0.0), d, d, False, 0.0, 0.0, 0.0, mounts, seats,
                  0.0, above, "")
    stacks = {"box": HousingStack("box", 15.0, 15.0, cavity, cavity / 2, ())}
    return shaft, stacks


def test_a_two_gear_shaft_by_hand():
    # 6004 (12 mm wide) in each wall, gears 2-27 and 29-54 in a 56-mm cavity
    shaft, stacks = _shaft([(2.0, 25.0), (29.0, 25.0)])
    stack = shaft_retention(shaft, stacks, {})
    got = [(p.kind, round(p.z0, 6), round(p.z1, 6)) for p in stack.parts]
    ring = shaft_ring(20)["s"]
    assert got == [("bearing", -12.0, 0.0), ("spacer", 0.0, 2.0), ("gear", 2.0, 27.0),
                   # the tie ring between the gears, the spacer above it short by the play
                   ("ring", 27.0, 27.0 + ring), ("spacer", 27.0 + ring, 29.0 - AXIAL_PLAY),
                   ("gear", 29.0, 54.0), ("spacer", 54.0, 56.0), ("bearing", 56.0, 68.0)]
    assert not stack.problems and not stack.set_screws


def test_a_gap_too_short_for_a_ring_is_named():
    shaft, stacks = _shaft([(0.5, 27.0), (28.0, 27.5)])   # 0.5 mm gaps everywhere
    stack = shaft_retention(shaft, stacks, {})
    assert [p.code for p in stack.problems] == ["no_room_for_retaining_ring"]
    assert stack.problems[0].path == "housing.axial_gap"


def _graph(shaft, stack):
    b = _Builder()
    _axial_stack(b, stack, shaft, "shaft", None, lambda housing: "frame",
                 {m.gear: m.gear for m in shaft.mounts})
    return b.axial


def _free_by_linear_programming(graph: AxialGraph, frame: str) -> dict:
    """Each part's largest displacement down and up (bounded to 1 mm) that the contacts allow:
    ``x_upper >= x_lower`` for each rest, ``x_a = x_b`` for each fixed pair, ``x_frame = 0``."""
    names = sorted(set(graph.parts) | {n for pair in graph.rests + graph.fixed for n in pair})
    index = {n: k for k, n in enumerate(names)}
    rows, eq = [], []
    for upper, lower in graph.rests:
        row = np.zeros(len(names))
        row[index[lower]], row[index[upper]] = 1.0, -1.0   # x_lower - x_upper <= 0
        rows.append(row)
    for a, b in graph.fixed + [(frame, frame)]:
        row = np.zeros(len(names))
        row[index[a]] += 1.0
        row[index[b]] -= 1.0
        eq.append(row)
    frame_row = np.zeros(len(names))
    frame_row[index[frame]] = 1.0
    eq.append(frame_row)
    free = {}
    for name in names:
        if name == frame:
            continue
        ways = []
        for way, sign in (("down", 1.0), ("up", -1.0)):
            cost = np.zeros(len(names))
            cost[index[name]] = sign
            out = linprog(cost, A_ub=np.array(rows) if rows else None,
                          b_ub=np.zeros(len(rows)) if rows else None, A_eq=np.array(eq),
                          b_eq=np.zeros(len(eq)), bounds=[(-1.0, 1.0)] * len(names))
            assert out.status == 0
            if sign * out.x[index[name]] < -0.5:
                ways.append(way)
        if ways:
            free[name] = ways
    return free


faces = st.lists(st.tuples(st.floats(0.0, 30.0), st.floats(5.0, 40.0)), min_size=1, max_size=3)


@settings(max_examples=30, deadline=None)
@given(faces, st.floats(1.5, 8.0), st.sampled_from([12.0, 15.0, 20.0, 25.0]),
       st.booleans(), st.data())
def test_every_part_of_a_designed_stack_is_held_and_each_ring_is_needed(widths, gap, d, through,
                                                                        data):
    """Gears of random widths and gaps (each gap at least ``gap``) on a shaft: the stack
    designed holds every part both ways, by the check and by the linear programme; taking
    any one ring or set screw away frees a part, and both methods name the same parts."""
    layout, z = [], gap
    for offset, width in widths:
        layout.append((z + offset, width))
        z += offset + width + gap
    shaft, stacks = _shaft(layout, d=d, cavity=z, roof_through=through,
                           above=20.0 if through else 0.0)
    stack = shaft_retention(shaft, stacks, {})
    assert not stack.problems
    graph = _graph(shaft, stack)
    report = axial_check(graph, "frame")
    assert report["passed"], report["free"]
    assert _free_by_linear_programming(graph, "frame") == {}
    locks = [pair for pair in graph.fixed]
    assert locks, "a cross-located stack needs a ring to tie the shaft to it"
    dropped = data.draw(st.sampled_from(locks))
    graph.fixed.remove(dropped)
    by_graph = {f["part"]: f["ways"] for f in axial_check(graph, "frame")["free"]}
    assert by_graph, f"dropping {dropped} freed nothing: the ring was not needed"
    assert by_graph == _free_by_linear_programming(graph, "frame")


def test_the_example_machines_hold_every_part_and_a_missing_ring_is_named(paper_drivetrain):
    from cadgen.assembly.machine import planting_model

    model = planting_model(paper_drivetrain)
    assert axial_check(model.axial, model.frame)["passed"]
    assert _free_by_linear_programming(model.axial, model.frame) == {}
    rings = [pair for pair in model.axial.fixed if "/ring-" in pair[0]]
    # each ring is needed: without it a part slides, and the check names the same parts as
    # the linear programme
    for pair in rings:
        model.axial.fixed.remove(pair)
        free = {f["part"]: f["ways"] for f in axial_check(model.axial, model.frame)["free"]}
        assert free and free == _free_by_linear_programming(model.axial, model.frame), pair
        model.axial.fixed.append(pair)


def test_the_hub_outside_the_housing_has_a_ring_each_side_and_clears_the_cam(paper_drivetrain):
    e = next(r for r in paper_drivetrain.retention if r.shaft == "E")
    hub = next(p for p in e.parts if p.kind == "hub")
    below, above = [p for p in e.rings if p.z1 <= hub.z0 + 1e-9][-1], e.rings[-1]
    assert below.z1 == pytest.approx(hub.z0) and above.z0 == pytest.approx(hub.z1)
    # the ring below turns with E a gap above the cam's top face (housing.axial_gap = 2 mm)
    assert 2.0 - (below.z1 - below.z0) >= RING_CLEARANCE
    shaft = next(s for s in paper_drivetrain.shafts if s.name == "E")
    stacks = paper_drivetrain.stacks["gearbox2"]
    top = stacks.cavity_height + stacks.roof_wall + shaft.extends_above
    assert top - above.z0 == pytest.approx(ring_room(15.0))   # groove and n past it


def test_nothing_overlaps_along_a_shaft(paper_drivetrain):
    for stack in paper_drivetrain.retention:
        ordered = sorted(stack.parts, key=lambda p: p.z0)
        for lower, upper in zip(ordered, ordered[1:]):
            gap = upper.z0 - lower.z1
            assert gap >= -1e-9, (stack.shaft, lower, upper)   # nothing overlaps along the shaft


@pytest.fixture(scope="module")
def paper_drivetrain():
    from cadgen.design import build_mechanism
    from cadgen.machine.drivetrain import drivetrain
    from cadgen.params import load_params

    params = load_params("params/xin2024-planter.toml")
    return drivetrain(params, build_mechanism(params))


def test_a_ring_groove_removes_its_annulus_from_the_shaft(paper_drivetrain):
    from types import SimpleNamespace

    from cadgen.solids.machine_parts import shaft_part, spacer_parts

    shaft = next(s for s in paper_drivetrain.shafts if s.name == "D")
    stack = next(r for r in paper_drivetrain.retention if r.shaft == "D")
    housing = SimpleNamespace(z_cavity_bottom=0.0, cavity_height=56.0,
                              floor_wall=paper_drivetrain.stacks["gearbox2"].floor_wall,
                              roof_wall=paper_drivetrain.stacks["gearbox2"].roof_wall)
    segments = 720
    plain = shaft_part(shaft, housing, "gearbox2", segments=segments).solid.volume()
    grooved = shaft_part(shaft, housing, "gearbox2", segments=segments,
                         retention=stack).solid.volume()
    ring = shaft_ring(15.0)
    # one groove: an annulus from d2 to d, m wide (the polygon's area ratio to the circle's)
    polygon = segments / (2 * math.pi) * math.sin(2 * math.pi / segments)
    expected = len(stack.rings) * math.pi / 4 * (15.0**2 - ring["d2"]**2) * ring["m"] * polygon
    assert plain - grooved == pytest.approx(expected, rel=2e-3)
    spacers = spacer_parts(shaft_part(shaft, housing, "gearbox2", segments=segments), stack,
                           0.0, segments)
    for part, record in zip(spacers, stack.spacers):
        by_hand = (math.pi / 4 * (record.outside**2 - record.bore**2)
                   * (record.z1 - record.z0) * polygon)
        assert part.solid.volume() == pytest.approx(by_hand, rel=1e-6)


def _disc_profile(outline, keyway=0.0):
    from types import SimpleNamespace

    return SimpleNamespace(outline=np.asarray(outline, dtype=float), centre=(0.0, 0.0),
                           notes={"keyway_angle_rad": keyway})


@pytest.mark.parametrize("radius, clearance", [(27.0, 1.0), (26.0, 0.0), (25.0, -1.0)])
def test_a_hub_set_screw_reaches_the_keys_back_plus_its_length(radius, clearance):
    """By hand: shaft 30, DIN 6885 key 8 x 7 (t1 4): the key's back 15 - 4 + 7 = 18 mm from the
    axis; an M5 x 8 screw ends at 26 mm; a disc of radius R leaves R - 26."""
    from types import SimpleNamespace

    from cadgen.machine.catalogue import key_for_shaft
    from cadgen.machine.hubs import set_screw_clearance

    key = key_for_shaft(30.0)
    assert (key.width, key.height, key.shaft_depth) == (8.0, 7.0, 4.0)
    t = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
    disc = _disc_profile(np.column_stack([radius * np.cos(t), radius * np.sin(t)]), 0.3)
    got = set_screw_clearance(disc, SimpleNamespace(diameter=30.0), key,
                              "set screw ISO 4029 M5 x 8 - 45H")
    # the 720-gon's chord at 0.3 rad lies within R (1 - cos(pi / 720)) of the circle
    assert got == pytest.approx(clearance, abs=radius * (1 - np.cos(np.pi / 720)) + 1e-12)


def test_a_set_screw_on_a_tooths_line_meets_the_tip_and_in_a_space_the_root():
    """A square 'gear' of half-width 30: along +x the ray leaves at 30, along the diagonal at
    30 sqrt 2 (the corner): where the ray leaves the outline, not the outline's least radius."""
    from cadgen.machine.hubs import outline_radius_along

    square = [(30.0, -30.0), (30.0, 30.0), (-30.0, 30.0), (-30.0, -30.0)]
    assert outline_radius_along(square, 0.0) == pytest.approx(30.0, abs=1e-12)
    assert outline_radius_along(square, np.pi / 4) == pytest.approx(30.0 * np.sqrt(2), abs=1e-9)
    assert outline_radius_along(square, 0.2) == pytest.approx(30.0 / np.cos(0.2), abs=1e-9)
