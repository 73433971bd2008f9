"""Pair-by-pair certified search (cadgen.sweep.pairwise) on scenes with closed-form distances.

Each synthetic pair's distance is a trigonometric sum with known bounds on its
first and second derivatives; the scene answers the three levels of the pair
scene with deliberately loose (but true) lower bounds, so that the search must
climb them. Truth: dense scans of the closed forms; the interval bounds against
brute-force minima of functions that attain them.
"""

import math

import numpy as np
import pytest

from cadgen.sweep.scene import Proximity
from cadgen.sweep.search import certified_distance
from kinematics.sweep import chord_bound, lipschitz_bound


class TrigScene:
    """Pairs with ``d_p(phi) = c + a sin(k phi + s) + b cos(m phi)``; levels of lower bounds.

    ``lower_bounds`` are the distances less a slack of up to 40 mm (bounding spheres),
    ``refine`` less up to 0.5 mm and exact on the pairs in ``attained`` (hulls), and
    ``exact`` the closed form. The slacks are pseudo-random per pose, reproducible.
    """

    def __init__(self, rng, pairs=6, attained=(0, 2), tight=()):
        self.pairs = [(f"a{p}", f"b{p}") for p in range(pairs)]
        self.c = rng.uniform(40.0, 120.0, pairs)
        self.a = rng.uniform(5.0, 30.0, pairs)
        self.k = rng.integers(1, 4, pairs).astype(float)
        self.s = rng.uniform(0.0, 2 * math.pi, pairs)
        self.b = rng.uniform(0.0, 8.0, pairs)
        self.m = rng.integers(2, 7, pairs).astype(float)
        self.attained = set(attained)
        self.tight = set(tight)   # bound equal to the distance, yet not shown exact
        self.calls = {"lower_bounds": 0, "refine": 0, "exact": 0}

    # the bounds the search is given (exact maxima of |d'| and |d''| are below them)
    @property
    def speeds(self):
        return self.a * self.k + self.b * self.m

    @property
    def accelerations(self):
        return self.a * self.k**2 + self.b * self.m**2

    def truth(self, phi):
        phi = np.asarray(phi, dtype=float)[..., None]
        return (self.c + self.a * np.sin(self.k * phi + self.s) + self.b * np.cos(self.m * phi))

    def _slack(self, phi, pair, scale):
        return scale * (0.5 + 0.5 * math.sin(1e3 * phi + 7.0 * pair) ** 2)

    def lower_bounds(self, phi, pairs=None):
        self.calls["lower_bounds"] += 1
        out = self.truth(phi) - np.array([self._slack(phi, p, 40.0) for p in range(len(self.pairs))])
        if pairs is not None:
            out = np.where(pairs, out, -np.inf)
        return out

    def _proximity(self, phi, pair, value):
        point = np.array([phi, 0.0, 0.0])
        return Proximity(float(value), point, point + (value, 0.0, 0.0), self.pairs[pair])

    def refine(self, phi, pair, below=math.inf):
        self.calls["refine"] += 1
        value = float(self.truth(phi)[pair])
        if pair in self.attained:
            return value, value, self._proximity(phi, pair, value)
        if pair in self.tight:
            return value, value, None
        return value - self._slack(phi, pair, 0.5), value + 3.0, None

    def exact(self, phi, pair, lower=0.0):
        self.calls["exact"] += 1
        return self._proximity(phi, pair, self.truth(phi)[pair])

    def distance(self, phi):
        values = self.truth(phi)
        p = int(np.argmin(values))
        return self._proximity(phi, p, values[p])

    def distances(self, phis):
        return self.truth(phis).min(axis=-1)


@pytest.mark.parametrize("seed, tight", [(1, ()), (2, ()), (3, ()), (4, ()), (5, ()),
                                         (1, (1, 3, 4, 5)), (3, (1, 3, 4, 5))],
                         ids=["1", "2", "3", "4", "5", "1-tight", "3-tight"])
def test_certified_minimum_of_pairs_against_a_dense_scan(seed, tight):
    # "tight": pairs whose hull bound equals their distance though no certificate says so:
    # a distance attained there must still be confirmed exactly before it is a pose's
    scene = TrigScene(np.random.default_rng(seed), tight=tight)
    bounds = {name: (speed / 2, acc / 2) for (a, b), speed, acc in
              zip(scene.pairs, scene.speeds, scene.accelerations) for name in (a, b)}
    result = certified_distance(scene, instance_bounds=bounds, steps=90, atol=1e-7)
    phi = np.linspace(0.0, 2 * math.pi, 2_000_001)
    dense = scene.truth(phi).min(axis=1)
    best = int(np.argmin(dense))
    truth = dense[best]
    # the dense scan's best sample is above the true minimum by at most K h^2 / 8
    slack = scene.accelerations.max() * (phi[1] - phi[0]) ** 2 / 8
    assert result.certified and not result.interference_ranges
    assert result.bound <= truth + 1e-12
    assert truth - slack - 1e-12 <= result.minimum <= truth + 1e-7
    assert result.minimum == pytest.approx(float(scene.truth(result.argument).min()), abs=1e-12)
    # the screening samples are the exact distances (the report's curve)
    assert result.samples_distance == pytest.approx(scene.distances(result.samples_phi), abs=0)
    # a pair's own (smaller) bounds: few exact queries beside the grid
    assert scene.calls["exact"] < 20 * len(scene.pairs) + 91
    # the certificate: intervals tiling the turn, each bound below the true distance on it
    certificate = result.certificate[np.argsort(result.certificate[:, 0])]
    assert certificate[0, 0] == 0.0 and certificate[-1, 1] == 2 * math.pi
    assert np.all(certificate[1:, 0] == certificate[:-1, 1])
    assert certificate[:, 2].min() == pytest.approx(result.bound, abs=0)
    for left, right, bound in certificate:
        inside = dense[(phi >= left) & (phi <= right)]
        assert bound <= inside.min() + 1e-12


def test_an_overlap_is_found_and_its_range_bisected():
    scene = TrigScene(np.random.default_rng(7))
    scene.c[3] = scene.a[3] - 2.0   # pair 3 dips 2 mm below 0 round its trough
    # d = c + a sin(k phi + s) + b cos(m phi) <= 0 somewhere: overlap; distances clipped at 0
    truth = scene.truth

    def clipped(phi):
        return np.maximum(truth(phi), 0.0)

    scene.truth = clipped
    speed = float(scene.speeds.max())
    result = certified_distance(scene, lipschitz=speed, steps=90, atol=1e-7)
    assert result.interferes and result.minimum == 0.0 and result.bound == 0.0
    phi = np.linspace(0.0, 2 * math.pi, 400_001)
    overlapping = truth(phi)[:, 3] <= 0.0
    starts = phi[1:][overlapping[1:] & ~overlapping[:-1]]
    assert len(result.interference_ranges) == len(starts)
    for (start, _), expected in zip(result.interference_ranges, starts):
        assert start == pytest.approx(expected, abs=2 * (phi[1] - phi[0]))


# ------------------------------------------------------------------ the interval bounds
def test_lipschitz_bound_is_attained_by_a_cone_and_never_exceeded(rng):
    f_left, f_right = rng.uniform(-5, 5, 200), rng.uniform(-5, 5, 200)
    width, lipschitz = rng.uniform(0.01, 2.0, 200), rng.uniform(0.1, 10.0, 200)
    bound = lipschitz_bound(f_left, f_right, width, lipschitz)
    # the lowest L-Lipschitz function through the two end values: the upper envelope of cones
    x = np.linspace(0.0, 1.0, 20_001)[:, None] * width
    sampled = np.maximum(f_left - lipschitz * x, f_right - lipschitz * (width - x)).min(axis=0)
    # sampling lies above the envelope's minimum by at most L times half a sample spacing
    assert np.all(bound <= sampled + 1e-12)
    assert np.all(sampled - bound <= lipschitz * width / 20_000 + 1e-12)


def test_chord_bound_is_attained_by_the_sagging_parabola(rng):
    f_left, f_right = rng.uniform(-5, 5, 200), rng.uniform(-5, 5, 200)
    width, curvature = rng.uniform(0.01, 2.0, 200), rng.uniform(0.0, 50.0, 200)
    bound = chord_bound(f_left, f_right, width, curvature)
    t = np.linspace(0.0, 1.0, 20_001)[:, None]
    parabola = f_left + (f_right - f_left) * t - 0.5 * curvature * width**2 * t * (1 - t)
    sampled = parabola.min(axis=0)
    # sampling lies above the minimum by at most (slope + sag) times half a spacing
    assert np.all(bound <= sampled + 1e-12)
    slope = np.abs(f_right - f_left) + curvature * width**2
    assert np.all(sampled - bound <= slope / 20_000 + 1e-12)
    # never below the classic screen, min(f_l, f_r) - K h^2 / 8
    assert np.all(bound >= np.minimum(f_left, f_right) - curvature * width**2 / 8 - 1e-12)
