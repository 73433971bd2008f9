"""Circular gears of a train: the largest standard module that gives each whole teeth.

A light module (no tooth generation, no scipy): the housings size themselves from it in a
metrics-only build, which must not pay for the cutter envelopes.
"""

from __future__ import annotations

from kinematics.errors import DesignError

__all__ = ["MIN_CIRCULAR_TEETH", "circular_module", "planting_circular_radii", "planting_modules",
           "TRAIN1_SETS", "train1_set_radii", "holding_set_module"]

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


def holding_set_module(mechanism, requested=None) -> float:
    """The module of train 1's set I (its planet holds the central gear still), mm.

    ``requested`` (the file's ``gears.circular_module``) when it gives the set whole tooth
    counts, else the largest 0.05-mm step giving each of its gears whole teeth (at least
    ``MIN_CIRCULAR_TEETH``), so each mesh's centre distance is its axis distance with
    standard gears. A set whose idler on B would have no radius, or that no module fits, is
    refused (``DesignError``) with the reason and the nearest base radii that work.
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
    module = _auto_module(radii)
    if module is not None:
        return module
    hint = _radius_hint(mechanism, key="I")
    raise DesignError.single(
        "train.R", "fractional_teeth",
        f"no module from 0.5 to 5 mm (0.05-mm steps, at least {MIN_CIRCULAR_TEETH} teeth) gives "
        f"whole tooth counts for train 1's set I (radii {', '.join(f'{r:.4g}' for r in radii)} "
        "mm, whose meshes must meet the axis distances of set II)" + (f"; {hint}" if hint else ""))


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
#: the sleeve takes (its journal in a 6008); the drivetrain checks the chosen sleeve against it.
DRIVE_SLEEVE_DIAMETER = 40.0


def planting_drive(mechanism, module_c: float, requested=None, carrier_rpm: float = 30.0):
    """The frame's drive of a planting design: :func:`cadgen.gears.drive.drive_design` at n with
    the larger of train 1's two modules (``module_c`` set II's, as :func:`planting_modules`
    gives it; ``requested`` the file's ``gears.circular_module``)."""
    from cadgen.gears.drive import drive_design

    try:
        module_i = holding_set_module(mechanism, requested)
    except DesignError:
        module_i = module_c
    return drive_design(mechanism.n, carrier_rpm, max(module_c, module_i), DRIVE_SLEEVE_DIAMETER)
