"""Circular gears of a train: the largest standard module that gives each whole teeth.

A light module (no tooth generation, no scipy): the housings size themselves from it in a
metrics-only build, which must not pay for the cutter envelopes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from kinematics.errors import DesignError
from kinematics.profile_shift import undercut_free_shift

__all__ = ["MIN_CIRCULAR_TEETH", "circular_module", "planting_circular_radii", "planting_modules",
           "TRAIN1_SETS", "train1_set_radii", "holding_set_module", "holding_set_design",
           "SetDesign", "working_shift_sum", "planting_drive", "TrainAxes"]

#: Circular gears get at least this many teeth: a standard rack undercuts fewer (2/sin^2(20 deg)).
MIN_CIRCULAR_TEETH = 17


def _whole(radii, module, min_teeth=0) -> bool:
    counts = [2 * r / module for r in radii]
    return all(abs(c - round(c)) < 1e-6 and round(c) >= min_teeth for c in counts)


def _auto_module(radii) -> float | None:
    """The largest 0.05-mm step from 5 mm down to 0.5 mm giving every circular gear a whole
    count of at least ``MIN_CIRCULAR_TEETH`` teeth, or None."""
    for step in range(100, 9, -1):
        if _whole(radii, step * 0.05, MIN_CIRCULAR_TEETH):
            return round(step * 0.05, 10)
    return None


def _finest_module(radii, below: float = 5.0) -> float | None:
    """The largest 0.01-mm step below ``below`` giving whole tooth counts (any count), or None."""
    for step in range(int(round(below * 100)), 0, -1):
        if _whole(radii, step * 0.01):
            return round(step * 0.01, 10)
    return None


def _teeth_text(radii, module) -> str:
    return ", ".join(str(int(round(2 * r / module))) for r in radii)


def circular_module(radii, requested=None, *, hint: str = "") -> float:
    """The requested module, or the largest 0.05-mm step (5 mm down) giving whole tooth counts.

    Only modules that give every circular gear at least ``MIN_CIRCULAR_TEETH``
    teeth are considered, so no circular gear is undercut. When none fits, the
    ``fractional_teeth`` problem names the key to set (``gears.circular_module``) and a
    value that works; ``hint`` (another key and value that would, e.g. ``train.R``) is
    added to it.
    """
    diameters = ", ".join(f"{2 * r:g}" for r in radii)
    if requested is not None:
        if not _whole(radii, requested):
            counts = [2 * r / requested for r in radii]
            auto = _auto_module(radii)
            finest = _finest_module(radii, requested)
            works = ([f"set gears.circular_module = {auto:g} (teeth {_teeth_text(radii, auto)})"
                      f" or leave it out to have {auto:g} mm chosen"] if auto else
                     [f"set gears.circular_module = {finest:g} (teeth "
                      f"{_teeth_text(radii, finest)})"] if finest else [])
            raise DesignError.single(
                "gears.circular_module", "fractional_teeth",
                f"module {requested:g} mm gives tooth counts {', '.join(f'{c:.3f}' for c in counts)}"
                f" for the circular gears of radii {', '.join(f'{r:g}' for r in radii)} mm: "
                f"choose a module that divides every pitch diameter ({diameters} mm)"
                + "".join(f": {w}" for w in works) + (f"; or {hint}" if hint else ""))
        return float(requested)
    module = _auto_module(radii)
    if module is not None:
        return module
    finest = _finest_module(radii)
    works = (f"; set gears.circular_module to a module that divides every pitch diameter "
             f"({diameters} mm), e.g. {finest:g} (teeth {_teeth_text(radii, finest)})"
             if finest else "")
    raise DesignError.single(
        "gears.circular_module", "fractional_teeth",
        f"no module from 0.5 to 5 mm (0.05-mm steps, at least {MIN_CIRCULAR_TEETH} teeth) gives "
        f"whole tooth counts for the circular gears of radii "
        f"{', '.join(f'{r:g}' for r in radii)} mm{works}" + (f"; or {hint}" if hint else ""))


def _radius_hint(mechanism, key: str = "II") -> str:
    """The nearest base radii ``train.R`` (0.5-mm steps) whose circular gears (set II and
    gear r, or ``key = "I"``: set I) take an automatic module, as a hint for
    ``fractional_teeth``."""
    import dataclasses

    found = []
    for sign in (-1, 1):
        for k in range(1, 41):
            R = mechanism.R + sign * 0.5 * k
            if R <= 0:
                break
            moved = dataclasses.replace(mechanism, R=R)
            radii = (planting_circular_radii(moved) if key == "II"
                     else train1_set_radii(moved, "I"))
            if min(radii) > 0 and _auto_module(radii) is not None:
                found.append(f"train.R = {R:g} (module {_auto_module(radii):g} mm)")
                break
    return "set " + " or ".join(found) if found else ""


#: Train 1's two parallel gear sets on carrier 1 (the paper's numbering: set II's planet carries
#: gearbox 2, set I's holds the central non-circular gear still): ``(key, name, converted ratio
#: rule, gear names sun -> idler on A -> idler on B -> planet)``.
TRAIN1_SETS = (
    ("II", "set II: carries gearbox 2", "-2/(n - 1)",
     ("sun", "idler 1", "idler 2", "train-1 planet")),
    ("I", "set I: holds the central gear", "-1/(n - 1)",
     ("sun I", "idler 1-I", "idler 2-I", "planet I")),
)


@dataclass(frozen=True)
class TrainAxes:
    """Train 1's axes alone (``R``, ``i12``, ``i13``, ``n``, and gearbox 2's ``r``): what the sets'
    radii and modules need, without a whole mechanism (the optimiser's rows)."""

    R: float
    i12: float
    i13: float
    n: float
    r: float = 0.0


def train1_set_radii(mechanism, key: str = "II") -> list:
    """Pitch radii (mm) of one of train 1's sets: sun (O), idler (A), idler (B), planet (C).

    Each set is sun -> idler -> idler -> planet on the shared axes O, A, B, C (three external
    meshes: converted ratio ``-r_sun / r_planet``). With the sun at ``n`` times the carrier,
    set II's planet must turn at minus the carrier's speed (ratio ``-2/(n - 1)``) and set I's
    not at all (``-1/(n - 1)``). With ``q = r_sun / r_planet`` and the axis distances
    ``OA = R(1 + i12)``, ``AB = R(i12 + i13)``, ``BC = R(1 + i13)`` (the spec's carrier radii),
    the four radii solve ``r_s + r_A = OA``, ``r_A + r_B = AB``, ``r_B + r_p = BC``,
    ``r_s = q r_p``: ``r_s = 2 R q / (1 + q)``, since ``OA - AB + BC = 2 R``. For n = 3:
    set II ``R, R i12, R i13, R``; set I ``2R/3, R(1 + i12) - 2R/3, R(i13 - 1) + 2R/3, 4R/3``.
    """
    R, n = float(mechanism.R), float(mechanism.n)
    q = (2.0 if key == "II" else 1.0) / (n - 1.0)
    sun = 2.0 * R * q / (1.0 + q)
    idler_a = R * (1.0 + mechanism.i12) - sun
    idler_b = R * (mechanism.i12 + mechanism.i13) - idler_a
    return [sun, idler_a, idler_b, sun / q]


def planting_circular_radii(mechanism) -> list:
    """Pitch radii of the planting mechanism's circular gears that share ``gears.circular_module``:
    train 1's set II (sun, idlers, planet; :func:`train1_set_radii`) and gearbox 2's 1:1 gear
    ``r``. Set I has its own module (:func:`holding_set_module`)."""
    return train1_set_radii(mechanism, "II") + [mechanism.r]


@dataclass(frozen=True)
class SetDesign:
    """One of train 1's sets as cut: module, teeth, profile shifts and radii (mm).

    ``reference_radii`` are ``m z / 2`` (the circles the rack cuts on), ``working_radii``
    the circles that roll at the axis distances (``a_w z / (z1 + z2)`` of each mesh; a gear
    in two meshes has one per mesh, the sun's and the planet's are their one mesh's). With
    ``shifted`` False the gears are standard (``x = 0``) and both radii agree."""

    module: float
    teeth: tuple
    shifts: tuple
    reference_radii: tuple
    axis_distances: tuple
    shifted: bool
    rule: str = ""
    pressure_angle: float = math.radians(20.0)

    @property
    def shortening(self) -> tuple:
        """Each gear's tip shortening, modules (:func:`tip_shortening`; 0 for standard gears)."""
        if not self.shifted:
            return (0.0,) * len(self.teeth)
        return tip_shortening(self.teeth, self.module, self.shifts, self.axis_distances,
                              self.pressure_angle)

    def working_radii(self, mesh: int) -> tuple:
        """The (drive, driven) rolling radii of mesh ``mesh`` (0, 1, 2) at its axis distance."""
        z1, z2 = self.teeth[mesh], self.teeth[mesh + 1]
        a = self.axis_distances[mesh]
        return a * z1 / (z1 + z2), a * z2 / (z1 + z2)


def _involute(alpha: float) -> float:
    return math.tan(alpha) - alpha


def working_shift_sum(z1: int, z2: int, module: float, axis_distance: float,
                      pressure_angle: float) -> float:
    """``x1 + x2`` that makes two standard-rack gears of ``z1``, ``z2`` teeth mesh without
    backlash at ``axis_distance`` (ISO 21771): ``cos alpha_w = a cos alpha / a_w``,
    ``x1 + x2 = (z1 + z2) (inv alpha_w - inv alpha) / (2 tan alpha)``, ``a = m (z1 + z2) / 2``."""
    a = module * (z1 + z2) / 2
    cosine = a * math.cos(pressure_angle) / axis_distance
    if not 0.0 < cosine < 1.0:
        raise ValueError(f"no working pressure angle: a = {a:g} mm at a_w = {axis_distance:g} mm")
    alpha_w = math.acos(cosine)
    return (z1 + z2) * (_involute(alpha_w) - _involute(pressure_angle)) / (2 * math.tan(pressure_angle))


def _shifted_set(radii, distances, q_fraction, module, pressure_angle):
    """Teeth and shifts of a set at ``module``: the sun's and planet's counts in the exact ratio
    ``q_fraction`` nearest their radii, the idlers' nearest theirs, the three shift sums from
    the axis distances, and of the one free choice left (the sun's shift; the others follow
    along the chain) the one that keeps every gear clear of undercut by the most, then the
    smallest largest shift. ``(worst |x|, undercut margin, teeth, shifts)`` or None when a
    count is below ``MIN_CIRCULAR_TEETH``."""
    p, q = q_fraction.numerator, q_fraction.denominator   # r_s / r_p = p / q
    k = max(1, round(2 * radii[0] / module / p))
    best = None
    for k in (k - 1, k, k + 1):   # the sun and planet counts k p, k q nearest their radii
        if k < 1:
            continue
        teeth = (k * p, round(2 * radii[1] / module), round(2 * radii[2] / module), k * q)
        if min(teeth) < MIN_CIRCULAR_TEETH:
            continue
        try:
            sums = [working_shift_sum(teeth[i], teeth[i + 1], module, distances[i],
                                      pressure_angle) for i in range(3)]
        except ValueError:
            continue
        # the least shift each keeps free of undercut by the standard rack (ha* = 1)
        floor = [float(undercut_free_shift(module * z / 2, module, pressure_angle))
                 for z in teeth]
        # x = (x_s, S1 - x_s, S2 - S1 + x_s, S3 - S2 + S1 - x_s): each a_i + s_i x_s
        signs = (1.0, -1.0, 1.0, -1.0)
        offsets = (0.0, sums[0], sums[1] - sums[0], sums[2] - sums[1] + sums[0])
        x_s, margin = _best_free_shift(offsets, signs, floor)
        shifts = tuple(o + g * x_s for o, g in zip(offsets, signs))
        worst = max(abs(x) for x in shifts)
        score = (min(margin, 0.0), -worst)
        if best is None or score > best[0]:
            best = (score, worst, margin, teeth, shifts)
    return None if best is None else best[1:]


def _best_free_shift(offsets, signs, floor) -> tuple:
    """The free shift ``x`` of a chain whose shifts are ``a_i + s_i x`` (``s_i`` = +-1): the
    one keeping every ``x_i`` above its undercut floor ``f_i`` by the most when that margin
    is negative; else, of those keeping all above, the one with the smallest largest ``|x_i|``.
    Both are piecewise linear in ``x``: the best lies at a breakpoint, all of which are tried.
    Returns ``(x, margin)``."""
    up = min(a - f for a, s, f in zip(offsets, signs, floor) if s > 0)     # margin: up + x
    down = min(a - f for a, s, f in zip(offsets, signs, floor) if s < 0)   # ... and down - x
    if up + down < 0.0:   # no x clears every floor: the largest margin
        x = (down - up) / 2
        return x, (up + down) / 2
    low, high = -up, down
    candidates = {low, high}
    lines = list(zip(offsets, signs))
    for i, (a, s) in enumerate(lines):
        candidates.add(-a / s)
        for b, t in lines[i + 1:]:
            if s != t:
                candidates.add((b - a) / (s - t))
            candidates.add(-(a + b) / (s + t) if s + t else low)
    inside = [x for x in candidates if low - 1e-12 <= x <= high + 1e-12]
    x = min(inside, key=lambda x: max(abs(a + s * x) for a, s in lines))
    return x, min(up + x, down - x)


def tip_shortening(teeth, module: float, shifts, distances, pressure_angle: float) -> tuple:
    """Each gear's addendum reduction (modules) so every mesh keeps the standard tip clearance
    at its working centre distance: ``k = (x1 + x2) - (a_w - a) / m`` per mesh (ISO 21771),
    a gear in two meshes the larger of its two."""
    k = [0.0] * len(teeth)
    for i in range(len(teeth) - 1):
        a = module * (teeth[i] + teeth[i + 1]) / 2
        mesh = shifts[i] + shifts[i + 1] - (distances[i] - a) / module
        k[i], k[i + 1] = max(k[i], mesh), max(k[i + 1], mesh)
    return tuple(max(value, 0.0) for value in k)


#: The largest profile shift (magnitude) a computed set uses: well inside the
#: ``gears.profile_shift`` range (-0.5, 0.8) and clear of pointed tips on 17+ teeth.
SHIFT_LIMIT = 0.5


def holding_set_design(mechanism, requested=None, pressure_angle: float = math.radians(20.0)):
    """Train 1's set I as cut (:class:`SetDesign`).

    Standard gears when a module gives each gear whole teeth on its radius
    (:func:`_standard_holding_module`'s rule). Otherwise profile-shifted gears: for each module
    (``requested``, else 0.05-mm steps from 5 mm down), the teeth nearest the radii with the
    sun-to-planet ratio exact, and the shifts that make each mesh's working centre distance
    its axis distance; the largest module whose shifts all stay within ``SHIFT_LIMIT``. The
    ratio must be rational (``n`` a ratio of small whole numbers); otherwise, or when no
    module works, ``DesignError`` names the reason and the nearest base radii that need none.
    """
    from fractions import Fraction

    radii = train1_set_radii(mechanism, "I")
    distances = (radii[0] + radii[1], radii[1] + radii[2], radii[2] + radii[3])
    module = _standard_holding_module(mechanism, requested)
    if module is not None:
        teeth = tuple(int(round(2 * r / module)) for r in radii)
        return SetDesign(module, teeth, (0.0,) * 4, tuple(module * z / 2 for z in teeth),
                         distances, False, "standard gears: whole teeth at the axis distances")
    ratio = Fraction(1.0 / (mechanism.n - 1.0)).limit_denominator(50)
    if abs(float(ratio) - 1.0 / (mechanism.n - 1.0)) > 1e-12:
        raise DesignError.single(
            "train.n", "holding_set_ratio_irrational",
            f"train 1's set I must turn its planet at exactly -1/(n - 1) = "
            f"{-1.0 / (mechanism.n - 1.0):.6g} of the sun (relative to the carrier) to hold the "
            f"central gear still; no whole tooth counts up to 50 give it: choose n a ratio of "
            f"small whole numbers (3, 2.5, 4, ...). "
            f"{_no_standard_module(mechanism, radii).problems[0].message}")
    modules = ([float(requested)] if requested is not None
               else [round(step * 0.05, 10) for step in range(100, 9, -1)])
    chosen = None
    for module in modules:   # the largest module clear of undercut, else the one nearest it
        found = _shifted_set(radii, distances, ratio, module, pressure_angle)
        if found is None or found[0] > SHIFT_LIMIT:
            continue
        if chosen is None or (chosen[1][1] < 0.0 and found[1] > chosen[1][1]):
            chosen = (module, found)
        if found[1] >= 0.0:
            break
    if chosen is not None:
        module, (_, _, teeth, shifts) = chosen
        return SetDesign(module, tuple(int(z) for z in teeth), tuple(shifts),
                         tuple(module * z / 2 for z in teeth), distances, True,
                         "profile-shifted gears: whole teeth nearest the radii, the "
                         "sun-to-planet ratio exact, each mesh's shift sum from its axis distance "
                         "(ISO 21771), the free choice keeping every gear clear of undercut, "
                         "tips shortened to the standard clearance", pressure_angle)
    # the refusal (its hint searches nearby base radii) is built only when it is raised: the
    # optimiser's screen asks for many designs that the shifts solve
    raise _no_standard_module(mechanism, radii, shifted_too=True)


def holding_set_module(mechanism, requested=None,
                       pressure_angle: float = math.radians(20.0)) -> float:
    """The module of train 1's set I (:func:`holding_set_design`), mm."""
    return holding_set_design(mechanism, requested, pressure_angle).module


def _standard_holding_module(mechanism, requested=None) -> float | None:
    """The module of train 1's set I (its planet holds the central gear still) with standard
    gears, mm, or None when no module gives whole teeth.

    ``requested`` (the file's ``gears.circular_module``) when it gives the set whole tooth
    counts, else the largest 0.05-mm step giving each of its gears whole teeth (at least
    ``MIN_CIRCULAR_TEETH``), so each mesh's centre distance is its axis distance with
    standard gears. A set whose idler on B would have no radius is refused (``DesignError``).
    """
    radii = train1_set_radii(mechanism, "I")
    if min(radii) <= 0.0:
        raise DesignError.single(
            "train.i13", "holding_set_impossible",
            f"train 1's set I (ratio -1/(n - 1), it holds the central gear still) needs radii "
            f"{', '.join(f'{r:.3g}' for r in radii)} mm on the axes O, A, B, C: the idler on B "
            f"would be {radii[2]:.3g} mm (R (i13 - 1) + 2 R / n must be > 0): raise train.i13 "
            f"above {1.0 - 2.0 / mechanism.n:.3g} or lower train.n")
    if requested is not None and _whole(radii, requested, MIN_CIRCULAR_TEETH):
        return float(requested)
    return _auto_module(radii)


def _no_standard_module(mechanism, radii, shifted_too: bool = False) -> DesignError:
    """The refusal of a set I no standard module fits (and, ``shifted_too``, no shifted one),
    with the nearest base radii that need no shift."""
    hint = _radius_hint(mechanism, key="I")
    shifted = (f"; nor do profile-shifted gears within |x| <= {SHIFT_LIMIT:g}"
               if shifted_too else "")
    return DesignError.single(
        "train.R", "fractional_teeth",
        f"no module from 0.5 to 5 mm (0.05-mm steps, at least {MIN_CIRCULAR_TEETH} teeth) gives "
        f"whole tooth counts for train 1's set I (radii {', '.join(f'{r:.4g}' for r in radii)} "
        "mm, whose meshes must meet the axis distances of set II)" + shifted
        + (f"; {hint}" if hint else ""))


def planting_modules(mechanism, teeth: int, requested=None) -> tuple:
    """``(non-circular module, circular module)`` of a planting design, mm.

    The non-circular one from the pitch curve's perimeter and ``teeth``; the circular
    one by :func:`circular_module` (``requested``: the file's ``gears.circular_module``).
    When no whole-tooth circular module exists the teeth stage says so; the housings,
    shafts and kinematic envelopes meanwhile size the circular gears as if they had
    ``requested`` or else the non-circular module.
    """
    module_nc = float(mechanism.module(teeth))
    try:
        module_c = circular_module(planting_circular_radii(mechanism), requested)
    except DesignError:
        module_c = requested or module_nc
    return module_nc, float(module_c)


#: The sleeve's outside diameter the drive's driven gear is designed round (mm): the largest
#: the sleeve takes (its journal in a 6010, the catalogue's largest bore); the drivetrain
#: checks the chosen sleeve against it.
DRIVE_SLEEVE_DIAMETER = 50.0


def planting_drive(mechanism, module_c: float, requested=None, carrier_rpm: float = 30.0,
                   pressure_angle: float = math.radians(20.0), hubs=(0.0, 0.0, 0.0, 0.0)):
    """The frame's drive of a planting design: :func:`cadgen.gears.drive.drive_design` at n with
    the larger of train 1's two modules (``module_c`` set II's, as :func:`planting_modules`
    gives it; ``requested`` the file's ``gears.circular_module``); ``hubs``: each gear's hub
    diameter (input gear 1, the central shaft's, input gear 2, the driven gear's) its rim
    must clear, once the drivetrain has sized their shafts. When no set of teeth reaches n at
    that module (a small module's gears cannot clear the hubs within ``max_teeth``), the next
    module of ISO 54's first series (``DRIVE_MODULES``) that does; the last refusal otherwise."""
    from cadgen.gears.drive import drive_design

    try:
        module_i = holding_set_module(mechanism, requested, pressure_angle)
    except DesignError:
        module_i = module_c
    module = max(module_c, module_i)
    refusal = None
    for candidate in [module] + [m for m in DRIVE_MODULES if m > module]:
        try:
            return drive_design(mechanism.n, carrier_rpm, candidate, DRIVE_SLEEVE_DIAMETER,
                                hubs=hubs)
        except DesignError as error:
            refusal = error
    raise refusal


#: Modules the drive may step up to when the train's does not reach n (ISO 54, first series).
DRIVE_MODULES = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0)
