"""The duckbill linkage as parts: its return spring by hand (EN 13906-1), the follower's loads by a
second route, the parts following the cam law in the assembly, the joint graph and the bill."""

import math

import numpy as np
import pytest

from cadgen.cam.design import design_cam
from cadgen.design import build_mechanism, evaluate
from cadgen.machine.duckbill import PIN_DIAMETERS
from cadgen.machine.follower import Body, GRAVITY, follower_forces
from cadgen.machine.springs import design_compression_spring, wahl_factor
from cadgen.params import load_params

PAPER = "params/xin2024-planter.toml"


# ------------------------------------------------------------------ the spring, by hand
def test_a_spring_by_hand_from_en_13906_1():
    # one wire (1.0 mm, EN 10270-1 DH: Rm 2230 MPa) round a 9 mm rod: D = 10 mm (index 10);
    # 14 mm of room for a 5 mm stroke leaves 7 mm for the coils at their least working length:
    # a coil takes d + 1.5 (0.0015 D^2 / d + 0.1 d) = 1.375 mm and the two closed end coils
    # 2 mm, so 5 active coils (5 x 1.375 + 2 = 8.875 <= 14 - 5)
    spring, why = design_compression_spring(10.0, 5.0, 14.0, inside_min=9.0, outside_max=20.0,
                                            wires=[(1.0, 2230.0, 2470.0)])
    assert why == ""
    assert (spring.wire, spring.mean_diameter, spring.active_coils) == (1.0, 10.0, 5.0)
    rate = 81_500 * 1.0**4 / (8 * 10.0**3 * 5)                 # 2.0375 N/mm
    assert spring.rate == pytest.approx(2.0375)
    assert spring.free_length == pytest.approx(14.0 + 10.0 / rate)   # 18.908 mm
    assert spring.preload == pytest.approx(10.0)
    assert spring.force_max == pytest.approx(10.0 + 2.0375 * 5.0)     # 20.1875 N
    wahl = 39 / 36 + 0.615 / 10                                 # (4w - 1)/(4w - 4) + 0.615/w
    assert wahl_factor(10.0) == pytest.approx(wahl) == pytest.approx(1.144833, abs=1e-6)
    stress = wahl * 8 * 10.0 * 20.1875 / math.pi                # 588.53 MPa
    assert spring.stress_max == pytest.approx(stress) == pytest.approx(588.525, abs=0.001)
    assert spring.stress_allowed == 1115.0 and spring.utilisation == pytest.approx(stress / 1115)
    assert spring.solid_length == 7.0 and spring.total_coils == 7.0
    assert spring.least_working_length == pytest.approx(7.0 + 1.875)
    assert spring.working_length == pytest.approx(9.0)
    assert spring.working_length >= spring.least_working_length
    # (pi D / (0.5 L0))^2 (1 - G/E) / (0.5 + G/E) > 1: no real root, it cannot buckle
    assert spring.buckling_deflection is None


def test_a_spring_too_weak_for_its_force_is_refused_with_the_reason():
    spring, why = design_compression_spring(400.0, 5.0, 14.0, inside_min=9.0, outside_max=20.0,
                                            wires=[(1.0, 2230.0, 2470.0)])
    assert spring is None and "0.5 Rm" in why


# ------------------------------------------------------------------ the follower's loads
class _StillFrame:
    """A planter frame that does not move (E fixed, no turn), the cam turning as the carrier."""

    class closure:
        class law:
            @staticmethod
            def ratio(phi):
                return np.ones_like(phi), np.zeros_like(phi)

    @staticmethod
    def attitude_derivatives(phi):
        return np.zeros_like(phi), np.zeros_like(phi), np.zeros_like(phi)

    @staticmethod
    def motion(phi, point):
        class Motion:
            acceleration = np.zeros((len(phi), 2))
        return Motion


@pytest.fixture(scope="module")
def cam():
    params = load_params(PAPER)
    mechanism = build_mechanism(params)
    return params, mechanism, design_cam(params, mechanism, evaluate(params, mechanism).events)


def test_a_push_rod_alone_needs_its_weight_less_its_own_acceleration(cam):
    # a 100 g rod on the duckbill axis, the frame still, the cam at 60 r/min: the spring must
    # hold m (g - s''), s the rod's travel down (Newton, along the axis)
    _, _, design = cam
    rod = Body("rod", "rod", 0.1, 0.0, (-130.0, -60.0))
    forces = follower_forces(design.linkage, design.profile, lambda phi: phi, _StillFrame,
                             [rod], 60.0, samples=7200)
    omega = 2 * math.pi
    # s = l_HG sin(lambda), lambda(t) = law(omega t): s'' = l_HG (cos(lambda) lambda'' -
    # sin(lambda) lambda'^2), the law's own derivatives times omega and omega^2
    lam, lam_1, lam_2 = design.profile.program(forces.phi)
    arm = design.linkage.rod_arm * 1e-3
    acceleration = arm * (np.cos(lam) * lam_2 - np.sin(lam) * lam_1**2) * omega**2
    assert np.abs(acceleration).max() > 1.0     # the law, not gravity alone, is being checked
    np.testing.assert_allclose(forces.needed_spring_force, 0.1 * (GRAVITY - acceleration),
                               atol=1e-6)
    assert forces.required_preload == pytest.approx(2 * forces.needed_spring_force.max())


def test_the_paper_linkage_keeps_its_roller_on_the_cam(cam):
    params, mechanism, design = cam
    from cadgen.machine.drivetrain import drivetrain

    duckbill = drivetrain(params, mechanism, design).fixings["duckbill"]
    spring, follower = duckbill["spring"], duckbill["follower"]
    assert follower["carrier_speed_rpm"] == params.field.carrier_speed_rpm
    assert spring["preload"] >= 2.0 * follower["needed_spring_force_max_n"] - 1e-9
    assert spring["force_max"] == pytest.approx(spring["preload"] + spring["rate"]
                                                * spring["stroke"])
    assert spring["stroke"] == pytest.approx(design.linkage.stroke)
    assert spring["utilisation"] < 1.0 and not spring["buckles"]
    assert spring["working_length"] >= spring["least_working_length"]
    # with gravity pulling the roller off at every pose, the cam still pushes it
    assert 0.0 < follower["contact_force_min_n"] < follower["contact_force_max_n"]
    # its wire's Rm is EN 10270-1 DH's least for that diameter, half of it allowed
    from cadgen.machine.pins import spring_wires

    assert spring["tensile_strength"] == dict((d, rm) for d, rm, _ in spring_wires())[
        spring["wire"]] == 2 * spring["stress_allowed"]


# ------------------------------------------------------------------ the assembly
@pytest.fixture(scope="module")
def paper(cam):
    from cadgen.machine.drivetrain import drivetrain
    from cadgen.solids.planting import planting_assembly

    params, mechanism, design = cam
    machine = drivetrain(params, mechanism, design)
    assembly, _, layout = planting_assembly(params, mechanism, None, design, None,
                                            drivetrain=machine)
    return params, mechanism, design, machine, assembly, layout


def _placed(assembly, phi):
    return {name: (part, pose) for name, part, pose in assembly.placements(phi)}


def _at(pose, xy, z=0.0):
    return (pose @ np.array([xy[0], xy[1], z, 1.0]))[:2]


@pytest.mark.parametrize("phi_deg", [0.0, 190.0, 200.0, 213.3, 225.0, 250.0],
                         ids=lambda v: f"{v:g}deg")
def test_the_linkage_follows_the_cam_law_in_the_assembly(paper, phi_deg):
    params, mechanism, design, machine, assembly, _ = paper
    fixing = machine.fixings["duckbill"]
    points, ell = fixing["points"], fixing["link"]["length"]
    placed = _placed(assembly, math.radians(phi_deg))
    for arm in ("arm1", "arm2"):
        _, lever = placed[f"lever-{arm}"]
        _, rod = placed[f"push-rod-{arm}"]
        for side, sign in (("right", 1.0), ("left", -1.0)):
            _, link = placed[f"blade-link-{side}-{arm}"]
            _, blade = placed[f"blade-{side}-{arm}"]
            near, far = _at(link, (0.0, 0.0)), _at(link, (ell, 0.0))
            assert np.linalg.norm(far - near) == pytest.approx(ell, abs=1e-9)
            crank = np.array(points["J"])
            if sign < 0:
                crank[0] = -2 * fixing["L1"] - crank[0]
            assert np.allclose(near, _at(blade, crank), atol=1e-9)     # on the blade's crank
            assert np.allclose(far, _at(rod, points["P2"]), atol=1e-9)  # on the rod's end
        # the lever's pin G lies in the rod's slot (a stadium along x round G at rest)
        g = np.linalg.solve(rod, lever @ np.array([*points["G"], 0.0, 1.0]))[:2]
        slot, pin = fixing["rod"], PIN_DIAMETERS["G"]
        assert abs(g[1] - points["G"][1]) <= (slot["slot_width"] - pin) / 2 + 1e-9
        assert abs(g[0] - points["G"][0]) <= (slot["slot_length"] - pin) / 2 + 1e-9
        # the roller (its centre on the lever at I) touches the cam's contour
        cam_part, cam_pose = placed[f"cam-{arm}"]
        centre = np.linalg.solve(cam_pose, lever @ np.array([*points["I"], 0.0, 1.0]))[:2]
        contour = np.asarray(cam_part.outline)
        a, b = contour, np.roll(contour, -1, axis=0)
        t = np.clip(np.sum((centre - a) * (b - a), axis=1) / np.sum((b - a) ** 2, axis=1), 0, 1)
        distance = np.min(np.linalg.norm(a + t[:, None] * (b - a) - centre, axis=1))
        assert distance == pytest.approx(params.cam.roller_radius,
                                         abs=2 * params.gears.chord_tolerance + 1e-6)


def test_the_model_holds_the_linkage_with_one_freedom_and_the_bill_buys_it(paper):
    from cadgen.assembly.machine import planting_model
    from cadgen.gears.trains import planting_train
    from cadgen.report.bom import _bought_rows

    params, mechanism, _, machine, assembly, _ = paper
    model = assembly.model
    for arm in ("arm1", "arm2"):
        for part in ("lever", "push-rod", "blade-link-right", "blade-link-left"):
            assert f"{part}-{arm}" in model.parts
        kinds = {(j.kind, j.a, j.b) for j in model.joints}
        assert ("slot", f"lever-{arm}", f"push-rod-{arm}") in kinds
        assert ("prismatic", f"push-rod-{arm}", f"planter-shell-{arm}") in kinds
        assert ("cam", f"lever-{arm}", f"cam-{arm}") in kinds
        assert not any(j.kind == "cam" and j.a.startswith("blade") for j in model.joints)
    # with the gear train's meshes the machine still has the one freedom of its drive
    train = planting_train(params, mechanism, drive=machine.drive)
    full = planting_model(machine, [tuple(s.generated.pair.names) for s in train.stages])
    assert full.mobility() == 1 and not full.redundant_joints() and not full.unconnected()
    instances = {name for part in assembly.parts for name, _, _ in part.instances}
    rows = {(r["part"], r["designation"]): r["quantity"]
            for r in _bought_rows(model, instances)}

    def count(kind):
        return sum(q for (part, _), q in rows.items() if part == kind)

    # per arm: pins at H, G, P2, two at J, two at O1, each with a washer and a split pin
    assert count("clevis pin") == count("washer") == count("split pin") == 2 * 7
    # the roller pin's DIN 471 4 mm ring (the shafts' own rings are larger: machine.retention)
    assert count("compression spring") == count("parallel pin") == 2
    assert rows[("retaining ring", "DIN 471 4 x 0.4")] == 2
    assert rows[("bearing", "604")] == 2                 # the rollers, 12 mm across
    assert rows[("clevis pin", machine.fixings["duckbill"]["pins"]["G"]["designation"])] == 2
    made = {part.name: len(part.instances) for part in assembly.parts}
    assert all(made[name] == 2 for name in ("lever", "push-rod", "blade-link-right",
                                            "blade-link-left"))


@pytest.mark.parametrize("phi_deg", [0.0, 200.0, 225.0], ids=lambda v: f"{v:g}deg")
def test_no_linkage_part_runs_into_another_closed_or_open(paper, phi_deg):
    from cadgen.solids.overlaps import overlap_check
    from cadgen.solids.parts import Assembly

    params, _, _, _, assembly, _ = paper
    arm = Assembly([p for p in assembly.parts if p.body in ("planter", "gearbox2")],
                   assembly.body_pose, assembly.model)
    result = overlap_check(arm, math.radians(phi_deg), segments=params.solids.segments_per_circle)
    assert result["passed"], result["failures"]
    assert result["pairs_examined"] > 20


def test_the_masses_the_spring_is_sized_with_are_the_solids_or_heavier(paper):
    params, _, _, machine, assembly, _ = paper
    from cadgen.machine.fits import process_fits

    fits = process_fits(params.manufacturing.process)
    estimated = {b["name"]: b["mass_kg"] for b in machine.fixings["duckbill"]["bodies"]}
    parts = {p.name: p for p in assembly.parts}
    for name, part in (("lever", "lever"), ("link right", "blade-link-right"),
                       ("push rod", "push-rod"), ("blade right", "blade-right")):
        solid = parts[part].mesh.volume * fits.material(parts[part].kind).density * 1e-9
        # plates exactly; the rod and the blades on the heavy side (the slot, the cuts round the
        # hinge ears are left out), which errs towards a stronger spring
        assert solid * 0.99 <= estimated[name] <= solid * 1.4, (name, estimated[name], solid)
    assert estimated["lever"] == pytest.approx(
        parts["lever"].mesh.volume * fits.material("lever").density * 1e-9, rel=0.01)


def test_the_roller_is_fitted_to_its_lever_before_the_lever_goes_on(paper):
    from cadgen.assembly.sequence import assembly_sequence

    steps = assembly_sequence(paper[4].model)
    assert [s["step"] for s in steps] == list(range(1, len(steps) + 1))
    for arm in ("arm1", "arm2"):
        roller = next(k for k, s in enumerate(steps)
                      if s["part"] == f"lever-{arm}" and s["joint"] == "cam")
        assert any("604" in b for b in steps[roller]["bought"])
        # the next step puts the lever (its roller on) onto its pivot in the planter's lug
        assert (steps[roller + 1]["part"], steps[roller + 1]["onto"]) == (
            f"lever-{arm}", f"planter-shell-{arm}")


@pytest.mark.parametrize("table, keys, path, code", [
    ("cam.lever", {"rod_arm": "110.0"}, "cam.lever.rod_arm", "rod_pin_off_axis"),
    ("cam", {"roller_radius": "9.0"}, "cam.roller_radius", "roller_not_in_catalogue"),
], ids=["rod-arm-off-the-axis", "roller-not-a-bearing"])
def test_a_linkage_that_cannot_be_made_fails_at_its_field(cam, tmp_path, table, keys, path, code):
    from cadgen.machine.drivetrain import drivetrain
    from tests.helpers import with_keys

    source = __import__("pathlib").Path(PAPER)
    file = tmp_path / source.name
    file.write_text(with_keys(source.read_text(encoding="utf-8"), table, **keys), encoding="utf-8")
    params = load_params(file)
    mechanism = build_mechanism(params)
    design = design_cam(params, mechanism, evaluate(params, mechanism).events)
    machine = drivetrain(params, mechanism, design)
    assert "duckbill" not in machine.fixings   # nothing of the linkage is made
    assert [(p.path, p.code) for p in machine.problems if p.path.startswith("cam")] == [
        (path, code)]


# ------------------------------------------------------------------ its bought items as solids
#: ISO 2341 B (table 1) by pin diameter: head dk, head k, split-pin hole d1, l_e min (the hole's
#: axis from the pin's end); ISO 8738: the washer's d2 and h; ISO 1234 by the hole d1: the legs'
#: d max and the eye's c max. Typed in from the standards' tables, not read from the catalogue.
ISO_2341 = {4.0: (6.0, 1.0, 1.0, 2.2), 5.0: (8.0, 1.6, 1.2, 2.9), 8.0: (14.0, 3.0, 2.0, 3.5)}
ISO_8738 = {4.0: (8.0, 0.8), 5.0: (10.0, 1.0), 8.0: (15.0, 2.0)}
ISO_1234 = {1.0: (0.9, 1.8), 1.2: (1.0, 2.0), 2.0: (1.8, 3.6)}
#: An open pose (the blades' largest opening) and the closed one.
POSES = (0.0, 213.3)


def _linkage_bought(assembly, kind=None):
    """The bought solids held by the planter's shell, blades and linkage (of ``kind``)."""
    linkage = {"planter-shell", "lever", "push-rod", "blade-right", "blade-left"}
    return [b for b in assembly.bought if b.host in linkage and (kind is None or b.kind == kind)]


def _diameter(part) -> float:
    """A pin's nominal diameter, read from its designation (ISO 2341 B d x l, ISO 2338 d m6 x l)."""
    import re

    return float(re.search(r"ISO 23\d\d (?:B )?([\d.]+)", part.designation).group(1))


def _length(part) -> float:
    """A pin's nominal length (from under its head), read from its designation."""
    import re

    return float(re.search(r" x ([\d.]+) - St$", part.designation).group(1))


def _copies_by_arm(part):
    """``{arm: instance}`` of a bought solid, its host's copies in order (arm 1 first)."""
    return dict(zip(("arm1", "arm2"), (name for name, _, _ in part.instances)))


def _hole_offset(solid, z, diameter, point) -> float:
    """Distance from ``point`` (x, y) to the centre of the nearest round hole of ``diameter``
    (its area within 2 %) in the section of ``solid`` at ``z``: the hole as cut, read back."""
    import shapely

    loops = [shapely.Polygon(loop) for loop in solid.slice(z).to_polygons()]
    area = math.pi * diameter**2 / 4
    centres = [np.asarray(p.centroid.coords[0]) for p in loops
               if abs(p.area - area) < 0.02 * area]
    assert centres, (z, diameter)
    return float(min(np.linalg.norm(c - np.asarray(point)[:2]) for c in centres))


@pytest.mark.parametrize("phi_deg", POSES, ids=lambda v: f"{v:g}deg")
def test_each_linkage_pin_is_coaxial_with_the_holes_cut_in_the_parts_it_joins(paper, phi_deg):
    """Every clevis pin and the roller's pin, closed and open, both arms: in the frame of each
    made part it is held by or fitted to, its axis is normal to the part's plates and passes
    through the centre of the round hole cut there, read from a section of the solid through
    its first plate round the pin (the clearance hole, d + 0.2; the roller's pressed pin's, d);
    the lever's pin G rides in the push rod's slot (a stadium, checked by its sizes)."""
    from cadgen.machine.duckbill import PIN_HOLE_CLEARANCE

    _, _, _, machine, assembly, _ = paper
    fixing = machine.fixings["duckbill"]
    world = {name: pose for name, _, pose in
             assembly.placements(math.radians(phi_deg), bought=True)}
    parts = {part.name: part for part in assembly.parts}
    pins = _linkage_bought(assembly, "clevis pin") + _linkage_bought(assembly, "parallel pin")
    assert len(pins) == 8     # H, G, P2, J and O1 on each side, the roller's: per arm
    checked = 0
    for pin in pins:
        d = _diameter(pin)
        for arm, instance in _copies_by_arm(pin).items():
            for stem in sorted(pin.fitted):
                local = np.linalg.solve(world[f"{stem}-{arm}"], world[instance])
                axis, point = local[:3, 2], local[:3, 3]
                assert abs(abs(axis[2]) - 1.0) < 1e-12, (pin.name, stem)
                if stem == "push-rod" and "lever" in pin.fitted:
                    rod, g = fixing["rod"], fixing["points"]["G"]
                    assert abs(point[0] - g[0]) <= (rod["slot_length"] - d) / 2 + 1e-9
                    assert abs(point[1] - g[1]) <= (rod["slot_width"] - d) / 2 + 1e-9
                    continue
                # the heights of the hole's rim (vertices on its circle round the pin's axis):
                # a section between the first two is in the part's first plate
                hole = d if pin.kind == "parallel pin" else d + PIN_HOLE_CLEARANCE
                mesh = parts[stem].mesh
                radius = np.linalg.norm(mesh.vertices[:, :2] - point[:2], axis=1)
                # along the pin only: a clevis pin's shank is its frame's -z, a pin's +z
                ends = point[2] + np.array([0.0, (1.0 if pin.kind == "parallel pin" else -1.0)
                                            * axis[2] * _length(pin)])
                rim = mesh.vertices[abs(radius - hole / 2) < 1e-6, 2]
                levels = np.unique(np.round(rim[(rim >= ends.min() - 1e-9)
                                                & (rim <= ends.max() + 1e-9)], 9))
                z = 0.5 * (levels[0] + levels[1])
                assert _hole_offset(parts[stem].solid, z, hole, point) < 1e-6, (
                    pin.name, stem, arm)
                checked += 1
    # per arm: H (lever, shell), G (lever), P2 (rod, two links), J and O1 (two parts) each
    # side, the roller's pin (lever)
    assert checked == 2 * (2 + 1 + 3 + 2 * 2 + 2 * 2 + 1)


def _stack_of(assembly, pin):
    """The washer and split pin placed with ``pin`` (its stack)."""
    mates = {part.kind: part for part in assembly.bought
             if part.stack == pin.stack and part is not pin}
    return mates["washer"], mates["split pin"]


def _in_pin_frame(world, pin, other_instance, arm="arm1"):
    return np.linalg.solve(world[_copies_by_arm(pin)[arm]], world[other_instance])


@pytest.mark.parametrize("phi_deg", POSES, ids=lambda v: f"{v:g}deg")
def test_each_clevis_pin_spans_its_plates_its_washer_and_its_split_pin(paper, phi_deg):
    """Along each clevis pin (ISO 2341 B), measured on the placed solids: its head bears on the
    first plate's face, its washer (ISO 8738) on the last one's, the split pin (ISO 1234) goes
    through the pin's axis l_e from its end (ISO 2341) clear of the washer, and the pin is as
    long as the plates, the washer and that hole need; sizes from the standards' tables."""
    _, _, _, _, assembly, _ = paper
    world = {name: pose for name, _, pose in
             assembly.placements(math.radians(phi_deg), bought=True)}
    parts = {part.name: part for part in assembly.parts}
    pins = _linkage_bought(assembly, "clevis pin")
    assert sorted(_diameter(p) for p in pins) == [4.0, 4.0, 4.0, 5.0, 5.0, 5.0, 8.0]
    for pin in pins:
        d, length = _diameter(pin), _length(pin)
        head, k, hole, l_e = ISO_2341[d]
        outside, h = ISO_8738[d]
        # the pin's own solid: head dk x k on a d x l shank
        np.testing.assert_allclose(pin.mesh.bounds[:, 2], [-length, k], atol=1e-9)
        assert pin.mesh.extents[0] == pytest.approx(head, abs=1e-9)
        # the plates round it, in its frame (the shank along -z): each part's vertices within
        # the head's (the washer's) reach of its axis
        near, far = [], []
        for stem in pin.fitted:
            local = _in_pin_frame(world, pin, f"{stem}-arm1")
            vertices = parts[stem].mesh.vertices @ local[:3, :3].T + local[:3, 3]
            radius = np.hypot(vertices[:, 0], vertices[:, 1])
            depth = -vertices[:, 2]
            on = (depth > -1e-9) & (depth < length)
            near.append(depth[on & (radius <= head / 2)].min())
            far.append(depth[on & (radius <= outside / 2)].max())
        assert min(near) == pytest.approx(0.0, abs=1e-9), pin.name   # the head on a face
        grip = max(far)
        washer, split = _stack_of(assembly, pin)
        w = _in_pin_frame(world, pin, _copies_by_arm(washer)["arm1"])
        ring = washer.mesh.vertices @ w[:3, :3].T + w[:3, 3]
        np.testing.assert_allclose(sorted(-ring[:, 2])[::len(ring) - 1], [grip, grip + h],
                                   atol=1e-9)
        assert washer.mesh.extents[0] == pytest.approx(outside, abs=1e-9)
        # the split pin: across the pin's axis, through its hole l - l_e from under the head
        s = _in_pin_frame(world, pin, _copies_by_arm(split)["arm1"])
        legs, at = s[:3, 2], s[:3, 3]
        assert abs(legs[2]) < 1e-12                               # normal to the pin
        assert abs(legs[0] * at[1] - legs[1] * at[0]) < 1e-9     # its axis crosses the pin's
        assert -at[2] == pytest.approx(length - l_e, abs=1e-9)
        assert -at[2] - hole / 2 >= grip + h - 1e-9                # the hole clears the washer
        assert length >= grip + h + hole / 2 + l_e - 1e-9
        wire, eye = ISO_1234[hole]
        np.testing.assert_allclose(sorted(split.mesh.extents[:2]), [wire, eye], atol=1e-9)


def test_the_return_spring_sits_between_the_web_and_the_collar_at_its_installed_length(paper):
    """At rest the spring's solid (EN 13906-1's coil envelope) is round the push rod's shank
    (its axis measured from the rod's solid), as long as installed, L1 = L0 - F1 / R with the
    rate by hand, and sits on both seats: moved 0.01 mm either way it runs into the web or the
    collar, where it is it shares nothing with them (booleans of the placed solids)."""
    from cadgen.solids.overlaps import VOLUME_FLOOR

    _, _, _, machine, assembly, _ = paper
    record = machine.fixings["duckbill"]["spring"]
    d, D, n = record["wire"], record["mean_diameter"], record["active_coils"]
    assert (d, D, n) == (0.9, pytest.approx(9.9), 3.5)
    rate = 81_500 * d**4 / (8 * D**3 * n)                    # EN 13906-1, G for EN 10270-1
    installed = record["free_length"] - record["preload"] / rate
    [spring] = _linkage_bought(assembly, "compression spring")
    assert len(spring.instances) == 2
    np.testing.assert_allclose(sorted(spring.mesh.extents),
                               [D + d, D + d, installed], atol=1e-6)
    world = {name: pose for name, _, pose in assembly.placements(0.0, bought=True)}
    parts = {part.name: part for part in assembly.parts}
    for arm, instance in _copies_by_arm(spring).items():
        pose = world[instance]
        rod_pose = world[f"push-rod-{arm}"]
        # the rod's shank between the seats, in the rod's frame: a section across it halfway
        # (the rod turned so its y is z: (x, y, z) -> (x, -z, y))
        local = np.linalg.solve(rod_pose, pose)
        np.testing.assert_allclose(local[:3, 2], [0.0, 1.0, 0.0], atol=1e-12)
        turned = parts["push-rod"].solid.transform(
            np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0]]))
        [loop] = turned.slice(local[1, 3] + installed / 2).to_polygons()
        import shapely

        shank = shapely.Polygon(loop)
        np.testing.assert_allclose(shank.centroid.coords[0], [local[0, 3], -local[2, 3]],
                                   atol=1e-9)
        assert np.ptp(np.asarray(loop)[:, 0]) < D - d        # the coils clear the rod
        for other, towards in ((f"planter-shell-{arm}", -1.0), (f"push-rod-{arm}", 1.0)):
            name = other.rsplit("-", 1)[0]
            seat = parts[name].solid.transform(world[other][:3, :])
            shifted = pose.copy()
            shifted[:3, 3] += towards * 0.01 * pose[:3, 2]
            assert (spring.solid.transform(pose[:3, :]) ^ seat).volume() <= VOLUME_FLOOR
            assert (spring.solid.transform(shifted[:3, :]) ^ seat).volume() > 0.1, other


@pytest.mark.parametrize("phi_deg", POSES, ids=lambda v: f"{v:g}deg")
def test_the_roller_runs_on_its_pin_under_the_lever_and_on_the_cam(paper, phi_deg):
    """The 604-2Z roller (ISO 15: 4 x 12 x 4) on the ISO 2338 pin, coaxial in the world at a
    closed and an open pose; its top face level with the cam's, its outside on the cam's
    contour; the DIN 471 4 ring (0.4 thick) under it on the pin; the pin flush with the lever's
    top face (the solids' faces, measured)."""
    params, _, _, _, assembly, _ = paper
    world = {name: pose for name, _, pose in
             assembly.placements(math.radians(phi_deg), bought=True)}
    parts = {part.name: part for part in assembly.parts}
    [bearing] = [b for b in _linkage_bought(assembly, "bearing")]
    [pin] = _linkage_bought(assembly, "parallel pin")
    [ring] = _linkage_bought(assembly, "retaining ring")
    assert (bearing.designation, ring.designation) == ("604", "DIN 471 4 x 0.4")
    np.testing.assert_allclose(sorted(bearing.mesh.extents), [4.0, 12.0, 12.0], atol=1e-9)
    # its bore (manifold3d keeps vertices to about 1e-8 mm)
    hole = bearing.mesh.vertices
    assert np.hypot(hole[:, 0], hole[:, 1]).min() == pytest.approx(2.0, abs=1e-8)
    for arm in ("arm1", "arm2"):
        at = {part.kind: world[_copies_by_arm(part)[arm]] for part in (bearing, pin, ring)}
        pin_axis = at["parallel pin"]
        for kind in ("bearing", "retaining ring"):
            local = np.linalg.solve(pin_axis, at[kind])
            np.testing.assert_allclose(local[:3, 2], [0.0, 0.0, 1.0], atol=1e-12)
            np.testing.assert_allclose(local[:2, 3], [0.0, 0.0], atol=1e-9)
        bottom = np.linalg.solve(pin_axis, at["bearing"])[2, 3]
        assert 0.0 < bottom - 0.4 and bottom + 4.0 < 12.0                 # on the pin
        assert np.linalg.solve(pin_axis, at["retaining ring"])[2, 3] == pytest.approx(
            bottom - 0.4, abs=1e-9)                                       # the ring under it
        cam_pose, lever_pose = world[f"cam-{arm}"], world[f"lever-{arm}"]
        top = (at["bearing"] @ [0.0, 0.0, 4.0, 1.0])[2]
        cam_top = (cam_pose @ [0.0, 0.0, parts["cam"].mesh.bounds[1, 2], 1.0])[2]
        assert top == pytest.approx(cam_top, abs=1e-9)
        lever_top = (lever_pose @ [0.0, 0.0, parts["lever"].mesh.bounds[1, 2], 1.0])[2]
        assert (pin_axis @ [0.0, 0.0, 12.0, 1.0])[2] == pytest.approx(lever_top, abs=1e-9)
        # the roller's axis 6 mm off the cam's contour (its outside on it)
        centre = np.linalg.solve(cam_pose, at["bearing"])[:2, 3]
        contour = np.asarray(parts["cam"].outline)
        a, b = contour, np.roll(contour, -1, axis=0)
        t = np.clip(np.sum((centre - a) * (b - a), axis=1) / np.sum((b - a) ** 2, axis=1), 0, 1)
        distance = np.min(np.linalg.norm(a + t[:, None] * (b - a) - centre, axis=1))
        assert distance == pytest.approx(6.0, abs=2 * params.gears.chord_tolerance + 1e-6)


def test_every_bought_row_of_the_linkage_is_placed_as_a_solid_as_often_as_billed(paper):
    """The linkage's bill rows (clevis pins, their washers and split pins, the roller's bearing,
    pin and ring, the spring) against the placed solids' designations, both arms."""
    from cadgen.report.bom import _bought_rows
    from cadgen.solids.bought import placed_designations

    _, _, _, _, assembly, _ = paper
    instances = {name for part in assembly.parts for name, _, _ in part.instances}
    kinds = {"clevis pin", "washer", "split pin", "parallel pin", "compression spring"}
    rows = {r["designation"]: r["quantity"] for r in _bought_rows(assembly.model, instances)
            if r["part"] in kinds or r["designation"] in ("604", "DIN 471 4 x 0.4")}
    assert sum(rows.values()) == 3 * 14 + 3 * 2 + 2   # pin stacks, the rollers, the springs
    placed = placed_designations(assembly)
    assert {name: placed[name] for name in rows} == rows


def test_the_arm_sweep_moves_each_linkage_item_with_the_part_that_holds_it(paper):
    """Both arms' copies of every linkage item are paired for the arm sweep, each with a speed
    bound from its host's motion (a pin on the lever turns about H with it), on top of the
    planter's own."""
    from cadgen.pipeline.clearances import _arm_part_bounds, arm_groups

    _, mechanism, design, _, assembly, _ = paper
    arm1, arm2 = arm_groups(assembly, bought=True)
    items = _linkage_bought(assembly)
    assert len(items) == 3 * 7 + 3 + 1
    pairs = dict(zip(arm1, arm2))
    for item in items:
        one, two = (name for name, _, _ in item.instances)
        assert pairs[one] == two
    parts = {part.name: part for part in assembly.parts}
    bounds = _arm_part_bounds(mechanism, parts, design, assembly.bought)
    # each bounded as its host moves: at least the planter's hub E's speed bound
    floor = mechanism.speed_bound("E"), mechanism.acceleration_bound("E")
    for item in items:
        speed, acceleration = bounds[item.name]
        assert speed >= floor[0] and acceleration >= floor[1], item.name
