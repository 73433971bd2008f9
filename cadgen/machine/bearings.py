"""Deep-groove ball bearings: ISO 281 basic rating life and the choice from the catalogue.

The basic rating life of a ball bearing (ISO 281:2007, eq. 1 with the ball
exponent p = 3) in hours at a constant speed:

    L10h = (C / P)^3 * 10^6 / (60 n)

C the basic dynamic load rating (N), P the equivalent dynamic load (N), n the
inner ring's speed relative to the outer ring (r/min). The gears of these
mechanisms are spur gears, so the bearings take no axial load and P = Fr
(ISO 281 X = 1, Y = 0). The radial load is taken as acting all revolution at its
largest value over the cycle (the design load times the service factor), which is
conservative: the soil load acts only while the tool is in the ground. Where the dynamics
ran, P is ISO 281's cycle-equivalent load over the turn instead
(:func:`cadgen.machine.cycle_loads.equivalent_load`).
"""

from __future__ import annotations

import math

from cadgen.machine.catalogue import bearings_with_bore
from cadgen.machine.model import Bearing

__all__ = ["BALL_EXPONENT", "l10_hours", "select_bearing", "journal_bore"]

#: ISO 281's life exponent for ball bearings.
BALL_EXPONENT = 3.0


def l10_hours(C_kN: float, P_N: float, rpm: float) -> float:
    """ISO 281 basic rating life L10h (h) of a ball bearing.

    Parameters
    ----------
    C_kN : float
        Basic dynamic load rating, kN.
    P_N : float
        Equivalent dynamic load, N (= the radial load for spur gears).
    rpm : float
        Speed of the inner ring relative to the outer, r/min.

    Returns
    -------
    float
        ``(C/P)^3 * 1e6 / (60 rpm)``; ``inf`` when the load or the speed is 0 (no
        fatigue: a bearing standing still is checked by its static rating instead).
    """
    C, P, rpm = float(C_kN) * 1000.0, float(P_N), float(rpm)
    if C <= 0 or P < 0 or rpm < 0:
        raise ValueError(f"l10_hours needs C > 0, P >= 0 and rpm >= 0, not C = {C_kN} kN, "
                         f"P = {P_N} N, rpm = {rpm}")
    if P == 0.0 or rpm == 0.0:
        return math.inf
    return (C / P) ** BALL_EXPONENT * 1e6 / (60.0 * rpm)


def select_bearing(d: float, load_n: float, rpm: float, life_min_h: float, *,
                   min_width: float = 0.0) -> tuple:
    """The smallest catalogue bearing of bore ``d`` whose L10h reaches ``life_min_h``.

    Parameters
    ----------
    d : float
        Shaft diameter = bearing bore, mm.
    load_n : float
        Radial load on the bearing, N, taken as acting all revolution (conservative).
    rpm : float
        Mean speed of the inner ring relative to the housing, r/min.
    life_min_h : float
        The life every bearing must reach, h.
    min_width : float
        Only bearings at least this wide (mm) are considered (the drivetrain's rounds never
        go back to a narrower bearing, so they settle); the widest of the bore when none is.

    Returns
    -------
    (Bearing, float, bool)
        The bearing (smallest outside diameter, then width, among those that last),
        its life L10h and whether it reaches ``life_min_h``. When none does, the one
        with the largest C and ``False``: the caller reports ``bearing_life_short``.

    Raises
    ------
    ValueError
        No catalogue bearing has bore ``d``.
    """
    candidates = bearings_with_bore(d)
    if not candidates:
        raise ValueError(f"no catalogue bearing has a {d:g} mm bore")
    wide = [b for b in candidates if b.width >= min_width]
    candidates = wide or [max(candidates, key=lambda b: (b.width, b.dynamic_load_kn))]
    for bearing in sorted(candidates, key=lambda b: (b.outside, b.width)):
        life = l10_hours(bearing.dynamic_load_kn, load_n, rpm)
        if life >= life_min_h:
            return bearing, life, True
    strongest: Bearing = max(candidates, key=lambda b: b.dynamic_load_kn)
    return strongest, l10_hours(strongest.dynamic_load_kn, load_n, rpm), False


def journal_bore(d: float) -> float:
    """The bore the bearings of a shaft of ``d`` have: ``d``, or (off the catalogue) the largest
    bore below it (the journals turned down to it), else the smallest bore."""
    from cadgen.machine.catalogue import preferred_diameters

    bores = preferred_diameters()
    if d in bores:
        return d
    below = [b for b in bores if b <= d]
    return below[-1] if below else bores[0]
