"""45 deg gussets under a printed housing's flange halves (issue 29, printing)."""

import io
import math
from types import SimpleNamespace

import numpy as np
import pytest
import shapely

from cadgen.solids.extrude import manifold3d_engine, to_trimesh
from cadgen.solids.flange_chamfer import (RISE_MARGIN, ChamferedHousing, chamfer_flanges,
                                          chamfer_run, seat_slot_width)
from cadgen.solids.machine_parts import stack_housing, with_dowels
from cadgen.solids.outline import circle
from cadgen.solids.printing import overhang_area
from cadgen.solids.split_housing import SplitHousing, split_housing
from tests.test_split_housing import CIRCLES, CLEARANCE, SEATS, WALL

SEGMENTS = 96
#: (floor wall, roof wall, cavity height, parting height above the cavity floor, seats)
CASES = {
    # both gussets whole (each half taller beside the flange than the gusset)
    "seated": (11.0, 11.0, 35.0, 19.5, SEATS),
    # the base's gusset reaches the floor: cut off there, it stands on the bed with the base
    "gusset-on-the-floor": (4.0, 4.0, 35.0, 8.0, ()),
    # the plane near the floor: the base's flange half is clipped, it has no gusset
    "clipped-flange": (4.0, 4.0, 35.0, 1.0, ()),
}
#: The cover is printed on its roof: turned over about x.
UPSIDE_DOWN = np.diag([1.0, -1.0, -1.0, 1.0])


def _housing(case):
    floor, roof, height, parting, seats = CASES[case]
    return with_dowels(split_housing(CIRCLES, clearance=CLEARANCE, wall=WALL, floor_wall=floor,
                                     roof_wall=roof, cavity_height=height, z_cavity_bottom=5.0,
                                     parting_z=5.0 + parting, seats=seats, bolt_size="M4",
                                     bolt_hole_diameter=4.5, segments=SEGMENTS))


@pytest.fixture(scope="module", params=list(CASES), ids=list(CASES))
def chamfered(request):
    plain = _housing(request.param)
    return request.param, plain, chamfer_flanges(plain)


def _seats(plain, width):
    """The bolts' seats left under the flange: the slots' part of the flange ring, less the
    bolts' holes (the same polygons as the solids')."""
    from cadgen.solids.flange_chamfer import _seat_slots

    ring = shapely.Polygon(plain.flange_outline).difference(shapely.Polygon(plain.outer_outline))
    slots = shapely.union_all([shapely.Polygon(s) for s in _seat_slots(plain, width)])
    holes = shapely.union_all([shapely.Polygon(circle(plain.bolt_hole_diameter / 2,
                                                      plain.bolt_segments, xy))
                               for xy in plain.bolt_positions])
    return ring.intersection(slots).difference(holes).area


def test_the_gussets_volume_has_its_closed_form(chamfered):
    case, plain, built = chamfered
    assert isinstance(built, ChamferedHousing)
    measured = built.base.volume() + built.cover.volume()
    assert np.isclose(built.volume, measured, rtol=1e-9, atol=0)
    assert built.volume > plain.volume
    # the split housing's own terms are unchanged: the gussets are all that was added
    assert np.isclose(built.volume - built.chamfer.volume, plain.volume, rtol=1e-12)
    assert [g[0] for g in built.chamfer.gussets] == (
        ["cover"] if case == "clipped-flange" else ["base", "cover"])
    # a gusset is run + margin high, or cut off at its end wall's outer face
    for half, _, z_low, _, z_high, (z_min, z_max) in built.chamfer.gussets:
        assert z_high - z_low == pytest.approx(built.chamfer.rise)
        if half == "base":
            assert (z_min, z_max) == (max(z_low, built.z_bottom), built.flange_z[0])
        else:
            assert (z_min, z_max) == (built.flange_z[1], min(z_high, built.z_top))
    clipped = {"seated": (), "gusset-on-the-floor": ("base",), "clipped-flange": ()}[case]
    assert [g[0] for g in built.chamfer.gussets if g[5][1] - g[5][0] < g[4] - g[2]] == list(clipped)
    assert built.chamfer.rise == pytest.approx(built.chamfer.run + RISE_MARGIN)


def test_each_half_is_one_clean_shell_in_its_stl(chamfered):
    import trimesh

    from cadgen.export.meshes import stl_bytes

    _, _, built = chamfered
    for name in ("base", "cover"):
        mesh = trimesh.load(io.BytesIO(stl_bytes(to_trimesh(getattr(built, name), name))),
                            file_type="stl")
        assert mesh.is_watertight and len(mesh.split(only_watertight=False)) == 1, name
        assert float(np.min(mesh.area_faces)) > 1e-9, name


def test_only_the_bolts_seats_overhang_on_the_end_walls(chamfered):
    """The base on its floor, the cover on its roof: before, the whole flange face away from the
    parting plane overhangs; with the gussets only the bolts' seats (the slots' roofs) do."""
    case, plain, built = chamfered
    ring = shapely.Polygon(plain.flange_outline).difference(shapely.Polygon(plain.outer_outline))
    seats = _seats(plain, built.chamfer.slot_width)
    for half, pose in (("base", None), ("cover", UPSIDE_DOWN)):
        before = overhang_area(to_trimesh(getattr(plain, half), half), pose)
        after = overhang_area(to_trimesh(getattr(built, half), half), pose)
        if case == "clipped-flange" and half == "base":   # its flange lies on the bed
            assert before == after == pytest.approx(0.0, abs=1e-6)
            continue
        assert before == pytest.approx(ring.area - sum(
            shapely.Polygon(circle(d / 2, 48, (x, y))).area for x, y, d in plain.dowels)
            - len(plain.bolt_positions) * shapely.Polygon(circle(
                plain.bolt_hole_diameter / 2, plain.bolt_segments)).area, rel=1e-6)
        assert after == pytest.approx(seats, rel=1e-6)
        assert after < 0.3 * before


def test_the_bolts_and_dowels_keep_their_holes_and_seats(chamfered):
    """A rod through each bolt's hole and a washer under the flange meet no material; a dowel's
    hole stays through."""
    m3d = manifold3d_engine()
    _, plain, built = chamfered
    low, high = built.flange_z
    radius = (seat_slot_width("M4") - 1.0) / 2    # the washer itself
    for x, y in built.bolt_positions:
        rod = m3d.Manifold.cylinder(built.z_top - built.z_bottom, 0.45 * 4.5, 0.45 * 4.5, 32)
        assert (built.solid ^ rod.translate((x, y, built.z_bottom))).is_empty()
        for half, z in (("base", low - 5.01), ("cover", high + 0.01)):   # short of the seat
            washer = m3d.Manifold.cylinder(5.0, radius, radius, 64).translate((x, y, z))
            assert (getattr(built, half) ^ washer).is_empty(), (half, x, y)
    for x, y, diameter in built.dowels:
        pin = m3d.Manifold.cylinder(100.0, 0.45 * diameter, 0.45 * diameter, 32)
        assert (built.solid ^ pin.translate((x, y, -50.0))).is_empty()


def test_the_run_is_the_flanges_reach_beyond_the_wall():
    plain = _housing("seated")
    run = chamfer_run(plain.outer_outline, plain.flange_outline)
    # the flange is 3 hole diameters wide, its round joins a little more (outline.offset_outline)
    assert 3 * 4.5 <= run <= 3 * 4.5 / math.cos(math.pi / SEGMENTS) * 1.001


def test_a_splice_bolt_beside_a_gusset_gets_its_room():
    """A short cover's splice bolts sit in its gusset's reach: the gusset is cut away round the
    cut, over the lugs and the screw head's (or the nut's) length and a washer beyond; the tall
    base's splice bolts are clear of its gusset, which stays whole."""
    from cadgen.machine.catalogue import nut, socket_screw, washer
    from cadgen.solids.segments import _half_heights, lug_thickness, segment_housing

    m3d = manifold3d_engine()
    plain = with_dowels(split_housing(
        CIRCLES, clearance=CLEARANCE, wall=WALL, floor_wall=4.0, roof_wall=4.0,
        cavity_height=60.0, z_cavity_bottom=5.0, parting_z=50.0, bolt_size="M4",
        bolt_hole_diameter=4.5, segments=SEGMENTS))
    cuts = [(np.array([95.0, 0.0]), np.array([0.0, 1.0]))]
    built = chamfer_flanges(plain, cuts=cuts)
    strips = [half for half, _ in built.chamfer.cutouts if half != "both"]
    assert strips == ["cover"]
    assert np.isclose(built.volume, built.base.volume() + built.cover.volume(), rtol=1e-9)
    split = segment_housing(built, cuts, segments=SEGMENTS)
    thickness = lug_thickness(built)
    stack = max(socket_screw("M4")["head_height"], nut("M4")["m"] + washer("M4")["h"])
    radius = washer("M4")["d2"] / 2
    z_bolt = _half_heights(built)["cover"][2]
    for bolt in split.joints[0].bolts:
        if bolt[2] != z_bolt:
            continue
        for side in (-1.0, 1.0):   # the head on one lug's face, the washer and nut on the other
            room = m3d.Manifold.cylinder(stack, radius, radius, 64).rotate((0.0, 90.0, 0.0))
            start = 95.0 + side * (thickness + 0.01) - (stack if side < 0 else 0.0)
            room = room.translate((start, bolt[1], bolt[2]))
            for piece in split.pieces:
                assert (piece.cover ^ room).is_empty()


def test_only_a_printed_housing_is_chamfered():
    stack = SimpleNamespace(floor_wall=11.0, roof_wall=11.0, cavity_height=35.0, parting_z=19.5)
    shell = SimpleNamespace(clearance=CLEARANCE, wall=WALL)
    made = {}
    for process in ("machined", "printed"):
        params = SimpleNamespace(housing=SimpleNamespace(bolt_size="M4"),
                                 manufacturing=SimpleNamespace(process=process,
                                                               build_volume=(256.0,) * 3))
        made[process] = stack_housing(params, CIRCLES, shell, stack, SEATS, z_cavity_bottom=5.0,
                                      segments=SEGMENTS)
    assert type(made["machined"]) is SplitHousing
    assert isinstance(made["printed"], ChamferedHousing) and made["printed"].chamfer.cuts == ()
