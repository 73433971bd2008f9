"""The hard-case catalogue (docs/hard-cases.md): the cases added here, and the catalogue's own check.

Every case of the catalogue is a test with its expected outcome; most live beside the
module they exercise, and the catalogue names them. The last test reads the catalogue
and checks that every test it names exists, so the list cannot drift from the suite.
"""

import ast
import math
import re
from pathlib import Path

import numpy as np
import pytest

from cadgen.solids.housings import envelope_circles
from kinematics.evaluation import evaluate_planting
from kinematics.pitch_curves import LimaconPitchCurve
from kinematics.planting import PlantingMechanism

from conftest import PAPER_LIMACON

REPO = Path(__file__).resolve().parents[1]
LENGTHS = ("a1", "b1", "c1", "d1", "g1", "g2")   # the limacon's length coefficients


def _metrics(scale: float):
    curve = LimaconPitchCurve(**{k: v * scale if k in LENGTHS else v
                                 for k, v in PAPER_LIMACON.items()})
    mechanism = PlantingMechanism(curve, i12=1.2, i13=1.1, R=36.0 * scale, r=27.0 * scale,
                                  L1=130.0 * scale, L2=190.0 * scale, phi0=np.pi / 2,
                                  phic=np.pi / 2, n=3.0)
    module = mechanism.module(22)
    circles = envelope_circles(mechanism, module, 6.0 * scale)
    evaluation = evaluate_planting(mechanism, teeth=22, depth=35.0 * scale,
                                   spacings=[150.0 * scale, 200.0 * scale],
                                   housing_circles=circles, steps=720)
    return {(m.key, None if m.spacing is None else m.spacing / scale): (m.value, m.unit)
            for m in evaluation.metrics}


@pytest.mark.parametrize("scale", [0.01, 100.0])
def test_tiny_and_huge_scales_scale_every_length_and_keep_every_angle(scale):
    """A similar design (every length times s): lengths scale by s, angles and counts stay."""
    reference, scaled = _metrics(1.0), _metrics(scale)
    assert reference.keys() == scaled.keys()
    for key, (value, unit) in reference.items():
        expected = value * scale if unit == "mm" else value
        assert scaled[key][0] == pytest.approx(expected, rel=1e-9, abs=1e-12 * scale), key


def test_tangent_contact_is_a_distance_of_zero_at_the_contact_angle():
    """A box on a carrier whose edge just grazes a fixed face: distance 0 at one angle, no
    interference range (the solids touch, they do not cross), certified."""
    from test_sweep_fcl import BETA, RHO, carrier_scene, face_box

    from cadgen.sweep.search import certified_distance

    _, scene = carrier_scene(*face_box(RHO))
    result = certified_distance(scene, lipschitz=RHO, acceleration=RHO, steps=360, atol=1e-9)
    assert result.certified and result.minimum == 0.0 and result.bound <= 0.0
    assert result.interference_ranges == []
    # the contact angle: where the outer edge points at the face (either side of the axis)
    assert min(abs(result.argument - BETA), abs(result.argument - (2 * math.pi - BETA))) < 1e-5


def _catalogued_tests():
    text = (REPO / "docs" / "hard-cases.md").read_text(encoding="utf-8")
    return sorted(set(re.findall(r"`(tests/test_\w+\.py)::(test_\w+)`", text)))


def test_every_catalogued_case_is_a_test_in_the_suite():
    cases = _catalogued_tests()
    assert len(cases) >= 30
    for path, name in cases:
        tree = ast.parse((REPO / path).read_text(encoding="utf-8"))
        names = {node.name for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)}
        assert name in names, f"{path}::{name} is in docs/hard-cases.md but not in the suite"
