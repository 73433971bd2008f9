"""Circular gears of a train: the largest standard module that gives each whole teeth.

A light module (no tooth generation, no scipy): the housings size themselves from it in a
metrics-only build, which must not pay for the cutter envelopes.
"""

from __future__ import annotations

from kinematics.errors import DesignError

__all__ = ["MIN_CIRCULAR_TEETH", "circular_module", "planting_circular_radii", "planting_modules"]

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


def _radius_hint(mechanism) -> str:
    """The nearest base radii ``train.R`` (0.5-mm steps) whose circular gears take an
    automatic module, as a hint for ``fractional_teeth``."""
    found = []
    for sign in (-1, 1):
        for k in range(1, 41):
            R = mechanism.R + sign * 0.5 * k
            radii = [R, R * mechanism.i12, R * mechanism.i13, R, mechanism.r]
            if R > 0 and _auto_module(radii) is not None:
                found.append(f"train.R = {R:g} (module {_auto_module(radii):g} mm)")
                break
    return "set " + " or ".join(found) if found else ""


def planting_circular_radii(mechanism) -> list:
    """Pitch radii of the planting mechanism's circular gears: train 1's set (sun, idlers,
    planet) and gearbox 2's 1:1 gear ``r``."""
    R = mechanism.R
    return [R, R * mechanism.i12, R * mechanism.i13, R, mechanism.r]


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
