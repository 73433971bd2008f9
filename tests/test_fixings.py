"""The arm parts' fixings (cadgen.machine.fixings) against hand sums and the DIN 6885 table, and
the overlap check (cadgen.solids.overlaps) against boxes whose intersections are known."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cadgen.machine.catalogue import key_lengths, preferred_diameters
from cadgen.machine.fixings import keyed_hub, needle_clamp, screwed_plate
from cadgen.machine.shafts import key_for_shaft

# ISO 898-1 Table: tensile stress areas of coarse threads (mm^2), the catalogue figures
STRESS_AREA = {"M3": 5.03, "M4": 8.78, "M5": 14.2}


def test_the_planters_hub_on_shaft_e_by_hand():
    # T_E = 17.27 N m on a 15 mm shaft: DIN 6885 5 x 5 (t1 = 3); p = 2 T / (d (h - t1) (l - b))
    torque = 17266.3
    hub, problems = keyed_hub("planter", "E", 15.0, torque, 8.0, 150.0, 0.009, "planter")
    assert problems == []
    assert hub["key"].length == 14.0   # 12 mm: 2 T / (15 x 2 x 7) = 164 MPa, over 150
    assert 2 * torque / (15 * 2 * (12 - 5)) > 150.0
    assert hub["pressure_mpa"] == pytest.approx(2 * torque / (15 * 2 * (14 - 5)))
    assert hub["length"] == 16.0 and hub["outside"] == 30.0   # the key plus 1 mm each end; 2 d


def test_a_small_shaft_gets_a_d_flat_unchecked_and_an_overload_is_named():
    hub, problems = keyed_hub("rocker", "planet", 8.0, 5000.0, 8.0, 150.0, 0.0, "linkage")
    assert hub["key"] is None and hub["flat_depth"] == pytest.approx(0.8)
    assert hub["pressure_mpa"] is None and problems == []
    hub, problems = keyed_hub("planter", "E", 15.0, 17266.3, 8.0, 10.0, 0.0, "planter.x")
    assert [p.code for p in problems] == ["key_overloaded"] and problems[0].path == "planter.x"
    assert hub["key"].length <= 2.5 * 15 - 2   # the longest the largest hub takes


@settings(max_examples=60, deadline=None)
@given(d=st.sampled_from([d for d in preferred_diameters() if 10 <= d <= 60]),
       torque=st.floats(1e3, 2e5), plate=st.floats(4.0, 30.0))
def test_the_hubs_key_is_the_shortest_passing_standard_key(d, torque, plate):
    hub, problems = keyed_hub("part", "shaft", d, torque, plate, 150.0, 0.0, "x")
    key = hub["key"]
    # brute force over the standard lengths: pressures from the table's own b, h, t1
    row = key_for_shaft(d)

    def pressure(length):
        return 2 * torque / (d * (row.height - row.shaft_depth) * (length - row.width))

    usable = [n for n in key_lengths() if n > row.width and n <= max(2.5 * d, plate) - 2]
    passing = [n for n in usable if pressure(n) <= 150.0]
    if not passing:
        assert [p.code for p in problems] == ["key_overloaded"]
        return
    fits_plate = [n for n in key_lengths() if n <= plate - 2 + 1e-9]   # a plate of 9.999...96
    assert key.length == max(passing[0], fits_plate[-1] if fits_plate else 0)
    assert problems == [] and hub["pressure_mpa"] <= 150.0 + 1e-9
    assert hub["length"] == pytest.approx(max(plate, key.length + 2))


def test_the_cams_screws_by_hand():
    # an 8 mm cam round a 32 mm bearing seat: M3 heads (3 mm) sink 3.4 mm, leaving 4.6 mm >= 0.8 d
    plate, problems = screwed_plate("cam", "gearbox2", 16.0, 8.0, 2733.0, 10.0, "cam.thickness")
    assert problems == [] and plate["bolt"] == "M3" and plate["bolts"] == 3
    assert plate["bolt_circle_radius"] == pytest.approx(16.0 + 2.0 + 2.5 / 2)   # tap drill 2.5
    assert plate["counterbore_diameter"] == 6.5 and plate["counterbore_depth"] == pytest.approx(3.4)
    # 4.6 clamped + 4.5 engaged = 9.1 mm: the next ISO 4762 M3 length is 10
    assert plate["screw"] == "ISO 4762 M3 x 10 - 8.8"
    shear = 2733.0 / (3 * STRESS_AREA["M3"] * plate["bolt_circle_radius"])
    assert plate["bolt_shear_mpa"] == pytest.approx(shear, rel=0.01)
    # a 5 mm plate cannot sink an M3, M4 or M5 head and keep 0.8 d under it
    _, problems = screwed_plate("cam", "gearbox2", 16.0, 5.0, 2733.0, 10.0, "cam.thickness")
    assert [p.code for p in problems] == ["plate_too_thin"]


def test_the_needles_clamp():
    clamp, problems = needle_clamp(8.0, 16.0, 0.06, "linkage.needle_diameter")
    assert problems == [] and clamp["wall"] == 4.0 and clamp["outside"] == pytest.approx(16.06)
    assert clamp["set_screw"] == "ISO 4027 M4 x 4 - 45H"


# ------------------------------------------------------------------ the overlap check
class _Part:
    def __init__(self, name, solid, kind="housing"):
        self.name, self.solid, self.kind = name, solid, kind


class _Assembly:
    def __init__(self, placed, model=None):
        self._placed, self.model = placed, model

    def placements(self, phi):
        return [(part.name, part, pose) for part, pose in self._placed]


def _box(x, y, z):
    from cadgen.solids.extrude import manifold3d_engine

    return manifold3d_engine().Manifold.cube((x, y, z))


@settings(max_examples=25, deadline=None)
@given(dx=st.floats(0.5, 9.5), dy=st.floats(0.5, 9.5), dz=st.floats(0.5, 9.5),
       turn=st.floats(0, 2 * math.pi))
def test_an_unjoined_overlap_fails_with_the_boxes_volume_and_thickness(dx, dy, dz, turn):
    from cadgen.solids.overlaps import overlap_check
    from cadgen.solids.parts import planar_transform

    # two 10 mm cubes, the second moved by (dx, dy, dz): they share (10 - dx)(10 - dy)(10 - dz);
    # both turned together about z (the overlap moves with them, its size does not)
    turned = planar_transform(turn)
    moved = turned @ planar_transform(0.0, (dx, dy), dz)
    check = overlap_check(_Assembly([(_Part("a", _box(10, 10, 10)), turned),
                                     (_Part("b", _box(10, 10, 10)), moved)]), segments=64)
    a, b, c = 10 - dx, 10 - dy, 10 - dz
    [overlap] = check["overlaps"]
    assert overlap["volume_mm3"] == pytest.approx(a * b * c, rel=1e-6)
    assert overlap["thickness_mm"] == pytest.approx(a * b * c / (a * b + b * c + c * a), rel=1e-6)
    assert not check["passed"] and "a and b share" in check["failures"][0]


def test_a_joined_shell_within_the_chord_error_passes_and_a_thick_one_does_not():
    from cadgen.assembly import AssemblyModel, Joint
    from cadgen.solids.extrude import manifold3d_engine
    from cadgen.solids.overlaps import overlap_check

    m3d = manifold3d_engine()
    shaft = m3d.Manifold.cylinder(20.0, 7.5, 7.5, 64)
    # a hub whose 64-gon bore, turned half a step, is cut by the shaft's corners
    hub = (m3d.Manifold.cylinder(10.0, 15.0, 15.0, 64)
           - m3d.Manifold.cylinder(10.0, 7.5, 7.5, 64).rotate((0, 0, 180 / 64)))
    model = AssemblyModel(("shaft", "hub"), (Joint("fixed", "hub", "shaft"),), "shaft")
    eye = np.eye(4)
    check = overlap_check(_Assembly([(_Part("shaft", shaft, "shaft"), eye),
                                     (_Part("hub", hub, "gear"), eye)], model), segments=64)
    [overlap] = check["overlaps"]
    assert overlap["joined"] and check["passed"]
    assert overlap["thickness_mm"] <= 7.5 * (1 - math.cos(math.pi / 64))
    # the same pair not joined by the model: the sliver is a defect
    loose = overlap_check(_Assembly([(_Part("shaft", shaft, "shaft"), eye),
                                     (_Part("hub", hub, "gear"), eye)]), segments=64)
    assert not loose["passed"]
    # a hub with no bore on the joined shaft: millimetres thick, fails
    solid = overlap_check(_Assembly([(_Part("shaft", shaft, "shaft"), eye),
                                     (_Part("hub", m3d.Manifold.cylinder(10.0, 15.0, 15.0, 64),
                                            "gear"), eye)], model), segments=64)
    assert not solid["passed"] and solid["overlaps"][0]["thickness_mm"] > 1.0


# ------------------------------------------------------------------ dowels and alignment
def test_dowels_and_the_seats_tilt_by_hand():
    from cadgen.machine.fits import deviation
    from cadgen.machine.fixings import dowel_pins, seat_misalignment

    # ISO 286-2: m6 over 18 up to 30 mm is +8 / +21 um; over 3 up to 6, +4 / +12
    assert deviation("m6", 20) == pytest.approx((0.008, 0.021))
    assert deviation("m6", 4) == pytest.approx((0.004, 0.012))
    pins = dowel_pins("M3", 9.0)   # a 9 mm flange pair: the 8 mm pin stays within it
    assert (pins["diameter"], pins["length"]) == (3.0, 8.0)
    assert pins["designation"] == "ISO 8734 3 x 8 - A - St"
    # H7 on 3 mm: 0 / +10 um; m6: +2 / +8 um: the largest clearance 10 - 2 = 8 um
    assert pins["clearance_max_mm"] == pytest.approx(0.008)
    assert dowel_pins("M4", 12.0)["designation"] == "ISO 8734 4 x 12 - A - St"
    # seats 68 mm apart, bores placed to 0.01 mm: atan((0.008 + 0.02) / 68) in arc minutes
    assert seat_misalignment(68.0, 0.008, 0.01) == pytest.approx(
        math.degrees(math.atan(0.028 / 68.0)) * 60.0)
    assert seat_misalignment(68.0, 0.008, 0.01) == pytest.approx(1.4156, abs=1e-4)


def test_the_dowel_holes_go_through_both_halves_in_the_flange():
    import shapely

    from cadgen.solids.machine_parts import dowel_positions, with_dowels
    from cadgen.solids.split_housing import split_housing

    housing = split_housing([(0.0, 0.0, 30.0), (70.0, 0.0, 20.0)], clearance=2.0, wall=4.0,
                            floor_wall=6.0, roof_wall=6.0, cavity_height=20.0,
                            z_cavity_bottom=0.0, parting_z=10.0, bolt_size="M4",
                            bolt_hole_diameter=4.5, segments=64)
    dowelled = with_dowels(housing)
    assert len(dowelled.dowels) == 2
    # the closed form counts the holes: it equals the solids' volume
    solid = (dowelled.base + dowelled.cover).volume()
    assert dowelled.volume == pytest.approx(solid, rel=1e-9)
    assert housing.volume - dowelled.volume == pytest.approx(
        2 * math.pi * 2.0**2 * (dowelled.flange_z[1] - dowelled.flange_z[0]), rel=0.01)
    outer = shapely.Polygon(housing.outer_outline)
    flange = shapely.Polygon(housing.flange_outline)
    positions = dowel_positions(housing)
    for x, y in positions:   # in the flange strip, clear of the wall and the edge
        point = shapely.Point(x, y)
        assert flange.contains(point.buffer(2.0)) and not outer.intersects(point.buffer(2.0))
    # far apart: the largest distance between any two bolt gaps' middles
    assert math.dist(*positions) > 0.8 * np.ptp(housing.flange_outline[:, 0])
    for half, z in ((dowelled.base, 9.0), (dowelled.cover, 11.0)):
        section = half.slice(z)   # a cross-section at that height
        holes = [shapely.Polygon(loop) for loop in section.to_polygons()]
        for x, y in positions:
            assert any(abs(p.area - math.pi * 4.0) < 0.05 * math.pi * 4.0
                       and p.contains(shapely.Point(x, y)) for p in holes), (z, x, y)


def test_a_printed_housings_seats_warn_of_their_tilt():
    from cadgen.report.content import check_warnings

    def report(tolerance):
        angle = math.degrees(math.atan((0.008 + 2 * tolerance) / 68.0)) * 60.0
        return {"solids": {"alignment": [{
            "housing": "gearbox1", "shaft": "A", "side": 1, "span_mm": 68.0,
            "dowel_clearance_mm": 0.008, "position_tolerance_mm": tolerance,
            "misalignment_arcmin": angle, "allowance_arcmin": 10.0, "passed": angle <= 10.0}]}}

    assert check_warnings(report(0.01)) == []
    [warning] = check_warnings(report(0.1))   # an FDM print places its bores to 0.1 mm
    assert warning["code"] == "seats_misaligned" and "10.5'" in warning["message"]


# ------------------------------------------------------------------ printing overhangs
def _t_shape():
    """A 20 x 20 x 4 plate on a 6 x 6 x 20 stem (its foot at z = 0), as one closed mesh."""
    import trimesh

    plate = trimesh.creation.box((20, 20, 4))
    plate.apply_translation((0, 0, 22))
    stem = trimesh.creation.box((6, 6, 20))
    stem.apply_translation((0, 0, 10))
    return trimesh.boolean.union([plate, stem], engine="manifold")


def test_overhang_by_hand_on_a_t_and_a_wedge():
    import trimesh

    from cadgen.solids.printing import overhang_area

    t = _t_shape()
    # on its stem's foot: the plate's underside less the stem, 400 - 36 mm^2, hangs
    assert overhang_area(t) == pytest.approx(400 - 36, rel=1e-9)
    flipped = np.diag([1.0, -1.0, -1.0, 1.0])   # turned over: on the plate, nothing hangs
    assert overhang_area(t, flipped) == pytest.approx(0.0, abs=1e-9)
    # a wedge's sloped underside, 10 mm wide: it hangs when it is more than 45 deg from the
    # vertical (40 deg from the bed), not when it is 40 deg from the vertical (50 from the bed)
    for slope_deg, hangs in ((40.0, True), (50.0, False)):
        run = 20.0
        rise = run * math.tan(math.radians(slope_deg))
        # a triangular prism: its sloped face rises from the bed edge (0, z=0) to (run, rise),
        # the rest of it above the slope; a vertical wall at x = run stands on the bed
        profile = np.array([[0.0, 0.0], [run, rise], [run, rise + 5.0], [0.0, 5.0]])
        wedge = trimesh.creation.extrude_polygon(
            __import__("shapely").Polygon(profile), 10.0)
        # the polygon is in x-y; stand it up so y is the height and the extrusion runs along y
        wedge.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [1, 0, 0]))
        wedge.apply_translation(-wedge.bounds[0])
        slope_area = 10.0 * math.hypot(run, rise)
        expected = slope_area if hangs else 0.0
        # the slope's lowest edge touches the bed, so it is not "on the bed" as a whole
        assert overhang_area(wedge) == pytest.approx(expected, rel=1e-6), slope_deg


@settings(max_examples=20, deadline=None)
@given(quaternion=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: sum(v * v for v in q) > 0.1))
def test_the_least_overhang_pose_finds_the_face_with_none_however_the_part_is_turned(quaternion):
    import trimesh

    from cadgen.solids.printing import least_overhang_pose, overhang_area

    t = _t_shape()
    q = np.array(quaternion) / np.linalg.norm(quaternion)
    t.apply_transform(trimesh.transformations.quaternion_matrix(q))
    pose, overhang = least_overhang_pose(t)
    assert overhang == pytest.approx(0.0, abs=1e-6)
    assert overhang_area(t, pose) == pytest.approx(overhang, abs=1e-9)
    placed = t.copy().apply_transform(pose)
    assert placed.bounds[0, 2] == pytest.approx(0.0, abs=1e-9)
    assert np.ptp(placed.vertices[:, 2]) == pytest.approx(24.0, abs=1e-6)   # plate down, stem up


def test_the_pricking_parts_stls_are_single_clean_shells(tmp_path):
    """The rocker with its hub boss and needle holder, the needle and the rest: each STL, read
    back, is one watertight shell with no zero-area facet (a boss coincident with the bar's
    end once left 124 slivers that admesh removed, splitting the rocker into 31 parts)."""
    import io

    import trimesh

    import cadgen.pipeline.build as build_module
    from cadgen.export.meshes import stl_bytes
    from cadgen.params import load_params

    made = {}
    original = build_module.STAGE_FUNCTIONS["parts"]

    def keep(run):
        made["parts"] = original(run)
        return made["parts"]

    functions = dict(build_module.STAGE_FUNCTIONS, parts=keep)
    params = load_params("params/kernel-b.toml")
    run = build_module._Build(params, ["kinematics", "metrics", "drivetrain", "parts"], None)
    run.effects, run.case = ["solids"], "field"
    run.run(functions)
    for part in made["parts"].assembly.parts:
        if part.kind in ("ground", "sprocket"):
            continue
        mesh = trimesh.load(io.BytesIO(stl_bytes(part.mesh)), file_type="stl")
        assert mesh.is_watertight and len(mesh.split(only_watertight=False)) == 1, part.name
        assert float(np.min(mesh.area_faces)) > 1e-9, part.name
