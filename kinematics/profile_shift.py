"""Profile shift (addendum modification) of cut teeth: the closed forms the checks and advice use.

A gear cut with a shift ``x`` (dimensionless, times the module ``m``; positive away from
the gear's centre) has its cutter's reference line ``x m`` outside the pitch curve: the
rack's teeth are offset outward by ``x m`` while the rack still rolls on the pitch curve.
For a circular gear of pitch radius ``r`` this is the textbook shifted spur gear:

* tooth thickness on the pitch circle ``s = m (pi/2 + 2 x tan(alpha))``;
* tip radius ``r + (ha* + x) m``, root radius ``r - (hf* - x) m``;
* undercut-free from ``z = 2 (ha* - x) / sin^2(alpha)`` teeth, i.e. a rack cuts a radius
  of curvature down to ``m (ha* - x) / sin^2(alpha)`` without undercut.

A non-circular gear is, tooth by tooth, the spur gear of its osculating circle: the same
forms hold with ``r`` the local radius of curvature of the pitch curve (so the tightest
convex stretch, radius ``rho_min``, decides undercut and pointed tips). Two gears in mesh
keep their pitch curves and centre distance when their shifts sum to zero ("V-zero"),
which is what this project offers: a non-circular pair's centre distance cannot move.

Also here, because the kinematic findings (which never import ``cadgen``) and the tooth
cutter (``cadgen.gears``) give the same advice: the pinion (shaper) cutter's sizes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["PROFILE_SHIFT_RANGE", "MIN_TIP_THICKNESS", "MIN_SHAPER_TEETH", "MAX_SHAPER_TEETH",
           "SHAPER_CLEARANCE", "MIN_PRACTICAL_MODULE", "SHIFT_STEP", "ShiftedGear",
           "undercut_radius", "undercut_free_shift", "undercut_free_module", "tip_thickness",
           "largest_unpointed_shift", "largest_unpointed_module", "shaper_teeth",
           "suggested_shift", "shift_verdict", "shift_key",
           "ModuleSetting", "undercut_advice", "concave_advice", "shift_setting"]

#: The shifts a file may give (coefficients of the module): at -0.5 a rack undercuts every
#: gear of fewer than 26 teeth (2 (ha* - x) / sin^2(alpha) = 25.6), and at 0.8 a 17-tooth
#: gear's tip is 0.22 m thick, pointed by the 0.25 m rule; beyond them lie no useful designs.
PROFILE_SHIFT_RANGE = (-0.5, 0.8)
#: A tooth whose tip is thinner than this many modules is pointed.
MIN_TIP_THICKNESS = 0.25
#: The smallest pinion cutter considered (fewer teeth would undercut itself).
MIN_SHAPER_TEETH = 10
#: The largest pinion cutter the cutter choice takes (a common catalogue size, 40 teeth):
#: any larger radius gains nothing on a stretch this one fits.
MAX_SHAPER_TEETH = 40
#: A shaper's pitch radius is kept below this fraction of the tightest concave radius it cuts.
SHAPER_CLEARANCE = 0.9
#: Advice never suggests a module below this (mm): finer teeth are not what a workshop cuts on
#: a planting gear, so below it the advice says to reshape the curve instead.
MIN_PRACTICAL_MODULE = 0.5
#: Suggested shifts are rounded up to this step, after a margin of half a step.
SHIFT_STEP = 0.01


def undercut_radius(module: float, pressure_angle: float, addendum: float = 1.0,
                    shift: float = 0.0):
    """Smallest radius of curvature (mm) a rack cuts without undercut: ``m (ha* - x) / sin^2(alpha)``.

    Zero or negative (no limit) once ``x >= ha*``.
    """
    return module * (addendum - shift) / np.sin(pressure_angle) ** 2


def undercut_free_shift(radius, module: float, pressure_angle: float, addendum: float = 1.0):
    """The least shift that keeps a rack-cut radius of curvature ``radius`` (mm) free of
    undercut: ``x = ha* - radius sin^2(alpha) / m`` (for a circle, ``ha* - z sin^2(alpha) / 2``)."""
    return addendum - np.asarray(radius, dtype=float) * np.sin(pressure_angle) ** 2 / module


def undercut_free_module(radius: float, pressure_angle: float, addendum: float = 1.0,
                         shift: float = 0.0) -> float:
    """The largest module (mm) at which a rack cuts a radius of curvature ``radius`` without
    undercut at ``shift``: ``radius sin^2(alpha) / (ha* - x)`` (inf once ``x >= ha*``)."""
    if shift >= addendum:
        return math.inf
    return float(radius) * math.sin(pressure_angle) ** 2 / (addendum - shift)


def _involute(angle):
    return np.tan(angle) - angle


def tip_thickness(radius, module: float, pressure_angle: float, addendum: float = 1.0,
                  shift=0.0, backlash: float = 0.0):
    """Tooth thickness (mm, arc) on the tip circle of the spur gear of pitch radius ``radius``.

    ``s_a = 2 r_a (s / (2 r) + inv(alpha) - inv(alpha_a))`` with ``s = m (pi/2 + 2 x tan
    alpha) - backlash``, ``r_a = r + (ha* + x) m`` and ``cos(alpha_a) = r cos(alpha) / r_a``;
    a straight pitch line (``radius`` inf) gives the rack's ``s - 2 (ha* + x) m tan(alpha)``.
    Negative when the flanks cross below the tip circle (the tooth is pointed). A tip inside
    the base circle (only for a few teeth and a large negative shift) counts as on it.
    """
    radius = np.asarray(radius, dtype=float)
    shift = np.asarray(shift, dtype=float)
    tan = np.tan(pressure_angle)
    pitch_thickness = module * (np.pi / 2 + 2 * shift * tan) - backlash
    tip = addendum + shift
    finite = np.isfinite(radius)
    safe = np.where(finite, radius, 1.0)
    tip_radius = safe + tip * module
    cos_tip = np.clip(safe * np.cos(pressure_angle) / tip_radius, -1.0, 1.0)
    curved = 2 * tip_radius * (pitch_thickness / (2 * safe) + _involute(pressure_angle)
                               - _involute(np.arccos(cos_tip)))
    straight = pitch_thickness - 2 * tip * module * tan
    out = np.where(finite, curved, straight)
    return float(out) if out.ndim == 0 else out


def largest_unpointed_shift(radius: float, module: float, pressure_angle: float,
                            addendum: float = 1.0, *, backlash: float = 0.0,
                            min_tip: float = MIN_TIP_THICKNESS, upper: float = 2.0) -> float:
    """The largest shift at which the spur gear of pitch radius ``radius`` keeps a tip
    ``min_tip`` modules thick (``upper`` if every shift up to it does; ``-inf`` if none from
    ``-addendum`` does). The tip thins as the shift grows."""
    from .scalar import brentq

    def margin(x):
        return tip_thickness(radius, module, pressure_angle, addendum, x, backlash) \
            - min_tip * module

    low = -addendum + 1e-6
    if margin(upper) >= 0:
        return upper
    if margin(low) < 0:
        return -math.inf
    return brentq(margin, low, upper, xtol=1e-9)


def largest_unpointed_module(radius: float, pressure_angle: float, addendum: float,
                             shift: float, module: float) -> float:
    """The largest module (up to ``module``) at which the spur gear of pitch radius
    ``radius`` keeps a tip of ``MIN_TIP_THICKNESS`` modules (more teeth on the same curve
    make the tip relatively thicker)."""
    from kinematics.scalar import brentq

    def margin(m):
        return tip_thickness(radius, m, pressure_angle, addendum, shift) - MIN_TIP_THICKNESS * m

    if margin(module) >= 0:
        return module
    low = module * 1e-3
    if margin(low) < 0:
        return 0.0
    return brentq(margin, low, module, xtol=1e-9)


def shaper_teeth(concave_radius: float, module: float) -> int:
    """Teeth of the pinion cutter the cutter choice takes for a concave stretch of radius
    ``concave_radius`` (mm): the most whose pitch radius stays below ``SHAPER_CLEARANCE`` of
    it, at most ``MAX_SHAPER_TEETH`` (a nearly straight stretch takes any cutter). Fewer than
    ``MIN_SHAPER_TEETH`` means none fits."""
    if not concave_radius < math.inf:
        return MAX_SHAPER_TEETH
    return int(min(math.floor(2 * SHAPER_CLEARANCE * concave_radius / module), MAX_SHAPER_TEETH))


def suggested_shift(needed: float) -> float:
    """``needed`` with half a :data:`SHIFT_STEP` of margin, rounded up to the step: what a
    file should say (a value at the limit is as undercut as the checks' sampling makes it)."""
    steps = math.ceil(round((needed + SHIFT_STEP / 2) / SHIFT_STEP, 9))
    return round(steps * SHIFT_STEP, 10)


def shift_key(name: str) -> str:
    """A gear's key in ``gears.profile_shift``: its name with spaces and hyphens as ``_``
    (``"intermediate 1"`` -> ``intermediate_1``, ``"train-1 planet"`` -> ``train_1_planet``)."""
    return name.replace(" ", "_").replace("-", "_")


@dataclass(frozen=True)
class ShiftedGear:
    """One gear as the shift advice sees it (lengths mm).

    Attributes
    ----------
    name : str
        As the reports name it (its key is :func:`shift_key` of it).
    radius : float
        Its smallest convex radius of curvature (a circle's radius): where a rack undercuts
        first and the tip is thinnest.
    module : float
    shift : float
        The shift it is cut with now.
    sign : int
        +1 for the gear advised, -1 for a mate in mesh with it (V-zero: the opposite shift),
        +1 for the mate's own mate, and so on along a chain of meshes.
    backlash : float
        mm taken off its teeth (thins the tip too).
    shaped : bool
        Some of its teeth are cut by a pinion cutter (near concave stretches): the rack's
        closed forms do not speak for those.
    """

    name: str
    radius: float
    module: float
    shift: float = 0.0
    sign: int = 1
    backlash: float = 0.0
    shaped: bool = False

    @property
    def key(self) -> str:
        return shift_key(self.name)


def _trouble(gear: ShiftedGear, shift: float, pressure_angle: float, addendum: float,
             itself: bool = False):
    """Why ``gear`` cannot take ``shift`` (a phrase), or None; ``itself``: the gear advised."""
    low, high = PROFILE_SHIFT_RANGE
    if not low - 1e-12 <= shift <= high + 1e-12:
        if itself:
            return f"that is beyond the range a file may give, {low:g} to {high:g}"
        return f"{gear.name} would then take {shift:+.2f}, outside {low:g} to {high:g}"
    needed = float(undercut_free_shift(gear.radius, gear.module, pressure_angle, addendum))
    if shift < needed - 1e-12:
        return (f"{gear.name} would then be undercut at {shift:+.2f} (its radius of curvature "
                f"{gear.radius:.2f} mm needs at least {needed:+.2f})")
    tip = tip_thickness(gear.radius, gear.module, pressure_angle, addendum, shift, gear.backlash)
    if shift > 0 and tip < MIN_TIP_THICKNESS * gear.module:
        thickness = (f"its tip {tip:.2f} mm thick" if tip > 0 else
                     "its flanks crossing below the tip")
        return (f"{gear.name}'s teeth would then be pointed at {shift:+.2f} ({thickness} where its "
                f"radius of curvature is {gear.radius:.2f} mm; at least {MIN_TIP_THICKNESS:g} m "
                "is needed)")
    return None


def shift_verdict(gear: ShiftedGear, linked=(), *, pressure_angle: float,
                  addendum: float = 1.0) -> tuple:
    """The shift that ends ``gear``'s undercut, and whether the file can take it.

    ``linked`` are the gears whose shifts follow from ``gear``'s (its mates in V-zero
    meshes, ``sign`` -1, and theirs). Returns ``(value, reason)``: the value to set (the
    least undercut-free shift, :func:`suggested_shift`) and None when the gear and every
    linked gear stay within :data:`PROFILE_SHIFT_RANGE`, free of undercut and unpointed
    there; else the reason it cannot be set (a phrase). ``value`` is None when the gear is
    not undercut by the closed form at its present shift.
    """
    needed = float(undercut_free_shift(gear.radius, gear.module, pressure_angle, addendum))
    if needed <= gear.shift:
        return None, None
    value = suggested_shift(needed)
    for other in (gear, *linked):
        reason = _trouble(other, other.sign * value, pressure_angle, addendum, other is gear)
        if reason is not None:
            return value, reason
    return value, None


# ----------------------------------------------------------------------------------------------
# Advice in the file's terms


@dataclass(frozen=True)
class ModuleSetting:
    """How one gear's module is set in the parameter file.

    Attributes
    ----------
    path : str
        ``"pitch_curve.teeth"`` (the module is the perimeter over pi z), ``"gears.module"`` or
        ``"gears.circular_module"``.
    module : float
        mm, as cut.
    perimeter : float
        mm, the pitch perimeter (for a tooth count).
    """

    path: str
    module: float
    perimeter: float = math.nan

    def text(self, largest: float, what: str) -> str:
        """The setting that gives a module of at most ``largest`` mm, for ``what``; or that no
        practical module does."""
        if not largest >= MIN_PRACTICAL_MODULE:
            return (f"no practical module {what} (it would take one below {largest:.3g} mm, "
                    f"under {MIN_PRACTICAL_MODULE:g} mm)")
        shown = math.floor(largest * 100) / 100
        if self.path == "pitch_curve.teeth":
            teeth = math.ceil(self.perimeter / (math.pi * largest) - 1e-9)
            return (f"pitch_curve.teeth = {teeth} or more (module "
                    f"{self.perimeter / (math.pi * teeth):.3f} mm) {what}")
        if self.path == "gears.circular_module":
            return (f"a gears.circular_module of {shown:g} mm or less that divides every circular "
                    f"gear's pitch diameter {what}")
        return f"{self.path} = {shown:g} or less {what}"


def shift_setting(gear: ShiftedGear, linked, value: float, given=None) -> tuple:
    """``(key, value)`` to write for ``gear`` to take ``value``: its own key, or, when the file
    already gives the shift of a gear ``linked`` to it (``given``: keys), that key with the
    value it must take (one shift per chain of meshes; the others follow)."""
    for other in (gear, *linked):
        if given is not None and other.key in given:
            return other.key, other.sign * value
    return gear.key, value


def undercut_advice(gear: ShiftedGear, linked=(), *, pressure_angle: float,
                    addendum: float = 1.0, setting: ModuleSetting | None = None,
                    pinion_teeth=(), given=None) -> str:
    """What avoids ``gear``'s undercut, as a clause to append to the finding (``"; ..."``).

    The profile shift of :func:`shift_verdict` as ``set gears.profile_shift.<key> = x`` when
    the gear and the ``linked`` ones can take it, else why no shift avoids it; then the
    module (``setting``) at which a rack cuts it without undercut at its present shift. The
    closed forms are the rack's: ``pinion_teeth`` (the undercut teeth a pinion cutter cut)
    and the linked gears' pinion-cut teeth are judged where they are cut, and the clause
    says so. ``given``: the keys the file gives a shift for (:func:`shift_setting`).
    """
    value, reason = shift_verdict(gear, linked, pressure_angle=pressure_angle, addendum=addendum)
    pinion = ("; the pinion cutter's undercut teeth (" + ", ".join(str(k) for k in pinion_teeth)
              + ") are judged on the cut, not by the rack's limit") if len(pinion_teeth) else ""
    if value is None:
        text = (f"; a rack cuts its tightest convex stretch (radius of curvature "
                f"{gear.radius:.2f} mm) without undercut at this shift ({gear.shift:+.2f}): the "
                "undercut teeth are the pinion cutter's, near its concave stretches")
        if gear.shift < 0:
            text += " (a shift nearer 0 lessens them)"
        return text
    name, setting_value = shift_setting(gear, linked, value, given)
    key = f"gears.profile_shift.{name}"
    if reason is None:
        text = (f"; set {key} = {setting_value:.2f} to avoid it"
                + (f" (the {gear.name} gear then takes {value:+.2f})" if name != gear.key else "")
                + f": the least shift (to {SHIFT_STEP:g}) at which a rack cuts its tightest "
                  f"convex stretch (radius of curvature {gear.radius:.2f} mm) without undercut, "
                  "m (ha* - x) / sin^2(alpha) at most that radius")
        if linked:
            mates = ", ".join(f"{other.name} {other.sign * value:+.2f}" for other in linked)
            shaped = [other.name for other in linked if other.shaped]
            text += (f"; the gears in mesh take the shifts that follow (V-zero): {mates}, "
                     "still clear of the rack's undercut limit and of pointed teeth")
            if shaped:
                text += (f" ({', '.join(shaped)}: its pinion-cut teeth, near its concave "
                         "stretches, are judged when cut)")
    else:
        need = (f"{key} would have to be at least {value:+.2f}" if name == gear.key else
                f"its shift would have to be at least {value:+.2f} ({key} = "
                f"{setting_value:+.2f})")
        text = (f"; no profile shift avoids it: {need} (the rack's limit at its tightest convex "
                f"radius of curvature, {gear.radius:.2f} mm), but {reason}")
    if setting is not None:
        largest = undercut_free_module(gear.radius, pressure_angle, addendum, gear.shift)
        text += "; or " + setting.text(largest, "lets a rack cut it without undercut at this "
                                                "shift")
    return text + pinion


def concave_advice(concave_radius: float, module: float, *,
                   setting: ModuleSetting | None = None) -> tuple:
    """What cuts a concave stretch of ``concave_radius`` mm: ``(clause, fits)``, the clause to
    append to the finding (``"; ..."``) and what fits: ``"cutter"`` (a pinion cutter fits at
    ``module``), ``"module"`` (one fits at a practical smaller module) or ``"none"``.

    The clause names the pinion cutter the cutter choice takes there (a nearly straight
    stretch takes the largest, :data:`MAX_SHAPER_TEETH`), or, when none of
    :data:`MIN_SHAPER_TEETH` teeth fits, the module from which one does (``setting``).
    """
    teeth = shaper_teeth(concave_radius, module)
    if teeth >= MAX_SHAPER_TEETH:
        return (f"; any pinion cutter fits it: gears.cutter = \"auto\" (the default) cuts "
                f"those teeth with a {teeth}-tooth pinion (shaper) cutter"), "cutter"
    if teeth >= MIN_SHAPER_TEETH:
        return (f"; gears.cutter = \"auto\" (the default) cuts those teeth with a {teeth}-tooth "
                f"pinion (shaper) cutter, pitch radius {teeth * module / 2:.1f} mm, the largest "
                f"below {SHAPER_CLEARANCE:g} of its tightest concave radius "
                f"({concave_radius:.1f} mm)"), "cutter"
    largest = 2 * SHAPER_CLEARANCE * concave_radius / MIN_SHAPER_TEETH
    text = (f"; no pinion cutter of at least {MIN_SHAPER_TEETH} teeth fits its tightest concave "
            f"radius ({concave_radius:.2f} mm) at module {module:.3f} mm")
    if setting is not None:
        text += "; " + setting.text(largest, f"fits a {MIN_SHAPER_TEETH}-tooth one")
    return text, ("module" if setting is not None and largest >= MIN_PRACTICAL_MODULE
                  else "none")
