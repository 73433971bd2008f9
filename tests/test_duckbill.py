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
