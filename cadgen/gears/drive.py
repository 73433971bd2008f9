"""The transmission box's drive: one countershaft turning the central shaft O and carrier 1.

The planting mechanism's central shaft O and its carrier 1 (gearbox 1, turning about O) must
turn the same way, O at ``n`` times the carrier's speed. A fixed frame (the transmission box)
holds one input shaft parallel to O at centre distance ``a`` carrying two gears:

* pair 1: input gear ``z1`` meshing with the central-shaft gear ``z2`` (keyed to O);
* pair 2: input gear ``z3`` meshing with the transmission driven gear ``z4`` (fixed to
  gearbox 1, coaxial with O, its bore clearing a hub sleeve around O).

Both meshes are external, so O and the carrier both turn opposite the input, i.e. the same
way: ``omega_O = omega_in z1 / z2``, ``omega_carrier = omega_in z3 / z4``, hence
``n = (z1 z4) / (z2 z3)``. Both pairs are standard (unshifted) spur gears of one module on the
same axis distance, so ``z1 + z2 == z3 + z4 == S`` and ``a = m S / 2``.

Numbers only (standard library); :func:`drive_design` chooses the teeth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from kinematics.errors import DesignError

__all__ = ["DriveDesign", "drive_design", "RULE", "EXACT_TOLERANCE", "RIM_MODULES",
           "DEDENDUM_MODULES"]

#: Relative ratio errors below this count as exact.
EXACT_TOLERANCE = 1e-12
#: Dedendum of a standard tooth, in modules (root radius = pitch radius - 1.25 m).
DEDENDUM_MODULES = 1.25
#: Least rim left between the driven gear's root circle and the hub sleeve, in modules.
RIM_MODULES = 2.5

RULE = ("n = (z1 z4)/(z2 z3) with z1 + z2 = z3 + z4 = S (standard spur gears, one module m, "
        "a = m S / 2); driven gear rim: m z4/2 - 1.25 m - sleeve/2 >= 2.5 m; chosen by least "
        "|ratio error| (< 1e-12 exact), then least S, then input speed nearest the target")


@dataclass(frozen=True)
class DriveDesign:
    """The chosen countershaft drive (lengths in mm, speeds in rpm).

    ``teeth`` is ``(z1, z2, z3, z4)``; ``radii`` the pitch radii in the same order.
    ``ratio_error`` is ``ratio_achieved / ratio_requested - 1`` (signed).
    """

    module_1: float
    module_2: float
    teeth: tuple[int, int, int, int]
    centre_distance: float
    ratio_requested: float
    ratio_achieved: float
    ratio_error: float
    input_speed_rpm: float
    carrier_speed_rpm: float
    radii: tuple[float, float, float, float]
    sleeve_diameter: float
    exact: bool

    @property
    def central_shaft_rpm(self) -> float:
        z1, z2, _, _ = self.teeth
        return self.input_speed_rpm * z1 / z2

    @property
    def rim(self) -> float:
        """Radial material between the driven gear's root circle and the sleeve (mm)."""
        return self.radii[3] - DEDENDUM_MODULES * self.module_2 - self.sleeve_diameter / 2

    @property
    def ratio_fraction(self) -> Fraction:
        z1, z2, z3, z4 = self.teeth
        return Fraction(z1 * z4, z2 * z3)

    def as_report(self) -> dict:
        """JSON-ready summary with the one-line ``rule``."""
        frac = self.ratio_fraction
        return {
            "module_1": self.module_1,
            "module_2": self.module_2,
            "teeth": {"z1": self.teeth[0], "z2": self.teeth[1],
                      "z3": self.teeth[2], "z4": self.teeth[3]},
            "centre_distance": self.centre_distance,
            "pitch_radii": list(self.radii),
            "ratio_requested": self.ratio_requested,
            "ratio_achieved": self.ratio_achieved,
            "ratio_fraction": f"{frac.numerator}/{frac.denominator}",
            "ratio_error": self.ratio_error,
            "exact": self.exact,
            "carrier_speed_rpm": self.carrier_speed_rpm,
            "central_shaft_rpm": self.central_shaft_rpm,
            "input_speed_rpm": self.input_speed_rpm,
            "sleeve_diameter": self.sleeve_diameter,
            "driven_gear_rim": self.rim,
            "rule": RULE,
        }


def _positive(path: str, value, code: str = "drive_value_invalid") -> float:
    value = float(value)
    if not math.isfinite(value) or value <= 0:
        raise DesignError.single(path, code, f"{path} must be a positive finite number, got {value!r}")
    return value


def drive_design(n: float, carrier_rpm: float, module: float, sleeve_diameter: float, *,
                 min_teeth: int = 17, max_teeth: int = 150,
                 input_speed_ratio: float | None = None, hubs=(0.0, 0.0, 0.0, 0.0)) -> DriveDesign:
    """Choose ``(z1, z2, z3, z4)`` so that O turns at ``n`` times the carrier's speed.

    Both pairs are standard spur gears of module ``module``, so ``z1 + z2 == z3 + z4 == S``;
    every gear has ``min_teeth <= z <= max_teeth``. Rim rule: the driven gear z4's root circle
    must leave a rim around the hub sleeve,
    ``m z4 / 2 - 1.25 m - sleeve_diameter / 2 >= 2.5 m``; the same rule round each gear's hub
    (``hubs``: the diameters its bore and keyway reach, ``d + 2 t2``, mm; 0: none known).

    S is searched from ``2 min_teeth`` to ``2 max_teeth`` and the choice minimises, in order:
    the relative ratio error ``|z1 z4 / (z2 z3) / n - 1|`` (below 1e-12 counts as exact); S;
    the distance of the input speed ratio ``z4 / z3`` from ``input_speed_ratio`` (default
    ``n``: the input turning at the central shaft's speed, i.e. ``z1 == z2`` when possible).
    A ratio no exact choice reaches (irrational ``n``) gives the nearest with ``exact=False``.

    Raises
    ------
    kinematics.errors.DesignError
        (a ``ValueError``) at ``train.n``: ``drive_ratio_invalid`` for ``n <= 1`` or not
        finite; ``drive_ratio_unreachable`` when no gear set meets the constraints or ``n``
        lies beyond the largest ratio they allow (the message names the nearest one).
    """
    n = float(n)
    if not math.isfinite(n) or n <= 1:
        raise DesignError.single("train.n", "drive_ratio_invalid",
                                 f"speed ratio n must be a finite number above 1 (O faster than "
                                 f"the carrier, same sense), got {n!r}")
    carrier_rpm = _positive("train.carrier_rpm", carrier_rpm)
    m = _positive("train.module", module)
    sleeve = float(sleeve_diameter)
    if not math.isfinite(sleeve) or sleeve < 0:
        raise DesignError.single("train.sleeve_diameter", "drive_value_invalid",
                                 f"sleeve diameter must be finite and >= 0, got {sleeve!r}")
    target = n if input_speed_ratio is None else _positive("train.input_speed_ratio",
                                                            input_speed_ratio)
    if int(min_teeth) != min_teeth or int(max_teeth) != max_teeth or not 1 <= min_teeth <= max_teeth:
        raise DesignError.single("train.teeth", "drive_value_invalid",
                                 f"need integers 1 <= min_teeth <= max_teeth, got "
                                 f"{min_teeth!r}, {max_teeth!r}")
    lo, hi = int(min_teeth), int(max_teeth)
    # Rim rule solved for each gear's least count (small slack against float noise in hub / m)
    def least(hub):
        return max(lo, math.ceil(DEDENDUM_MODULES * 2 + RIM_MODULES * 2 + hub / m - 1e-9))

    hubs = tuple(float(h) for h in hubs)
    z1_min, z2_min, z3_min = (least(h) for h in hubs[:3])
    z4_min = least(max(sleeve, hubs[3]))

    best = None          # (key, teeth)
    ratio_max = ratio_min = None
    for s in range(2 * lo, 2 * hi + 1):
        z1_lo, z1_hi = max(z1_min, s - hi), min(hi, s - z2_min)
        z3_lo, z3_hi = max(z3_min, s - hi), min(hi, s - z4_min)
        if z1_lo > z1_hi or z3_lo > z3_hi:
            continue
        top = z1_hi * (s - z3_lo) / ((s - z1_hi) * z3_lo)
        bottom = z1_lo * (s - z3_hi) / ((s - z1_lo) * z3_hi)
        ratio_max = top if ratio_max is None else max(ratio_max, top)
        ratio_min = bottom if ratio_min is None else min(ratio_min, bottom)
        for z1 in range(z1_lo, z1_hi + 1):
            z2 = s - z1
            # z3 / z4 = (z1 / z2) / n  ->  real z3; the ratio falls as z3 grows, so the best
            # integer z3 is one of its neighbours (clipped to the feasible range).
            r = z1 / (z2 * n)
            z3_real = r * s / (1 + r)
            for z3 in {min(z3_hi, max(z3_lo, math.floor(z3_real))),
                       min(z3_hi, max(z3_lo, math.ceil(z3_real)))}:
                z4 = s - z3
                ratio = (z1 * z4) / (z2 * z3)
                err = abs(ratio / n - 1)
                key = (0.0 if err < EXACT_TOLERANCE else err, s, abs(z4 / z3 - target), z1, z3)
                if best is None or key < best[0]:
                    best = (key, (z1, z2, z3, z4))
        if best is not None and best[0][0] == 0.0:
            break        # exact at this S: a larger S cannot win

    if best is None:
        raise DesignError.single("train.n", "drive_ratio_unreachable",
                                 f"no gear set meets the constraints ({lo} <= z <= {hi}, driven "
                                 f"gear z4 >= {z4_min} for the rim around a {sleeve:g} mm "
                                 f"sleeve at module {m:g}); no ratio is achievable")
    if best[0][0] != 0.0 and not ratio_min * (1 - EXACT_TOLERANCE) <= n <= ratio_max * (1 + EXACT_TOLERANCE):
        z1, z2, z3, z4 = best[1]
        raise DesignError.single("train.n", "drive_ratio_unreachable",
                                 f"speed ratio n = {n:g} lies beyond the ratios the constraints "
                                 f"allow ({ratio_min:.6g} .. {ratio_max:.6g} with {lo} <= z <= "
                                 f"{hi}, z4 >= {z4_min}); nearest achievable ratio "
                                 f"{(z1 * z4) / (z2 * z3):.6g} with teeth {best[1]}")

    z1, z2, z3, z4 = best[1]
    achieved = (z1 * z4) / (z2 * z3)
    return DriveDesign(
        module_1=m, module_2=m, teeth=best[1], centre_distance=m * (z1 + z2) / 2,
        ratio_requested=n, ratio_achieved=achieved, ratio_error=achieved / n - 1,
        input_speed_rpm=carrier_rpm * z4 / z3, carrier_speed_rpm=carrier_rpm,
        radii=tuple(m * z / 2 for z in best[1]), sleeve_diameter=sleeve,
        exact=best[0][0] == 0.0)
