"""Hard cases of the planting spec, through real parameter files: correct, or a specific error."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from cadgen.params import ParameterError, validate_text
from kinematics.pitch_curves import LimaconPitchCurve, pair_problems, solve_closure
from tests.conftest import PAPER_LIMACON
from tests.helpers import edited, reference_text


def codes(text):
    with pytest.raises(ParameterError) as caught:
        validate_text(text, "case.toml")
    return {(p.path, p.code) for p in caught.value.problems}


def test_reference_design_is_feasible():
    params = validate_text(reference_text(), "xin2024-planter.toml")
    assert params.name == "xin2024-planter"


def test_pitch_curve_through_its_centre():
    _, x, y = LimaconPitchCurve(**PAPER_LIMACON)._xy(1.0)
    text = edited(g1=PAPER_LIMACON["g1"] - float(x), g2=PAPER_LIMACON["g2"] - float(y))
    assert codes(text) == {("pitch_curve", "pointed_pitch_curve")}


def test_ratio_swing_beyond_one_to_ten_converges_then_is_rejected():
    # g2 = -20: swing 1:14.7, min r1 8.98 mm below 3 modules (10.3 mm at z = 22)
    curve = LimaconPitchCurve(**{**PAPER_LIMACON, "g2": -20.0})
    closure = solve_closure(curve)
    assert closure.ratio_swing > 10
    r = curve.radius
    reference = brentq(lambda a: quad(lambda t: r(t) / (a - r(t)), 0, 2 * np.pi, epsabs=1e-12,
                                      epsrel=1e-12, limit=500)[0] - 2 * np.pi,
                       closure.radius_max[1] + 1.0, 3 * closure.radius_max[1], xtol=1e-13)
    assert closure.centre_distance == pytest.approx(reference, rel=1e-9)
    assert codes(edited(g2=-20.0)) == {("pitch_curve", "pointed_pitch_curve")}


def test_too_few_teeth_for_the_pitch_curve():
    # z = 7 gives module 8.77 mm: both gears' smallest radii are under 3 modules
    assert codes(edited(teeth=7)) == {("pitch_curve", "pointed_pitch_curve"),
                                      ("pitch_curve", "tiny_intermediate_radius")}


class BumpPitchCurve:
    """``r = R0 + h exp(k (cos t - 1))``: a narrow lobe that forces a close to max r1."""

    def __init__(self, base, height, sharpness):
        self.base, self.height, self.sharpness = base, height, sharpness

    def radius(self, t):
        return self.radius_derivatives(t)[0]

    def radius_derivatives(self, t):
        t = np.asarray(t, dtype=float)
        k, h = self.sharpness, self.height
        e = np.exp(k * (np.cos(t) - 1))
        return self.base + h * e, -h * k * np.sin(t) * e, h * k * e * (k * np.sin(t) ** 2 - np.cos(t))


def test_tiny_intermediate_radius_is_named():
    curve = BumpPitchCurve(30.0, 29.0, 50.0)
    closure = solve_closure(curve)
    r = curve.radius
    reference = brentq(lambda a: quad(lambda t: r(t) / (a - r(t)), -np.pi, np.pi, points=[0.0],
                                      epsabs=1e-12, epsrel=1e-12, limit=500)[0] - 2 * np.pi,
                       60.0, 118.0, xtol=1e-13)
    assert closure.centre_distance == pytest.approx(reference, rel=1e-9)
    gap = closure.centre_distance - 59.0
    problems = pair_problems(closure, module=3.0)
    assert [p.code for p in problems] == ["tiny_intermediate_radius"]
    assert f"{gap:.3f} mm" in problems[0].message
    assert pair_problems(closure, module=gap / 3.0 * 0.999) == []


def test_depth_beyond_the_tip_path_is_rejected():
    assert codes(edited(depth=800.0)) == {("field.depth", "no_soil_crossing")}


def test_structural_and_unrelated_problems_are_reported_together():
    text = edited(depth=-1.0, L1='"130"')
    assert codes(text) == {("field.depth", "out_of_range"), ("planter.L1", "wrong_type")}


@pytest.mark.parametrize("teeth, refused", [(22, False), (49, False), (50, True), (704, True)])
def test_a_module_under_half_its_target_is_refused_where_the_teeth_are_cut(teeth, refused,
                                                                            tmp_path, capsys):
    # by hand: the paper's module is 2.7911 mm at 22 teeth, a pitch perimeter of
    # pi 22 x 2.7911 = 192.91 mm; half the 2.5 mm target is 1.25 mm, and 192.91 / (pi 49) =
    # 1.2532 mm stays above it while 192.91 / (pi 50) = 1.2281 mm falls below
    from cadgen.cli import main

    path = tmp_path / "fine.toml"
    path.write_text(edited(teeth=str(teeth)), encoding="utf-8")
    code = main(["validate", str(path)])
    out = capsys.readouterr().out
    if not refused:
        assert code == 0 and "module_far_below_target" not in out
        return
    assert code == 2
    [line] = [line for line in out.splitlines() if "module_far_below_target" in line]
    assert line.startswith(f"{path}: pitch_curve.teeth: {teeth} teeth")
    # the advice: the most teeth whose module meets the target, floor(192.91 / (pi 2.5)) = 24
    assert "pitch_curve.teeth = 24 or fewer" in line
    # a metrics-only build reports the module's failure and keeps this as a warning
    assert main(["build", str(path), "--effects", "metrics", "--output-dir",
                 str(tmp_path / "out")]) == 1
    assert "module_far_below_target" in capsys.readouterr().out


@pytest.mark.parametrize("table, key, value", [("pitch_curve", "teeth", 1001),
                                               ("solids", "segments_per_circle", 1025),
                                               ("gears", "meshing_poses", 4001)])
def test_knobs_beyond_what_a_build_does_in_ten_times_its_time_are_refused(table, key, value):
    from tests.helpers import with_keys

    with pytest.raises(ParameterError) as caught:
        validate_text(with_keys(reference_text(), table, **{key: str(value)}))
    assert [(p.path, p.code) for p in caught.value.problems] == [(f"{table}.{key}",
                                                                  "out_of_range")]


def test_a_pointed_stretch_names_the_module_that_cuts_it_and_that_module_does():
    # 6 teeth on the paper's curve are a module of 192.91 / (pi 6) = 10.23 mm: pointed. The
    # advice's module, turned into a tooth count by hand, validates.
    import math
    import re

    with pytest.raises(ParameterError) as caught:
        validate_text(edited(teeth="6"))
    advice = [float(re.search(r"a module of at most ([0-9.]+) mm", p.message).group(1))
              for p in caught.value.problems
              if p.code in ("pointed_pitch_curve", "tiny_intermediate_radius")]
    assert advice and all("more teeth: pitch_curve.teeth" in p.message
                          for p in caught.value.problems)
    teeth = math.ceil(np.pi * 22 * 2.79111 / (np.pi * min(advice)))
    assert teeth > 6
    validate_text(edited(teeth=str(teeth)))   # no pointed stretch any more
