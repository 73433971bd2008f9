"""Tooth strength (cadgen.gears.strength): a spur pair worked by hand, Hertz against the
cylinder formula, the non-circular equivalent reducing to the circular gear, the internal
pair, scaling with the force, the [machine] limits, and the pitch curvature the meshes use."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from cadgen.gears.gear_materials import GEAR_MATERIALS, gear_material
from cadgen.gears.strength import (MeshGear, MeshLoad, RackProfile, StrengthFactors,
                                   contact_ratio, elasticity_factor, form_factors, mesh_strength)
from cadgen.gears.strength_summary import train_strength_summary
from cadgen.params.machine import MachineParameters

ALPHA = math.radians(20.0)
RACK = RackProfile(ALPHA, 1.0, 1.25, 0.38)        # the DIN 3990 / ISO 53 rack, rho_fP 0.38 m
UNIT = StrengthFactors(1.0, 1.0, 1.0, 1.0)        # the hand calculation's K factors
C45 = gear_material("steel C45")


def spur_mesh(radii, module=2.0, face=20.0, force=1000.0 / math.cos(ALPHA), teeth=(None, None),
              material=C45, shifts=(0.0, 0.0), poses=3):
    pose = np.linspace(0.0, 2 * np.pi, poses, endpoint=False)
    gears = tuple(MeshGear(f"gear {k + 1}", np.full(poses, float(r)), material, x, z)
                  for k, (r, z, x) in enumerate(zip(radii, teeth, shifts)))
    return MeshLoad("pair", gears, module, face, RACK, pose, 2 * np.pi, np.full(poses, force))


def test_a_spur_pair_against_a_hand_calculation():
    """z1 = 20, z2 = 40, m = 2 mm, b = 20 mm, alpha = 20 deg, x = 0, Ft = 1000 N (T1 = 20 N m),
    both C45+N, K factors 1, written out as a textbook does (ISO 6336 simplified, load at the
    tip):

    - contact ratio (ISO 21771): r = 20, 40; rb = r cos 20 = 18.79385, 37.58770; ra = 22, 42;
      sqrt(22^2 - 18.79385^2) = 11.43639, sqrt(42^2 - 37.58770^2) = 18.73938,
      a sin(alpha) = 60 x 0.342020 = 20.52121, g = 9.65457; p_b = pi 2 cos 20 = 5.90426;
      eps_alpha = 1.63519; Y_eps = 0.25 + 0.75 / 1.63519 = 0.70866;
    - form factors read off DIN 3990-3's / ISO 6336-3's charts (x = 0, rho_fP = 0.38 m):
      z = 20: Y_Fa 2.80, Y_Sa 1.55; z = 40: Y_Fa 2.40, Y_Sa 1.67;
    - sigma_F1 = Ft / (b m) Y_Fa Y_Sa Y_eps = 1000 / 40 x 2.80 x 1.55 x 0.70866 = 76.89 MPa,
      sigma_F2 = 25 x 2.40 x 1.67 x 0.70866 = 71.01 MPa;
      S_F1 = 2 x 208.6 / 76.89 = 5.426 (C45+N at 190 HV: sigma_Flim = 0.240 x 190 + 163);
    - Z_E = sqrt(206000 / (pi 2 (1 - 0.3^2))) = 189.81, Z_H = sqrt(2 / (sin 20 cos 20)) =
      2.49457, Z_eps = sqrt((4 - 1.63519) / 3) = 0.88785;
      sigma_H = 189.81 x 2.49457 x 0.88785 x sqrt(1000 / (20 x 40) x 3 / 2) = 575.65 MPa;
      S_H = 535.75 x 0.85 / 575.65 = 0.7911 (sigma_Hlim = 0.925 x 190 + 360, Z_L Z_V Z_R 0.85).
    """
    result = mesh_strength(spur_mesh((20.0, 40.0), teeth=(20, 40)), UNIT)
    assert result.contact_ratio[0] == pytest.approx(1.63519, abs=1e-5)
    # the chart values are read to two decimals: 1.5 % covers their reading
    assert result.form_factor[:, 0] == pytest.approx([2.80, 2.40], rel=5e-3)
    assert result.stress_correction[:, 0] == pytest.approx([1.55, 1.67], rel=5e-3)
    assert result.root_stress[:, 0] == pytest.approx([76.89, 71.01], rel=1.5e-2)
    assert result.bending_safety[0, 0] == pytest.approx(5.426, rel=1.5e-2)
    assert result.contact_stress[0] == pytest.approx(575.65, rel=1e-5)
    assert result.contact_safety[:, 0] == pytest.approx([0.7911, 0.7911], rel=1e-4)
    assert result.valid.all()


@pytest.mark.parametrize("teeth, form, correction", [(17, 2.97, 1.52), (20, 2.80, 1.55),
                                                     (40, 2.40, 1.67), (100, 2.18, 1.79)],
                         ids=["z17", "z20", "z40", "z100"])
def test_form_factors_against_the_charts(teeth, form, correction):
    """DIN 3990-3 / ISO 6336-3 chart values (x = 0, rho_fP = 0.38 m), read to two decimals."""
    y_fa, y_sa, _, settled = form_factors([teeth], 0.0, RACK)
    assert settled[0]
    assert y_fa[0] == pytest.approx(form, abs=0.02)
    assert y_sa[0] == pytest.approx(correction, abs=0.02)


def test_hertz_against_the_cylinder_formula():
    """Two cylinders of the flanks' radii R_i sin(alpha) pressed by Fn per face width b:
    p0 = sqrt(Fn E* / (pi b R)), 1 / E* = sum (1 - nu^2) / E, 1 / R = 1 / R1 + 1 / R2
    (Johnson, Contact Mechanics, eq. 4.45); the mesh's stress is that times Z_eps and the
    root of the load factors."""
    factors = StrengthFactors(1.3, 1.1, 1.2, 1.05)
    steel, petg = C45, GEAR_MATERIALS["PETG"]
    force = 2345.0
    mesh = spur_mesh((17.5, 52.0), module=2.5, face=18.0, force=force, material=steel)
    mesh = MeshLoad(mesh.name, (mesh.gears[0], MeshGear("gear 2", mesh.gears[1].radius, petg)),
                    mesh.module, mesh.face_width, RACK, mesh.pose, mesh.period, mesh.normal_force)
    result = mesh_strength(mesh, factors)
    e_star = 1.0 / ((1 - 0.3**2) / 206000.0 + (1 - 0.38**2) / 2000.0)
    radius = 1.0 / (1.0 / (17.5 * math.sin(ALPHA)) + 1.0 / (52.0 * math.sin(ALPHA)))
    p0 = math.sqrt(force * factors.product / 18.0 * e_star / (math.pi * radius))
    z_eps = np.sqrt((4 - result.contact_ratio) / 3)
    assert result.contact_stress == pytest.approx(p0 * z_eps, rel=1e-12)
    assert elasticity_factor(steel, steel) == pytest.approx(189.81, abs=0.01)


@settings(max_examples=40, deadline=None)
@given(teeth=st.tuples(st.integers(14, 120), st.integers(14, 120)),
       module=st.floats(0.8, 6.0), force=st.floats(10.0, 1e5),
       face=st.floats(4.0, 60.0))
def test_the_non_circular_equivalent_of_constant_curvature_is_the_circular_gear(teeth, module,
                                                                               force, face):
    """A pitch curve of constant curvature 2 / (m z) is the circle: z_v = z, and every stress
    and safety is the circular gear's; the contact is ISO 6336-2's Z_H form."""
    radii = tuple(module * z / 2 for z in teeth)
    circular = mesh_strength(spur_mesh(radii, module, face, force, teeth=teeth))
    curved = mesh_strength(spur_mesh(radii, module, face, force))
    assert curved.equivalent_teeth[:, 0] == pytest.approx(teeth, rel=1e-12)
    for name in ("root_stress", "bending_safety", "contact_stress", "contact_safety",
                 "contact_ratio"):
        assert getattr(curved, name) == pytest.approx(getattr(circular, name), rel=1e-9)
    u = teeth[1] / teeth[0]
    z_h = math.sqrt(2 / (math.sin(ALPHA) * math.cos(ALPHA)))
    z_eps = math.sqrt((4 - min(max(circular.contact_ratio[0], 1.0), 2.0)) / 3)
    iso = elasticity_factor(C45, C45) * z_h * z_eps * math.sqrt(
        force * math.cos(ALPHA) / (face * 2 * radii[0]) * (u + 1) / u
        * StrengthFactors().product)
    assert circular.contact_stress[0] == pytest.approx(iso, rel=1e-9)


def test_a_concave_stretch_is_the_internal_gear():
    """A pinion z1 = 20 in an internal gear z2 = 80 (m = 2, x = 0), the internal one given as
    a concave pitch curve (R = -80 mm):

    - contact: ISO 6336-2's internal pair, sigma_H = Z_E Z_H Z_eps sqrt(Ft / (b d1) (u - 1) /
      u), u = 4;
    - contact ratio (ISO 21771, internal): (sqrt(ra1^2 - rb1^2) - sqrt(ra2^2 - rb2^2) + a sin
      alpha) / p_b, ra2 = 80 - 2 = 78 mm, a = 60 mm (neither gear's tip passes the other's
      base tangent point here);
    - form factor: ISO 6336-3's internal-gear equations, which give the basic rack's Y_Fa.
    """
    force = 1000.0 / math.cos(ALPHA)
    result = mesh_strength(spur_mesh((20.0, -80.0), force=force))
    rb1, rb2 = 20 * math.cos(ALPHA), 80 * math.cos(ALPHA)
    ratio = (math.sqrt(22**2 - rb1**2) - math.sqrt(78**2 - rb2**2) + 60 * math.sin(ALPHA)) \
        / (math.pi * 2 * math.cos(ALPHA))
    assert result.contact_ratio[0] == pytest.approx(ratio, rel=1e-12)
    z_h = math.sqrt(2 / (math.sin(ALPHA) * math.cos(ALPHA)))
    z_eps = math.sqrt((4 - ratio) / 3)
    sigma = elasticity_factor(C45, C45) * z_h * z_eps * math.sqrt(
        1000.0 / (20 * 40) * 3 / 4 * StrengthFactors().product)
    assert result.contact_stress[0] == pytest.approx(sigma, rel=1e-12)
    assert result.equivalent_teeth[:, 0] == pytest.approx([20.0, -80.0])
    rack_form = form_factors([np.inf], 0.0, RACK)[0][0]
    assert result.form_factor[1, 0] == pytest.approx(rack_form, abs=2e-3)
    # ISO 6336-3's internal tooth in modules: s_Fn = 2 (pi/4 + tan a (hfP - rfP) + rfP / cos a
    # - rfP cos 30), h_Fa = h - (pi/4 + (hfP - h) tan a) tan a - rfP (1 - sin 30), rho_F = rfP/2
    root = 2 * (math.pi / 4 + math.tan(ALPHA) * (1.25 - 0.38) + 0.38 / math.cos(ALPHA)
                - 0.38 * math.cos(math.pi / 6))
    arm = 2.25 - (math.pi / 4 + (1.25 - 2.25) * math.tan(ALPHA)) * math.tan(ALPHA) - 0.38 * 0.5
    ratio_l, notch = root / arm, root / 0.38
    y_sa = (1.2 + 0.13 * ratio_l) * notch ** (1 / (1.21 + 2.3 / ratio_l))
    assert result.stress_correction[1, 0] == pytest.approx(y_sa, rel=1e-12)


def test_conformal_flanks_are_flagged_not_rated():
    """A concave stretch tighter than its mate's convex one cannot touch at a point."""
    result = mesh_strength(spur_mesh((30.0, -25.0)))
    assert np.isnan(result.contact_stress).all() and not result.valid.any()
    assert any("conformal" in reason for _, reason, _ in result.invalid_reasons)


@pytest.mark.parametrize("scale", [0.25, 2.0, 7.5], ids=["quarter", "double", "7.5x"])
def test_safety_scales_inversely_with_force_and_its_root(scale):
    base = mesh_strength(spur_mesh((24.0, 36.0), module=3.0, force=800.0))
    scaled = mesh_strength(spur_mesh((24.0, 36.0), module=3.0, force=800.0 * scale))
    assert scaled.bending_safety == pytest.approx(base.bending_safety / scale, rel=1e-12)
    assert scaled.contact_safety == pytest.approx(base.contact_safety / math.sqrt(scale),
                                                  rel=1e-12)


def test_an_idler_endures_seven_tenths_in_bending():
    plain = mesh_strength(spur_mesh((24.0, 36.0), module=3.0))
    mesh = spur_mesh((24.0, 36.0), module=3.0)
    idler = MeshGear("gear 2", mesh.gears[1].radius, C45, reversed_bending=True)
    reversed_ = mesh_strength(MeshLoad(mesh.name, (mesh.gears[0], idler), 3.0, 20.0, RACK,
                                       mesh.pose, mesh.period, mesh.normal_force))
    assert reversed_.bending_safety[1] == pytest.approx(0.7 * plain.bending_safety[1], rel=1e-12)
    assert reversed_.bending_safety[0] == pytest.approx(plain.bending_safety[0], rel=1e-12)


def test_the_limits_fail_below_not_at():
    """A safety exactly at machine.bending_safety_min / contact_safety_min passes; a hair
    below fails with a Problem naming the field."""
    result = mesh_strength(spur_mesh((20.0, 40.0), teeth=(20, 40)))
    bending = float(result.bending_safety.min())
    contact = float(np.nanmin(result.contact_safety))
    at = train_strength_summary([result], bending, contact, {}, "test")
    assert not at.problems
    below = train_strength_summary([result], bending * (1 + 1e-9), contact * (1 + 1e-9), {},
                                   "test")
    paths = sorted({p.path for p in below.problems})
    assert paths == ["machine.bending_safety_min", "machine.contact_safety_min"]
    weakest = min(below.gears.values(), key=lambda g: g.bending_safety_min)
    assert weakest.bending_safety_min == bending
    defaults = MachineParameters()
    assert (defaults.bending_safety_min, defaults.contact_safety_min) == (1.4, 1.0)


def test_aluminium_flanks_are_not_rated():
    mesh = spur_mesh((20.0, 40.0), material=gear_material("aluminium EN AW-7075"))
    summary = train_strength_summary([mesh_strength(mesh)], 1.4, 1.0, {}, "test")
    assert all(g.contact_safety_min is None for g in summary.gears.values())
    assert {p.code for p in summary.warnings} == {"tooth_contact_not_rated"}


def test_unknown_materials_and_bad_inputs_are_refused():
    with pytest.raises(ValueError, match="unobtainium"):
        gear_material("unobtainium")
    with pytest.raises(ValueError, match="finite and >= 0"):
        mesh_strength(spur_mesh((20.0, 40.0), force=-1.0))


def test_contact_ratio_stops_at_the_base_tangent_point():
    """An 8-tooth pinion with a rack: the rack's tip would reach past the pinion's base
    tangent point (undercut flank), so its stretch of the path ends there."""
    pinion = 8.0
    ratio = contact_ratio(np.array([pinion]), np.array([1e9]), 2.0, RACK)
    rb1 = pinion * math.cos(ALPHA)
    along = math.sqrt((pinion + 2) ** 2 - rb1**2) - rb1 * math.tan(ALPHA)
    assert ratio[0] == pytest.approx((along + rb1 * math.tan(ALPHA))
                                     / (math.pi * 2 * math.cos(ALPHA)), rel=1e-9)


def test_the_planting_pitch_curvature_against_the_cut_curves(paper_mechanism):
    """The analytic curvature at the contact (closed-form derivatives) against the curvature
    of the arc-length splines the teeth are cut along (:class:`kinematics.arclength`)."""
    from types import SimpleNamespace

    from cadgen.gears.trains import planting_pair
    from cadgen.machine.gear_strength import contact_curvatures

    pair = planting_pair(paper_mechanism)
    analytic = contact_curvatures(SimpleNamespace(mechanism="planting"), paper_mechanism)
    tau = np.linspace(0.0, 2 * np.pi, 20000, endpoint=False)
    for which, name in enumerate(pair.names):
        curve = pair.curve(which)
        spline = curve.curvature(np.linspace(0.0, curve.length, 20000, endpoint=False))
        exact = analytic[name](tau)
        assert exact.min() == pytest.approx(spline.min(), rel=2e-3)
        assert exact.max() == pytest.approx(spline.max(), rel=2e-3)


def test_the_pricking_pitch_curvature_against_the_cut_curves():
    """kernel-b's gears: the contact functions' closed-form curvature against the arc-length
    splines of the same pitch curves."""
    from cadgen.design import pricking_design
    from cadgen.gears.pairs import PitchPair
    from cadgen.params import load_params
    from tests.helpers import REFERENCE

    params = load_params(REFERENCE.parent / "kernel-b.toml")
    design = pricking_design(params)
    functions, breaks = design.cycle_functions()
    curvatures = design.cycle_curvatures()
    period = design.motion.period
    tau = np.linspace(0.0, period, 20000, endpoint=False)
    for drive, driven in (("sun", "intermediate 1"), ("intermediate 2", "planet")):
        pair = PitchPair((drive, driven), design.linkage.a, period, functions[drive],
                         functions[driven], breaks=breaks)
        for which, name in enumerate(pair.names):
            curve = pair.curve(which)
            spline = curve.curvature(np.linspace(0.0, curve.length, 20000, endpoint=False))
            exact = curvatures[name](tau)
            assert exact.min() == pytest.approx(spline.min(), rel=2e-3, abs=1e-5)
            assert exact.max() == pytest.approx(spline.max(), rel=2e-3)


def test_a_gear_below_its_limit_fails_the_build_and_the_gear_material_names_the_allowables():
    """A strength problem fails the verdict; ``[machine] gear_material`` sets the allowables
    (ISO 6336-5 MQ: 42CrMo4+QT at 300 HV, sigma_Hlim = 1.313 x 300 + 373 = 766.9 MPa against
    C45+N's 0.925 x 190 + 360 = 535.75) and the bill's and the masses' material."""
    from cadgen.machine.fits import FitError, design_fits, process_fits
    from cadgen.report.content import failures

    problem = {"path": "machine.contact_safety_min", "code": "contact_safety",
               "message": "input gear 2: S_H 0.74 below 1.0"}
    said = failures({"gear_train": {"strength": {"problems": [problem]}}})
    assert said == ["tooth strength: [contact_safety] input gear 2: S_H 0.74 below 1.0"]
    assert gear_material("steel 42CrMo4+QT").contact_endurance == pytest.approx(766.9)
    assert gear_material("steel C45").contact_endurance == pytest.approx(535.75)
    assert process_fits("machined", "steel 42CrMo4+QT").material("gear").name == \
        "steel 42CrMo4+QT"
    assert process_fits("printed", "PA12").material("gear").density == 1010.0
    assert process_fits("machined").material("gear").name == "steel C45"
    with pytest.raises(FitError, match="gear material 'bronze'"):
        process_fits("machined", "bronze")
    from types import SimpleNamespace
    params = SimpleNamespace(manufacturing=SimpleNamespace(process="laser"),
                             machine=MachineParameters(gear_material="PETG"))
    assert design_fits(params).material("gear").process == "laser-cut plate"
    assert set(GEAR_MATERIALS) == set(MachineParameters.model_fields["gear_material"]
                                      .annotation.__args__[0].__args__)


def test_the_dynamics_forces_reach_the_strength_at_the_carrier_angle_of_each_arm():
    """The planting non-circular pair's cycle parameter is the central gear's polar angle of
    the contact, which is the carrier angle (gearbox 2 turns +phi, the central gear -phi
    relative to it, the contact stays on the line of centres): arm 2's copy is half a turn on.
    The forces are the dynamics' times the service factor, both arms' copies in one cycle."""
    from cadgen.machine.gear_strength import dynamics_mesh_forces
    from cadgen.params import load_params
    from cadgen.pipeline.build import STAGE_FUNCTIONS, _Build

    from helpers import REFERENCE

    params = load_params(REFERENCE)
    run = _Build(params, ["kinematics", "metrics", "cam", "drivetrain", "dynamics"], None)
    run.effects, run.case = ["dynamics"], "field"
    run.run(STAGE_FUNCTIONS)
    result = run.values["dynamics"]
    forces = dynamics_mesh_forces(result, 1.5)
    pose, force = forces["central", "intermediate"]
    n = len(result.phi)
    expected = np.concatenate([np.mod(result.phi, 2 * np.pi), np.mod(result.phi + np.pi, 2 * np.pi)])
    gap = np.angle(np.exp(1j * (pose - expected)))
    assert np.abs(gap).max() < 1e-9
    arms = [result.meshes["central", "intermediate", side].normal_force_n for side in (1, 2)]
    np.testing.assert_array_equal(force, 1.5 * np.concatenate(arms))
    # the drive's pairs are one for the machine; every mesh of the train is there
    assert len(forces["input gear 2", "transmission driven gear"][0]) == n
    assert {pair for pair in forces} == {key[:2] for key in result.meshes}
