"""Shaft sizing: the shaft as a beam on two bearings, its diameter from torque and bending, keys.

The beam. A shaft rests on two bearings, the floor's at ``z1`` and the roof's at
``z2`` (heights from the housing's cavity floor; a bearing sits in its end wall
from the inner face outwards, so ``z1 = -B1/2`` and ``z2 = cavity_height + B2/2``).
The loads are each gear's mesh resultant at its mid-plane, plus any external load
at its height (beyond a bearing: an overhang). The mesh forces of one shaft point
in different directions over the cycle; they are all taken in one direction, which
gives the largest reactions and moments any combination could (conservative).
Reactions by statics, the bending moment is piecewise linear between the load and
bearing points, so its largest magnitude is at one of them.

The diameter (Tresca / ASME closed form, static strength with a safety factor):

    d_req = (16 S / (pi tau_allow) * sqrt(M^2 + T^2))^(1/3),   tau_allow = yield / 2

M the largest bending moment, T the largest torque (both N mm; taken together even
where they occur at different heights, conservative), S the safety factor. The
chosen diameter is the smallest preferred one (a catalogue bearing's bore) whose
core under its keyseat (``d - t1`` of its DIN 6885 key; below 10 mm a D-flat of
depth ``0.1 d`` instead) still reaches ``d_req``.

Keys. A parallel key (form A, round ends) of length ``l`` and width ``b`` carries
on its effective length ``l - b``; the flank pressure on the hub side is

    p = 2 T / (d (h - t1) (l - b))

checked against the allowed ``key_pressure_mpa``.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.machine.catalogue import CatalogueError, key_for_shaft, key_length, preferred_diameters

__all__ = ["FLAT_DEPTH_RATIO", "KEYLESS_BELOW", "beam_reactions", "bending_moments",
           "max_bending", "required_diameter", "shaft_core", "choose_diameter", "key_pressure",
           "hub_key", "hollow_required", "RULES"]

#: Shafts below this diameter (mm) get a D-flat instead of a key (no DIN 6885 key under 10 mm
#: carries a useful torque, and a flat is easier to make on a small shaft).
KEYLESS_BELOW = 10.0
#: D-flat depth as a fraction of the diameter: deep enough to drive a set screw's hub.
FLAT_DEPTH_RATIO = 0.1

RULES = {
    "beam": "simply supported on its two bearings (floor z1 = -B1/2, roof z2 = cavity + B2/2); "
            "every radial load in one direction (conservative); reactions by statics",
    "required_diameter": "d = (16 S / (pi tau) sqrt(M^2 + T^2))^(1/3), tau = yield / 2 "
                         "(Tresca / ASME, static), S = shaft_safety_factor",
    "chosen_diameter": "smallest bearing bore whose core (d - t1 under the key; d - 0.1 d "
                       "under a D-flat below 10 mm) reaches the required diameter",
    "key": "DIN 6885-1 form A; length the longest standard one within the face width; "
           "p = 2 T / (d (h - t1) (l - b)) <= key_pressure_mpa",
    "flat": "below 10 mm a D-flat of depth 0.1 d; the check is the shaft's own torsion only",
}


def _loads(loads):
    loads = np.asarray(loads, dtype=float).reshape(-1, 2)
    if not np.all(np.isfinite(loads)):
        raise ValueError(f"beam loads must be finite (z, force) pairs, not {loads.tolist()}")
    return loads


def beam_reactions(z1: float, z2: float, loads) -> tuple:
    """Bearing reactions ``(R1, R2)`` (N) of a beam on supports at ``z1`` and ``z2``.

    Parameters
    ----------
    z1, z2 : float
        Support heights, mm, ``z1 != z2``.
    loads : (n, 2) float
        ``(z, force)`` pairs: each force's height (mm, anywhere, overhangs allowed)
        and magnitude (N), all in one direction.

    Returns
    -------
    (float, float)
        The reactions, opposite to the loads: ``R1 + R2 = sum(force)`` and the
        moments about either support vanish.
    """
    z1, z2 = float(z1), float(z2)
    if not abs(z2 - z1) > 1e-9:
        raise ValueError(f"the bearings must be apart, not at z1 = {z1} and z2 = {z2}")
    loads = _loads(loads)
    z, force = loads[:, 0], loads[:, 1]
    R2 = float(np.sum(force * (z - z1)) / (z2 - z1))
    return float(np.sum(force)) - R2, R2


def bending_moments(z1: float, z2: float, loads, at) -> np.ndarray:
    """Bending moment (N mm) at heights ``at`` (mm): the moments of the forces below each height.

    Reactions act against the loads; the sign is the loads' sense (positive sags).
    """
    R1, R2 = beam_reactions(z1, z2, loads)
    loads = _loads(loads)
    points = np.concatenate([[float(z1), float(z2)], loads[:, 0]])
    forces = np.concatenate([[-R1, -R2], loads[:, 1]])   # loads positive, reactions against
    at = np.asarray(at, dtype=float)
    arm = at[..., None] - points                          # (..., n + 2)
    return -np.sum(np.where(arm > 0.0, forces * arm, 0.0), axis=-1)


def max_bending(z1: float, z2: float, loads) -> float:
    """The largest bending moment magnitude (N mm) over the shaft (at a load or bearing point)."""
    loads = _loads(loads)
    if len(loads) == 0:
        return 0.0
    at = np.concatenate([[float(z1), float(z2)], loads[:, 0]])
    return float(np.max(np.abs(bending_moments(z1, z2, loads, at))))


def required_diameter(bending_nmm: float, torque_nmm: float, yield_mpa: float,
                      safety: float) -> float:
    """``(16 S / (pi tau) sqrt(M^2 + T^2))^(1/3)`` with ``tau = yield / 2`` (mm)."""
    if not (yield_mpa > 0 and safety > 0):
        raise ValueError(f"yield and safety factor must be positive, not {yield_mpa}, {safety}")
    tau = float(yield_mpa) / 2.0   # Tresca: the shear yield is half the tensile yield
    equivalent = math.hypot(float(bending_nmm), float(torque_nmm))
    return (16.0 * float(safety) / (math.pi * tau) * equivalent) ** (1.0 / 3.0)


def shaft_core(d: float) -> tuple:
    """``(core, key, flat_depth)`` of a shaft of diameter ``d``: under its keyseat or flat.

    Below :data:`KEYLESS_BELOW` a D-flat (depth ``0.1 d``, key None); otherwise the
    DIN 6885 key for ``d`` (default length) and no flat.
    """
    d = float(d)
    if d < KEYLESS_BELOW:
        depth = FLAT_DEPTH_RATIO * d
        return d - depth, None, depth
    key = key_for_shaft(d)
    return d - key.shaft_depth, key, 0.0


def choose_diameter(required: float) -> float | None:
    """The smallest preferred diameter (a bearing bore) whose core reaches ``required``; None if
    even the largest does not."""
    for d in preferred_diameters():
        try:
            core = shaft_core(d)[0]
        except CatalogueError:   # a bore with no key in the table: not a candidate
            continue
        if core >= required - 1e-12:
            return d
    return None


def key_pressure(torque_nmm: float, d: float, key) -> float:
    """Flank pressure (MPa) of a form-A key: ``2 T / (d (h - t1) (l - b))``; inf if ``l <= b``."""
    effective = key.length - key.width
    if torque_nmm == 0.0:
        return 0.0
    if effective <= 0.0:
        return math.inf
    return 2.0 * float(torque_nmm) / (float(d) * (key.height - key.shaft_depth) * effective)


def hub_key(d: float, face_width: float):
    """The key of a hub of ``face_width`` on a shaft of ``d`` (mm), or None below 10 mm.

    Its length is the longest standard length within the face width.
    :class:`~cadgen.machine.catalogue.CatalogueError` when no standard key is that
    short or the shaft is outside the key table.
    """
    if float(d) < KEYLESS_BELOW:
        return None
    key = key_for_shaft(d, key_length(face_width))
    return key


def hollow_required(bending: float, torque: float, bore: float, machine) -> float:
    """The least outside diameter (mm) of a tube of ``bore`` whose largest shear stress under
    bending and torsion, ``16 d sqrt(M^2 + T^2) / (pi (d^4 - bore^4))``, stays within ``tau / S``
    (``tau = yield / 2``), by bisection (the stress falls as ``d`` grows)."""
    tau = machine.shaft_yield_mpa / 2 / machine.shaft_safety_factor
    moment = math.hypot(bending, torque)

    def stress(d):
        return 16 * d * moment / (math.pi * (d ** 4 - bore ** 4))
    low, high = bore + 1e-6, bore + 200.0
    if moment == 0.0:
        return bore
    for _ in range(100):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if stress(middle) > tau else (low, middle)
    return high
