"""The transmission box's countershaft drive (cadgen.gears.drive).

Independent sources: exact fractions (fractions.Fraction) for the speed identity
n = (z1 z4) / (z2 z3); centre distances computed by hand as m (z_a + z_b) / 2 for each pair;
the rim rule written out again here; a brute-force scan over every (z1, z3) of every S (plain
Python for the smaller S of the reference case, numpy for the full range) against which the
design's choice and error are compared.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinematics.errors import DesignError

from cadgen.gears.drive import DriveDesign, drive_design


def rim_ok(z4, module, sleeve):
    """Driven gear's root circle leaves 2.5 modules around the sleeve (written out again)."""
    return module * z4 / 2 - 1.25 * module - sleeve / 2 >= 2.5 * module


def exact_sets(s, n, module, sleeve, lo=17, hi=150):
    """Every (z1, z2, z3, z4) with z1 + z2 = z3 + z4 = s, exact ratio n and the rim rule."""
    n = Fraction(n)
    out = []
    for z1 in range(lo, hi + 1):
        for z3 in range(lo, hi + 1):
            z2, z4 = s - z1, s - z3
            if not (lo <= z2 <= hi and lo <= z4 <= hi):
                continue
            if Fraction(z1 * z4, z2 * z3) == n and rim_ok(z4, module, sleeve):
                out.append((z1, z2, z3, z4))
    return out


def brute_force(n, module, sleeve, lo, hi):
    """Least relative error over every feasible (z1, z3) of every S, and the ratio range."""
    best, r_min, r_max = math.inf, math.inf, -math.inf
    for s in range(2 * lo, 2 * hi + 1):
        z = np.arange(lo, hi + 1)
        z1 = z[(s - z >= lo) & (s - z <= hi)]
        z3 = z1[np.array([rim_ok(s - v, module, sleeve) for v in z1], dtype=bool)]
        if z1.size == 0 or z3.size == 0:
            continue
        a, c = np.meshgrid(z1, z3, indexing="ij")
        ratio = (a * (s - c)) / ((s - a) * c)
        best = min(best, float(np.min(np.abs(ratio / n - 1))))
        r_min, r_max = min(r_min, float(ratio.min())), max(r_max, float(ratio.max()))
    return best, r_min, r_max


# Reference design: n = 3, module 2, sleeve 30 mm.
# Rim rule: 2 z4 / 2 - 2.5 - 15 >= 5  ->  z4 >= 22.5, so z4 >= 23 (not binding below).
# 3 = (5/3) (9/5): z1 : z2 = 5 : 3 needs S a multiple of 8, z4 : z3 = 9 : 5 a multiple of 14,
# so S = lcm(8, 14) = 56 with (35, 21, 20, 36): 35 * 36 / (21 * 20) = 1260 / 420 = 3.
# The swapped set (36, 20, 21, 35) is exact too; the default prefers the input speed nearest
# the central shaft's (z4 / z3 = 36 / 20 = 1.8 is nearer 3 than 35 / 21 = 1.67).
# Centre distance: 2 (35 + 21) / 2 = 56 mm = 2 (20 + 36) / 2.
def test_reference_n3():
    d = drive_design(3, 30.0, 2.0, 30.0)
    assert isinstance(d, DriveDesign)
    assert d.teeth == (35, 21, 20, 36)
    z1, z2, z3, z4 = d.teeth
    assert Fraction(z1 * z4, z2 * z3) == 3
    assert d.exact and d.ratio_error == 0.0 and d.ratio_achieved == 3.0
    assert d.centre_distance == 56.0 == 2.0 * (z1 + z2) / 2 == 2.0 * (z3 + z4) / 2
    assert d.radii == (35.0, 21.0, 20.0, 36.0)
    assert d.module_1 == d.module_2 == 2.0
    assert rim_ok(z4, 2.0, 30.0) and d.rim == pytest.approx(36 - 2.5 - 15)
    # Input at carrier * z4 / z3 = 30 * 36 / 20; O at input * z1 / z2 = 3 * carrier.
    assert d.input_speed_rpm == pytest.approx(54.0)
    assert d.central_shaft_rpm == pytest.approx(90.0)
    # No smaller S has an exact set meeting every rule (brute force, all (z1, z3)).
    for s in range(34, 56):
        assert exact_sets(s, 3, 2.0, 30.0) == []
    assert set(exact_sets(56, 3, 2.0, 30.0)) == {(35, 21, 20, 36), (36, 20, 21, 35)}


# Rim rule binding: sleeve 58 mm -> z4 - 2.5 - 29 >= 5 -> z4 >= 36.5, so z4 >= 37. Both exact
# sets at S = 56 have z4 = 36 or 35 (rim 36 - 2.5 - 29 = 4.5 < 5): violated. The next exact S
# is 60: 3 = (3/2) * 2 -> (36, 24, 20, 40), z4 = 40, rim 40 - 31.5 = 8.5 >= 5; the swap
# (40, 20, 24, 36) fails the rim.
def test_rim_rule_binds():
    d = drive_design(3, 30.0, 2.0, 58.0)
    assert d.teeth == (36, 24, 20, 40) and d.exact
    assert rim_ok(40, 2.0, 58.0) and d.rim == pytest.approx(8.5)
    assert not rim_ok(36, 2.0, 58.0) and not rim_ok(35, 2.0, 58.0)
    for s in range(34, 60):
        assert exact_sets(s, 3, 2.0, 58.0) == []
    assert exact_sets(60, 3, 2.0, 58.0) == [(36, 24, 20, 40)]


def test_input_speed_ratio_tiebreak():
    # At S = 56 the two exact sets give input/carrier 36/20 = 1.8 and 35/21 = 1.667.
    d = drive_design(3, 30.0, 2.0, 30.0, input_speed_ratio=1.5)
    assert d.teeth == (36, 20, 21, 35)
    assert d.input_speed_rpm == pytest.approx(30.0 * 35 / 21)


def test_report_json_ready():
    import json
    rep = drive_design(3, 30.0, 2.0, 30.0).as_report()
    json.dumps(rep)
    assert rep["teeth"] == {"z1": 35, "z2": 21, "z3": 20, "z4": 36}
    assert rep["ratio_fraction"] == "3/1" and rep["exact"] is True
    assert "2.5 m" in rep["rule"] and "\n" not in rep["rule"]


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6).flatmap(lambda q: st.tuples(st.integers(q + 1, 12), st.just(q))))
def test_rational_is_exact(pq):
    p, q = pq
    d = drive_design(p / q, 20.0, 2.0, 30.0)
    z1, z2, z3, z4 = d.teeth
    assert d.exact and Fraction(z1 * z4, z2 * z3) == Fraction(p, q)
    assert z1 + z2 == z3 + z4 and rim_ok(z4, 2.0, 30.0)


@settings(max_examples=25, deadline=None)
@given(n=st.floats(1.2, 8.0), hi=st.integers(30, 150), sleeve=st.floats(0.0, 60.0))
def test_float_matches_brute_force(n, hi, sleeve):
    best, r_min, r_max = brute_force(n, 2.0, sleeve, 17, hi)
    if not r_min * (1 - 1e-12) <= n <= r_max * (1 + 1e-12) and best >= 1e-12:
        with pytest.raises(DesignError) as info:
            drive_design(n, 20.0, 2.0, sleeve, max_teeth=hi)
        assert info.value.problems[0].code == "drive_ratio_unreachable"
        return
    d = drive_design(n, 20.0, 2.0, sleeve, max_teeth=hi)
    z1, z2, z3, z4 = d.teeth
    assert all(17 <= z <= hi for z in d.teeth) and z1 + z2 == z3 + z4
    assert rim_ok(z4, 2.0, sleeve)
    assert abs(d.ratio_error) <= best * (1 + 1e-9) + 1e-15
    assert d.exact == (best < 1e-12)


@pytest.mark.parametrize("n", [math.pi, 2 ** 0.5 + 1, math.e, (1 + 5 ** 0.5) / 2 + 1, 7 ** 0.5])
def test_irrational_near(n):
    d = drive_design(n, 30.0, 2.0, 30.0, max_teeth=150)
    assert not d.exact
    assert abs(d.ratio_error) < 1e-3
    z1, z2, z3, z4 = d.teeth
    assert d.ratio_error == pytest.approx((z1 * z4) / (z2 * z3) / n - 1, abs=1e-15)


def test_unreachable():
    with pytest.raises(DesignError) as info:
        drive_design(1000, 30.0, 2.0, 30.0, max_teeth=150)
    problem = info.value.problems[0]
    assert (problem.path, problem.code) == ("train.n", "drive_ratio_unreachable")
    # Largest ratio: (150/17) * (150/17) = 22500/289 = 77.8547.
    assert "77.8547" in problem.message
    # Rim rule beyond max_teeth: z4 >= 7.5 + 400 / 2 > 150.
    with pytest.raises(DesignError) as info:
        drive_design(3, 30.0, 2.0, 400.0)
    assert info.value.problems[0].code == "drive_ratio_unreachable"


@pytest.mark.parametrize("n", [1.0, 0.5, -3.0, float("nan"), float("inf")])
def test_bad_n(n):
    with pytest.raises(ValueError):
        drive_design(n, 30.0, 2.0, 30.0)
