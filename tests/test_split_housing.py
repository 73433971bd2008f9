"""Split housings (base and cover), bearing seats, shaft holes, flange bolts, shafts."""

import math

import numpy as np
import pytest
import shapely

from cadgen.machine.model import Bearing, BearingSeat
from cadgen.solids.extrude import extrude, to_trimesh
from cadgen.solids.outline import circle, offset_outline
from cadgen.solids.shell import shell_outlines
from cadgen.solids.split_housing import (
    bolt_count,
    flange_width,
    shaft_solid,
    split_encloses,
    split_housing,
)
from kinematics.errors import DesignError

SEGMENTS = 96
BEARING = Bearing("6001", 12.0, 28.0, 8.0, 5.07, 2.36)
ALLOWANCE = 0.0105
CIRCLES = [(0.0, 0.0, 30.0), (70.0, 0.0, 25.0), (120.0, 0.0, 20.0)]
CLEARANCE, WALL = 2.0, 4.0
GEAR_LAYERS = ((7.0, 12.0), (21.0, 12.0))   # (z_bottom, face width) of the two gear layers


def _seat(shaft, xy, wall, through, *, bearing=BEARING, hole=12.5, side=1):
    return BearingSeat(shaft, "gearbox2", side, xy, wall, bearing, bearing.outside + ALLOWANCE,
                       through, hole if through else 0.0, 100.0, 10.0, 1e5, 5000.0)


SEATS = (_seat("C2", (0.0, 0.0), "floor", False), _seat("C2", (0.0, 0.0), "roof", False),
         _seat("D", (70.0, 0.0), "floor", True), _seat("D", (70.0, 0.0), "roof", False),
         _seat("E", (120.0, 0.0), "floor", False), _seat("E", (120.0, 0.0), "roof", True))

#: (floor wall, roof wall, parting height above the cavity floor, seats)
CASES = {
    "seated": (11.0, 11.0, 19.5, SEATS),
    # thin end walls without seats, the plane near the floor: the base's flange half is clipped
    "clipped-flange": (4.0, 4.0, 1.0, ()),
}


def _build(case):
    floor, roof, parting, seats = CASES[case]
    return split_housing(CIRCLES, clearance=CLEARANCE, wall=WALL, floor_wall=floor,
                         roof_wall=roof, cavity_height=35.0, z_cavity_bottom=5.0,
                         parting_z=5.0 + parting, seats=seats, bolt_size="M4",
                         bolt_hole_diameter=4.5, segments=SEGMENTS)


@pytest.fixture(scope="module", params=list(CASES), ids=list(CASES))
def housing(request):
    return request.param, _build(request.param)


def test_parts_watertight(housing):
    _, built = housing
    for solid, name in ((built.base, "base"), (built.cover, "cover")):
        mesh = to_trimesh(solid, name)
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0


def test_base_and_cover_disjoint_and_volume_closed_form(housing):
    """base ^ cover is empty; base + cover is the outer prism with its flange minus every void,
    each volume from shapely's areas of the same polygons."""
    case, built = housing
    floor, roof, _, seats = CASES[case]
    assert (built.base ^ built.cover).volume() < 1e-6
    cavity, outer = shell_outlines(CIRCLES, clearance=CLEARANCE, wall=WALL, segments=SEGMENTS)
    flange = offset_outline(outer, flange_width(4.5), SEGMENTS)
    height = 35.0 + floor + roof
    low, high = built.flange_z
    ring = shapely.Polygon(flange).difference(shapely.Polygon(outer))
    # a clearance hole is no fit: its polygon is within 0.01 mm of its circle, no finer
    sides = built.bolt_segments
    assert 12 <= sides <= SEGMENTS and 2.25 * (1 / math.cos(math.pi / sides) - 1) <= 0.01
    bolts = shapely.union_all([shapely.Polygon(circle(2.25, sides, xy))
                               for xy in built.bolt_positions])
    assert bolts.within(ring)     # every bolt hole lies in the flange, clear of the wall
    expected = (shapely.Polygon(outer).area * height + (ring.area - bolts.area) * (high - low)
                - shapely.Polygon(cavity).area * 35.0)
    for seat in seats:
        wall = floor if seat.wall == "floor" else roof
        expected -= shapely.Polygon(circle(seat.seat_diameter / 2, SEGMENTS, seat.xy)).area * 8.0
        if seat.through:
            expected -= (shapely.Polygon(circle(seat.hole_diameter / 2, SEGMENTS, seat.xy)).area
                         * (wall - 8.0))
    measured = built.base.volume() + built.cover.volume()
    assert np.isclose(measured, expected, rtol=1e-9, atol=0)
    assert np.isclose(built.volume, expected, rtol=1e-9, atol=0)
    assert np.isclose(built.solid.volume(), expected, rtol=1e-9, atol=0)
    # the flange halves: clipped to the housing's height, otherwise max(wall, 1.5 d) each side
    assert low == max(5.0 - floor, built.parting_z - 6.0) and high == built.parting_z + 6.0
    if case == "clipped-flange":
        assert low == 5.0 - floor


def test_bolt_count_is_the_pitch_rule(housing):
    _, built = housing
    _, outer = shell_outlines(CIRCLES, clearance=CLEARANCE, wall=WALL, segments=SEGMENTS)
    mid = shapely.Polygon(offset_outline(outer, flange_width(4.5) / 2, SEGMENTS))
    count = max(4, math.ceil(mid.exterior.length / (12 * 4.0)))
    assert len(built.bolt_positions) == count == bolt_count(mid.exterior.length, "M4")
    # evenly spaced along the mid-line
    spacing = np.diff([mid.exterior.project(shapely.Point(p)) for p in built.bolt_positions])
    assert np.allclose(spacing, mid.exterior.length / count, rtol=1e-9)


def _gear(radius, angle, z_bottom, face, centre):
    """A three-lobed stand-in for a non-circular gear, its largest radius ``radius``."""
    theta = 2 * np.pi * np.arange(180) / 180
    rho = radius * (0.8 + 0.2 * np.cos(3 * (theta - angle)))
    outline = np.column_stack([rho * np.cos(theta), rho * np.sin(theta)]) + centre
    return extrude(outline, face, z0=z_bottom)


@pytest.mark.parametrize("angle", [0.0, 0.7, 2.1], ids=["pose0", "pose1", "pose2"])
def test_gears_turn_inside(housing, angle):
    """The gears at three poses lie in the cavity and cut neither base nor cover; the seats,
    bored beyond the cavity's end faces, do not make them look outside."""
    case, built = housing
    for (cx, cy, radius), (z_bottom, face) in zip(CIRCLES, GEAR_LAYERS + GEAR_LAYERS[:1]):
        gear = _gear(radius, angle, 5.0 + z_bottom, face, (cx, cy))
        assert split_encloses(built, gear) == (True, 0.0)
        assert (gear ^ built.base).is_empty() and (gear ^ built.cover).is_empty()


def test_a_gear_in_a_seat_is_outside():
    built = _build("seated")
    # a pin reaching from the cavity 3 mm down into D's floor seat: not in the material, yet
    # outside the cavity
    pin = extrude(circle(5.0, SEGMENTS, (70.0, 0.0)), 6.0, z0=2.0)
    enclosed, outside = split_encloses(built, pin)
    assert not enclosed and np.isclose(outside, 3.0 * shapely.Polygon(circle(5.0, SEGMENTS)).area)
    assert (pin ^ built.solid).is_empty()


def _section_circle(mesh, z, near):
    """Centre and radius fitted to the vertices of the section loop of ``mesh`` at height ``z``
    nearest ``near``: only the points on the mesh's vertical edges (the polygon's vertices;
    the others lie on the triangles' diagonals, inside the circle)."""
    section = mesh.section(plane_origin=(0.0, 0.0, z), plane_normal=(0.0, 0.0, 1.0))
    points = np.asarray(section.vertices)[:, :2]
    vertex_xy = {tuple(v) for v in np.asarray(mesh.vertices)[:, :2]}
    on_edges = np.array([p for p in points if tuple(p) in vertex_xy])
    distance = np.linalg.norm(on_edges - near, axis=1)
    loop = on_edges[distance < 20.0]
    x, y = loop[:, 0], loop[:, 1]
    (a, b, c), *_ = np.linalg.lstsq(np.column_stack([2 * x, 2 * y, np.ones_like(x)]),
                                    x * x + y * y, rcond=None)
    return np.array([a, b]), math.sqrt(c + a * a + b * b), len(loop)


def test_seat_diameter_and_concentric_shaft_hole():
    built = _build("seated")
    base = to_trimesh(built.base, "base")
    seat = SEATS[2]      # D's floor seat, through: counterbore 8 mm deep from z = 5, hole below
    centre, radius, count = _section_circle(base, 5.0 - 4.0, np.array(seat.xy))
    assert count == SEGMENTS
    assert np.isclose(2 * radius, BEARING.outside + ALLOWANCE, rtol=1e-6, atol=0)
    hole_centre, hole_radius, _ = _section_circle(base, 5.0 - 8.0 - 1.5, np.array(seat.xy))
    assert np.isclose(2 * hole_radius, 12.5, rtol=1e-6, atol=0)
    assert np.linalg.norm(hole_centre - centre) < 1e-9
    assert np.linalg.norm(centre - seat.xy) < 1e-9


def test_seat_problems_all_at_once():
    wide = Bearing("6005", 25.0, 47.0, 12.0, 11.2, 6.55)
    seats = (_seat("D", (70.0, 0.0), "floor", True),                 # 8 mm deep in 8.5: too deep
             _seat("E", (120.0, 10.0), "roof", False, bearing=wide),   # breaks out
             _seat("C2", (0.0, 0.0), "roof", True, hole=30.0))        # hole wider than the seat
    with pytest.raises(DesignError) as caught:
        split_housing(CIRCLES, clearance=CLEARANCE, wall=WALL, floor_wall=8.5, roof_wall=14.0,
                      cavity_height=35.0, z_cavity_bottom=5.0, parting_z=20.0, seats=seats,
                      bolt_size="M4", bolt_hole_diameter=4.5, segments=SEGMENTS)
    found = {(p.path, p.code) for p in caught.value.problems}
    assert found == {("housing.seats.D.floor", "seat_too_deep"),
                     ("housing.seats.E.roof", "seat_breaks_out"),
                     ("housing.seats.C2.roof", "no_shoulder")}


def test_end_wall_and_parting_problems():
    with pytest.raises(DesignError) as caught:
        split_housing(CIRCLES, clearance=CLEARANCE, wall=WALL, floor_wall=1.0, roof_wall=4.0,
                      cavity_height=35.0, z_cavity_bottom=5.0, parting_z=50.0, seats=(),
                      bolt_size="M4", bolt_hole_diameter=4.5, segments=SEGMENTS)
    assert {(p.path, p.code) for p in caught.value.problems} == {
        ("housing.floor_wall", "wall_too_thin"), ("housing.parting_z", "parting_outside_cavity")}


@pytest.mark.parametrize("flat_depth, keyseats", [
    (0.0, ()),
    (0.0, ((10.0, 30.0, 4.0, 2.5, 0.3),)),
    (1.0, ((10.0, 30.0, 4.0, 2.5, 0.3), (40.0, 50.0, 4.0, 2.5, math.pi))),
], ids=["plain", "keyed", "keyed-flat"])
def test_shaft_solid_volume(flat_depth, keyseats):
    shaft = shaft_solid(12.0, -5.0, 60.0, keyseats=keyseats, flat_depth=flat_depth,
                        segments=SEGMENTS)
    assert to_trimesh(shaft, "shaft").is_watertight
    section = shapely.Polygon(circle(6.0, SEGMENTS))
    if flat_depth:
        section = section.difference(shapely.box(6.0 - flat_depth, -12.0, 12.0, 12.0))
    expected = section.area * 65.0
    for z_from, z_to, width, depth, angle in keyseats:
        slot = shapely.affinity.rotate(shapely.box(6.0 - depth, -width / 2, 12.0, width / 2),
                                       angle, origin=(0.0, 0.0), use_radians=True)
        expected -= section.intersection(slot).area * (z_to - z_from)
    assert np.isclose(shaft.volume(), expected, rtol=1e-9)


@pytest.mark.parametrize("phi", [0.0, 1.3, 4.0])
def test_the_paper_designs_gears_turn_inside_base_and_cover(planting_solids, phi):
    """The real gears of both gearboxes, placed in their housing's body at three carrier
    angles (their local placement turns them on their axes), lie in the cavity: nothing of
    them outside it, nothing in the base's or the cover's material (manifold booleans)."""
    from cadgen.solids.split_housing import split_encloses

    params, *_, assembly, housings, _ = planting_solids
    from helpers import gears_in_their_housings

    checked = 0
    for part, _, housing, local in gears_in_their_housings(assembly, housings, phi):
        placed = part.solid.transform(local[:3, :])
        enclosed, outside = split_encloses(housing, placed)
        assert enclosed, (part.name, outside)
        assert (placed ^ housing.base).is_empty() and (placed ^ housing.cover).is_empty()
        checked += 1
    assert checked == 16
