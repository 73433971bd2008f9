"""The mechanisms' solids: closed parts, gear volumes, housings enclosing their gears, files.

Independent sources: the shoelace area of each gear's cut outline times its face
width; manifold3d booleans of placed gears against their housing (a second
method beside the report's disc-in-cavity check); the cam law's mouth width
against the blades' placed vertices; the kinematic envelope circles against the
solid housing's lowest point; volumes read back from the written files.
"""

import dataclasses
import math

import numpy as np
import pytest

from cadgen.design import pricking_design, pricking_field
from cadgen.export.meshes import assembly_bytes, load_volume, stl_bytes
from cadgen.gears.trains import pricking_train
from cadgen.params import ParameterError, load_params, validate_text
from cadgen.params.planting import Gearbox2Envelope
from cadgen.solids.split_housing import flange_width, split_encloses
from cadgen.solids.outline import signed_area
from cadgen.solids.parts import gear_solid
from cadgen.solids.planting import planting_assembly
from cadgen.solids.pricking import pricking_assembly
from cadgen.solids.outcome import solids_outcome as _solids_outcome, solids_report
from kinematics.errors import DesignError

from helpers import REFERENCE, reference_text

KERNEL_B = REFERENCE.parent / "kernel-b.toml"


@pytest.fixture(scope="module")
def planting(planting_solids):
    return planting_solids


@pytest.fixture(scope="module")
def pricking():
    params = load_params(KERNEL_B)
    design = pricking_design(params)
    field = pricking_field(params, design)
    train = pricking_train(params, design)
    assembly, housings = pricking_assembly(params, design, train, field)
    return params, design, train, assembly, housings


def _to_manifold(part, transform):
    return part.solid.transform(transform[:3, :])


@pytest.mark.parametrize("which", ["planting", "pricking"])
def test_every_part_is_a_closed_positive_volume(which, request):
    assembly = request.getfixturevalue(which)[-3 if which == "planting" else -2]
    kinds = set()
    for part in assembly.parts:
        mesh = part.mesh
        assert mesh.is_watertight and mesh.is_winding_consistent, part.name
        assert mesh.volume > 0, part.name
        kinds.add(part.kind)
    expected = ({"gear", "housing", "shaft", "spacer", "cam", "planter", "blade", "ground"}
                if which == "planting" else {"gear", "housing", "shaft", "spacer", "rocker", "needle",
                                             "ground",
                                             "sprocket"})
    assert kinds == expected


@pytest.mark.parametrize("which", ["planting", "pricking"])
def test_gear_volume_is_outline_area_times_face_width(which, request):
    fixture = request.getfixturevalue(which)
    params, assembly = fixture[0], fixture[-3 if which == "planting" else -2]
    gears = [p for p in assembly.parts if p.kind == "gear"]
    assert gears
    for part in gears:
        bottom, top = part.mesh.bounds[:, 2]
        face = top - bottom
        area = signed_area(part.outline)
        bore = params.gears.bore_diameter / 2
        if bore > 0:
            n = params.solids.segments_per_circle
            area -= n / 2 * bore**2 * math.sin(2 * math.pi / n)
        # a gear held by a set screw has its tapped hole drilled through the rim: less what a
        # tap drill's cylinder along the screw's axis takes from the gear as cut
        drilled = sum(_drilled(fixture, part, item) for item in part.bought
                      if item.kind == "set screw")
        assert part.mesh.volume == pytest.approx(area * face - drilled, rel=1e-9), part.name


def _drilled(fixture, gear, screw) -> float:
    """The volume an ISO 2306 tap drill along ``screw``'s axis, from the gear's axis out past
    its outline, takes from the gear as cut (its extrusion from the train's profile)."""
    from cadgen.machine.fixings import TAP_DRILL
    from cadgen.solids.extrude import manifold3d_engine

    params, train = fixture[0], fixture[4]
    profile = next(p for p, _, _, _ in train.gears if p.file_stem == gear.name)
    face = float(np.ptp(gear.mesh.bounds[:, 2]))
    cut, _ = gear_solid(profile, face, params.solids.segments_per_circle, "gears.face_width",
                        params.gears.chord_tolerance)
    radius = TAP_DRILL[f"M{screw.size['d']:g}"] / 2
    reach = float(np.hypot(*np.asarray(gear.outline).T).max()) + 1.0
    frame = np.array(screw.at, dtype=float)
    axis = frame[:3, 2]
    frame[:3, 3] -= axis * float(axis @ frame[:3, 3])   # the screw's line at the gear's axis
    drill = manifold3d_engine().Manifold.cylinder(reach, radius, radius, 96)
    return (cut ^ drill.transform(frame[:3, :])).volume()


def test_gears_with_a_bore_keep_it(planting):
    profile = dataclasses.replace(planting[4].gears[0][0], bore_radius=5.0)
    solid, outline = gear_solid(profile, 10.0, 64, "gears.face_width", 0.005)
    hole = 64 / 2 * 5.0**2 * math.sin(2 * math.pi / 64)   # the bore is an inscribed 64-gon
    assert solid.volume() == pytest.approx((signed_area(outline) - hole) * 10.0, rel=1e-9)


def test_planting_housings_enclose_their_gears_checked_with_booleans(planting):
    from helpers import gears_in_their_housings

    *_, assembly, housings, _ = planting
    box = dict(zip(("gearbox1", "gearbox2", "frame"), housings))
    for phi in (0.0, 1.234, 4.0):
        for part, _, housing, local in gears_in_their_housings(assembly, housings, phi):
            inside, outside = split_encloses(housing, _to_manifold(part, local))
            assert inside, (part.name, phi, outside)
            # and they cut neither half of the split housing
            placed = _to_manifold(part, local)
            assert (placed ^ housing.base).is_empty() and (placed ^ housing.cover).is_empty()
    report = _solids_outcome(planting[0], assembly, box).enclosure
    assert all(row["gears_enclosed"] for row in report)
    assert {row["nearest_gear"] for row in report} <= {p.name for p in assembly.parts}


def test_a_housing_too_small_for_its_gears_is_reported(planting):
    """Explicit envelope radii 8 mm short at C: the central gear cuts into gearbox 2's wall."""
    params, mechanism, evaluation, cam, train, *_ = planting
    from cadgen.solids.housings import housing_circles

    radius_c = next(c.radius for c in housing_circles(params, mechanism)
                    if (c.gearbox, c.point) == ("gearbox2", "C"))
    small = params.model_copy(update={"housing": params.housing.model_copy(update={
        "gearbox2": Gearbox2Envelope(C=radius_c - 8.0)})})
    assembly, housings, _ = planting_assembly(small, mechanism, train, cam,
                                              evaluation.events.soil_level)
    rows = {r["housing"]: r for r in _solids_outcome(
        small, assembly, {"gearbox1": housings[0], "gearbox2": housings[1]}).enclosure}
    assert not rows["gearbox2"]["gears_enclosed"] and rows["gearbox2"]["nearest_gear"] == "central"
    # the cavity still holds the hull's tangents towards D, so somewhat less than 8 mm is lost
    assert -8.0 - 0.05 < rows["gearbox2"]["smallest_margin_mm"] < 0.0
    central = next(p for p in assembly.parts if p.name == "central")
    # and the booleans agree: at some pose the central gear pokes into the wall
    assert any(not split_encloses(housings[1], _to_manifold(central, central.local(phi)))[0]
               for phi in np.linspace(0, 2 * np.pi, 12, endpoint=False))


def test_pricking_case_encloses_its_gears(pricking):
    *_, assembly, housings = pricking
    case = housings["gear-case"]
    for angle in (0.0, 2.0, 4.5):
        for part in (p for p in assembly.parts if p.kind == "gear"):
            inside, outside = split_encloses(case, _to_manifold(part, part.local(angle)))
            assert inside, (part.name, angle, outside)


def test_pricking_needle_tip_follows_the_designed_loop(pricking):
    params, design, _, assembly, _ = pricking
    needle = next(p for p in assembly.parts if p.name == "needle")
    for angle in (0.0, 1.0, 3.0, 5.5):
        pose = assembly.body_pose("planet", angle)
        vertices = needle.mesh.vertices @ pose[:3, :3].T + pose[:3, 3]
        # the needle's point is its one vertex farthest from B; it must sit on the loop
        far = vertices[np.argmax(np.linalg.norm(vertices[:, :2] - pose[:2, 3], axis=1))]
        start = design.motion.phi1_start  # the assembly's carrier angle counts from Rmax
        v = design.motion.invert(np.array([start + design.motion.sense * angle]))
        assert np.linalg.norm(far[:2] - design.motion.tip(v)[0]) < 1e-6


def test_blades_open_to_the_mouth_the_cam_gives(planting):
    params, mechanism, evaluation, cam, *_ = planting
    assembly = planting[5]
    phi = 0.5 * (cam.timing.opening[1] + cam.timing.closing[0])   # held open
    tips = []
    for name, part, pose in assembly.placements(phi):
        if part.kind == "blade" and name.endswith("arm1"):
            world = part.mesh.vertices @ pose[:3, :3].T + pose[:3, 3]
            # the blade tip: its vertex nearest the closed tip N, taken in the planter frame
            planter = np.linalg.inv(assembly.body_pose("planter", phi))
            local = world @ planter[:3, :3].T + planter[:3, 3]
            tips.append(local[np.argmin(local[:, 1])])
    width = abs(tips[0][0] - tips[1][0])
    assert width == pytest.approx(cam.linkage.mouth_width(cam.linkage.opening_angle), abs=1e-6)
    assert width >= params.cam.pot_diameter


def test_solid_housing_matches_the_kinematic_ground_clearance(planting):
    """The housing's outermost edge (the parting flange) is its wall's hull of circumscribed
    polygons offset by the flange width, and the envelope circles are the gears' discs grown by
    clearance, wall and flange: the solid reaches at most the polygons' sag r (1/cos(pi/n) - 1)
    beyond them and never falls inside them; its side wall stands one flange width inside."""
    params, mechanism, evaluation, *_ = planting
    assembly, housings = planting[5], planting[6]
    phi = math.radians(evaluation.extras["ground_clearance_at_deg"])
    lowest, lowest_wall, flange = np.inf, np.inf, 0.0
    for name, part, pose in assembly.placements(phi):
        if part.kind == "housing":
            world = part.mesh.vertices @ pose[:3, :3].T + pose[:3, 3]
            lowest = min(lowest, world[:, 1].min())
            housing = housings[0 if name.startswith("gearbox1") else 1]
            outline = housing.outer_outline @ pose[:2, :2].T + pose[:2, 3]
            if outline[:, 1].min() < lowest_wall:
                lowest_wall = outline[:, 1].min()
                flange = flange_width(housing.bolt_hole_diameter)
    kinematic = next(m.value for m in evaluation.metrics if m.key == "ground_clearance")
    n = params.solids.segments_per_circle
    bound = max(c.radius for c in evaluation.housing_circles) * (1 / math.cos(math.pi / n) - 1)
    solid_clearance = lowest - evaluation.events.soil_level
    assert kinematic - bound - 1e-9 <= solid_clearance <= kinematic + 1e-9
    wall_clearance = lowest_wall - evaluation.events.soil_level
    assert kinematic + flange - bound - 1e-9 <= wall_clearance <= kinematic + flange + 1e-9


def test_shafts_clear_the_housings_and_the_cam_is_bored_for_e(planting):
    """Every shaft runs in its seats and holes without touching the housing's material; side
    instances and arm instances as the gears'; the cam's bore is E's running hole."""
    params, mechanism, *_, assembly, housings, _ = planting
    from cadgen.machine.drivetrain import drivetrain

    machine = drivetrain(params, mechanism)
    shafts = {p.name: p for p in assembly.parts if p.kind == "shaft"}
    # C2 of side 2 is a part of its own: its central-gear keyseat is half a turn from side 1's
    assert set(shafts) == {f"shaft-{s.name}" for s in machine.shafts} | {"shaft-C2-arm2"}
    assert [i[0] for i in shafts["shaft-C2"].instances] == ["shaft-C2-side1"]
    assert [i[0] for i in shafts["shaft-C2-arm2"].instances] == ["shaft-C2-arm2"]
    assert [i[0] for i in shafts["shaft-A"].instances] == ["shaft-A-side1", "shaft-A-side2"]
    assert [i[0] for i in shafts["shaft-E"].instances] == ["shaft-E-arm1", "shaft-E-arm2"]
    # in the world, every shaft instance against every housing half placed: a shaft passing
    # another housing (O through gearbox 1's floor, C2 through gearbox 2's) or bolted to it
    # (the flanges of S and C) touches none of its material either
    for phi in (0.0, 2.1):
        placed = [(name, part, pose) for name, part, pose in assembly.placements(phi)]
        halves = [(name, _to_manifold(part, pose)) for name, part, pose in placed
                  if part.kind == "housing"]
        for name, part, pose in placed:
            if part.kind != "shaft":
                continue
            solid = _to_manifold(part, pose)
            for other, half in halves:
                assert (solid ^ half).volume() < 1e-6, (name, other, phi)
    e = next(s for s in machine.shafts if s.name == "E")
    hole = next(seat.hole_diameter for seat in e.seats if seat.wall == "roof")
    cam = next(p for p in assembly.parts if p.name == "cam")
    n = params.solids.segments_per_circle
    bore_area = n / 2 * (hole / 2) ** 2 * math.sin(2 * math.pi / n)
    assert cam.mesh.volume == pytest.approx(
        (signed_area(cam.outline) - bore_area) * params.cam.thickness, rel=1e-9)


def test_stl_and_assembly_round_trip_with_the_same_volume(planting, tmp_path):
    assembly = planting[5]
    for part in assembly.parts[:4] + [p for p in assembly.parts if p.kind == "blade"]:
        data = stl_bytes(part.mesh)
        assert load_volume(data, "stl") == pytest.approx(part.mesh.volume, rel=1e-6)
    placed = [(name, part.mesh, pose) for name, part, pose in assembly.placements(0.7)]
    total = sum(part.mesh.volume for _, part, _ in assembly.placements(0.7))
    for kind, rtol in (("glb", 1e-6), ("3mf", 1e-9)):
        data = assembly_bytes(placed, kind)
        assert load_volume(data, kind) == pytest.approx(total, rel=rtol)


def _section_moments(ring) -> np.ndarray:
    """``[A, int x dA, int y dA, int x^2 dA, int y^2 dA]`` of a closed ring (either way round,
    counted positive) by Green's theorem."""
    x, y = np.asarray(ring, dtype=float).T
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    moments = np.array([cross.sum() / 2, ((x + x1) * cross).sum() / 6,
                        ((y + y1) * cross).sum() / 6,
                        ((x * x + x * x1 + x1 * x1) * cross).sum() / 12,
                        ((y * y + y * y1 + y1 * y1) * cross).sum() / 12])
    return moments * np.sign(moments[0])


def test_mass_properties_against_closed_forms(planting):
    params = planting[0]
    report = solids_report(_solids_outcome(params, planting[5], {
        "gearbox1": planting[6][0], "gearbox2": planting[6][1]}))
    rows = {row["part"]: row for row in report["parts"]}
    # machined gears are steel, here the file's 42CrMo4+QT: 7850 kg/m^3 (EN 10083 data sheet),
    # 1e-9 kg/mm^3 per kg/m^3
    assert params.manufacturing.process == "machined"
    for name in ("sun", "idler-1", "central"):
        row = rows[name]
        assert row["material"] == "steel 42CrMo4+QT" and row["density_kg_m3"] == 7850.0
        assert row["mass_kg"] == pytest.approx(row["volume_mm3"] * 7850.0e-9, rel=1e-12)
    # a circular gear is symmetric about its axis but for its keyway: centre of mass mid-face,
    # off the axis by at most the keyway's area times its reach over the section's area
    from cadgen.design import build_mechanism
    from cadgen.machine.drivetrain import drivetrain

    sun = rows["sun"]
    face = params.gears.face_width_for(1.8)
    _, mount = drivetrain(params, build_mechanism(params)).shaft_of_gear("sun")
    reach = mount.hub_bore / 2 + mount.key.hub_depth
    section = math.pi * (30.0**2 - reach**2)          # at least: the root circle minus the hole
    bound = mount.key.width * mount.key.hub_depth * reach / section
    assert sun["centre_of_mass_mm"][2] == pytest.approx(face / 2, abs=1e-9)
    assert math.hypot(*sun["centre_of_mass_mm"][:2]) <= bound
    inertia = np.array(sun["inertia_kg_mm2"])
    # the prism of its section (Green's theorem on the outline and the hole, about the
    # centroid): I_xx = rho t Iy2 + m t^2/12, I_yy = rho t Ix2 + m t^2/12, I_zz = rho t (Ix2 + Iy2)
    part = next(p for p in planting[5].parts if p.name == "sun")
    profile = next(p for s in planting[4].stages for p in s.generated.profiles
                   if p.name == "sun")
    from cadgen.solids.outline import circle

    holes = ([np.asarray(profile.hole)] if getattr(profile, "hole", None) is not None
             else [circle(profile.bore_radius, params.solids.segments_per_circle, profile.centre)]
             if profile.bore_radius > 0 else [])
    moments = _section_moments(part.outline) - sum(_section_moments(h) for h in holes)
    area, (cx, cy), rho = moments[0], moments[1:3] / moments[0], 7850.0e-9
    ix2, iy2 = moments[3] - area * cx**2, moments[4] - area * cy**2
    mass = rho * face * area
    assert sun["mass_kg"] == pytest.approx(mass, rel=1e-9)
    assert inertia[0, 0] == pytest.approx(rho * face * iy2 + mass * face**2 / 12, rel=1e-9)
    assert inertia[1, 1] == pytest.approx(rho * face * ix2 + mass * face**2 / 12, rel=1e-9)
    assert inertia[2, 2] == pytest.approx(rho * face * (ix2 + iy2), rel=1e-9)
    # and nearly axisymmetric (a z-fold gear thinned to its chord tolerance, less its keyway)
    assert inertia[0, 0] == pytest.approx(inertia[1, 1], rel=1e-3)
    # between the solid discs of the root and the tip radius: m r^2 / 2
    tip = 36.0 + 1.8
    assert 0.5 * sun["mass_kg"] * 30.0**2 < inertia[2, 2] < 0.5 * sun["mass_kg"] * tip**2
    assert report["total_mass_kg"] == pytest.approx(
        sum(r["mass_kg"] * r["instances"] for r in report["parts"]), rel=1e-12)


@pytest.mark.parametrize("changes, path, code", [
    (dict(face_width="0.0"), "gears.face_width", "out_of_range"),
    (dict(wall="1.0"), "housing.wall", "wall_too_thin"),
])
def test_bad_solid_parameters_name_the_field(changes, path, code):
    text = _with_keys(changes)
    with pytest.raises(ParameterError) as caught:
        validate_text(text)
    assert (path, code) in {(p.path, p.code) for p in caught.value.problems}


def _with_keys(changes):
    """The reference file with keys added to [housing] or [gears] (added if missing)."""
    from tests.helpers import with_keys

    text = reference_text()
    for key, value in changes.items():
        text = with_keys(text, "housing" if key == "wall" else "gears", **{key: value})
    return text


def test_a_self_intersecting_gear_outline_is_refused_before_extrusion(planting):
    profile = planting[4].gears[0][0]
    outline = profile.outline.copy()
    k = len(outline) // 3
    outline[[k, k + 40]] = outline[[k + 40, k]]   # two far points swapped: the ring crosses itself
    with pytest.raises(DesignError) as caught:
        gear_solid(dataclasses.replace(profile, outline=outline), 10.0, 64, "gears.face_width",
                   chord_tolerance=1e-9)
    assert caught.value.problems[0].code == "self_intersecting_outline"
    assert "central" in caught.value.problems[0].path


def test_assembly_is_deterministic(planting):
    assembly = planting[5]
    placed = [(name, part.mesh, pose) for name, part, pose in assembly.placements(0.3)]
    again = [(name, mesh.copy(), pose.copy()) for name, mesh, pose in placed]
    assert assembly_bytes(placed, "glb") == assembly_bytes(again, "glb")


def test_ridge_ground_has_the_profile_it_was_given():
    from cadgen.params.solids import GroundParameters
    from cadgen.solids.ground import ground_part

    ground = GroundParameters(profile="ridge", ridge_top_width=300.0, ridge_height=150.0,
                              ridge_side_slope_deg=45.0, furrow_width=200.0, thickness=100.0,
                              margin=0.0)
    part = ground_part(ground, -500.0, (-400.0, 600.0), (0.0, 100.0), ridge_centre=50.0,
                       segments=32)
    mesh = part.mesh
    assert mesh.is_watertight and mesh.is_winding_consistent
    # the section: slab under the furrows (width W x 100) plus the trapezoidal ridge
    (x0, y0, z0), (x1, y1, z1) = mesh.bounds
    width = z1 - z0
    ridge = 0.5 * (300.0 + 300.0 + 2 * 150.0) * 150.0     # 45 deg sides: 150 mm runs
    assert (x1 - x0, y1) == pytest.approx((1000.0, -500.0))
    assert mesh.volume == pytest.approx((width * 100.0 + ridge) * 1000.0, rel=1e-12)
    # the ridge top is centred on z = 50 and 300 mm wide at the soil level
    top = mesh.vertices[np.isclose(mesh.vertices[:, 1], -500.0)]
    assert (top[:, 2].min(), top[:, 2].max()) == pytest.approx((-100.0, 200.0))
