"""Non-circular gear pairs: pitch curves, phasing at the start position, cutter choice, checks.

A pair is given by its contact functions along a common parameter ``tau``: the
drive's and the driven gear's pitch radius at the contact and the polar angle of
the contact point in each gear's own frame. The drive sits at the origin, the
driven gear at ``(a, 0)``, and at ``tau`` they are turned so that the contact
lies on the x axis: ``theta_drive = -psi_drive``, ``theta_driven = pi - psi_driven``.
At ``tau = 0`` (the mechanism's start position) the drive has a tooth centred on
the contact and the driven gear a space: the pair assembles there, and each
stage of a train is phased at its own start contact, so the train's phases agree.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

import shapely.errors

from kinematics.errors import DesignError
from kinematics.profile_shift import (MIN_SHAPER_TEETH, MIN_TIP_THICKNESS, SHAPER_CLEARANCE,
                                      shift_key, shaper_teeth as _fitting_shaper)  # noqa: F401

from cadgen.gears.teeth import GearProfile
from cadgen.gears.teeth import CutterChoice, ToothSystem, gear_outline

if TYPE_CHECKING:   # scipy's splines behind it: imported where a non-circular curve is built
    from kinematics.arclength import ArcLengthCurve

__all__ = ["PitchPair", "GearCheck", "GeneratedPair", "generate_pair", "generate_gear",
           "mating_phase", "circle_pair", "MIN_SHAPER_TEETH", "MIN_ROOT_THICKNESS",
           "FAILING_PROBLEMS"]

# MIN_SHAPER_TEETH (the smallest pinion cutter considered), SHAPER_CLEARANCE (a shaper's pitch
# radius stays below this fraction of the tightest concave radius it cuts) and MIN_TIP_THICKNESS
# (modules: a thinner tip is pointed) live in kinematics.profile_shift: the pricking findings
# give the same advice without importing cadgen.
#: The undercut policy (both mechanisms): an undercut tooth is a warning while its remaining
#: root thickness (its narrowest section between the pitch curve and the root fillet, measured
#: on the cut outline) is at least this many modules, and a failure below it. A full tooth is
#: pi/2 = 1.571 m thick there (at the pitch curve); by Lewis' bending section (root stress
#: 6 F h / (b s^2)) a tooth of 1.25 m keeps (1.25 / 1.571)^2 = 63 % of the full tooth's
#: section modulus, the bending stress rising at most 1.58 times: about what a standard 20-deg
#: spur gear loses from 17 teeth to 10 (Lewis form factors 0.303 and about 0.20), the fewest
#: teeth the usual Lewis tables list. Measured here, a circular gear cut by the standard rack
#: meets it with 8 teeth (1.30 m) and not with 7 (1.20 m).
MIN_ROOT_THICKNESS = 1.25
#: Gear-check problems that fail the design; every other one is a warning. A positive profile
#: shift whose cut teeth are pointed is refused: the file asked for it.
FAILING_PROBLEMS = frozenset({"undercut_root_too_thin", "profile_shift_pointed"})


@dataclass(frozen=True)
class PitchPair:
    """Contact functions of a closed non-circular pair over one cycle ``tau`` in [0, period).

    ``drive(tau)`` and ``driven(tau)`` return ``(rho, drho, psi, dpsi)``: pitch
    radius at the contact and polar angle of the contact in the gear's frame,
    with their ``tau``-derivatives (arrays like ``tau``).
    """

    names: tuple
    centre_distance: float
    period: float
    drive: object
    driven: object
    breaks: tuple = ()
    curve_periods: tuple = ()   # tau range in which each gear turns once (default: period)
    radii: tuple = ()           # (drive, driven) pitch radii of a pair of circular gears

    def rotations(self, tau):
        """Body rotations (drive, driven) in rad that put the contact on the x axis."""
        tau = np.asarray(tau, dtype=float)
        return -self.drive(tau)[2], np.pi - self.driven(tau)[2]

    def curve(self, which: int, samples: int = 4096):
        """Gear ``which``'s pitch curve by arc length: an exact
        :class:`~cadgen.gears.spur.CircleCurve` for a circular pair (``radii`` set), else an
        :class:`~kinematics.arclength.ArcLengthCurve` of the contact functions."""
        functions = self.drive if which == 0 else self.driven
        if self.radii:
            from cadgen.gears.spur import CircleCurve

            # the contact's polar angle is linear in tau on a circle: start and rate say it all
            _, _, psi, rate = functions(np.zeros(1))
            return CircleCurve(self.radii[which], float(psi[0]), float(rate[0]))
        from kinematics.arclength import ArcLengthCurve

        def position(tau):
            rho, _, psi, _ = functions(tau)
            return rho[..., None] * np.stack([np.cos(psi), np.sin(psi)], axis=-1)

        def velocity(tau):
            rho, drho, psi, dpsi = functions(tau)
            u = np.stack([np.cos(psi), np.sin(psi)], axis=-1)
            perp = np.stack([-u[..., 1], u[..., 0]], axis=-1)
            return drho[..., None] * u + (rho * dpsi)[..., None] * perp

        period = self.curve_periods[which] if self.curve_periods else self.period
        breaks = np.asarray(self.breaks) if len(self.breaks) else None
        return ArcLengthCurve.from_parametric(position, velocity, period, breaks=breaks,
                                              samples=samples)


def circle_pair(names, drive_radius: float, driven_radius: float) -> PitchPair:
    """Two circular gears in mesh: one turn of the drive per cycle."""
    ratio = drive_radius / driven_radius

    def drive(tau):
        tau = np.asarray(tau, dtype=float)
        return np.full_like(tau, drive_radius), np.zeros_like(tau), tau, np.ones_like(tau)

    def driven(tau):
        tau = np.asarray(tau, dtype=float)
        return (np.full_like(tau, driven_radius), np.zeros_like(tau), np.pi - ratio * tau,
                np.full_like(tau, -ratio))

    return PitchPair(tuple(names), drive_radius + driven_radius, 2 * np.pi, drive, driven,
                     curve_periods=(2 * np.pi, 2 * np.pi / ratio),
                     radii=(float(drive_radius), float(driven_radius)))


@dataclass(frozen=True)
class GearCheck:
    """Checks of one generated gear (lengths mm); each list names the teeth (0-based) affected."""

    convex: bool
    concave_teeth: list
    curvature_min: float
    cutter: str
    shaper_teeth: int | None
    undercut_teeth: list
    root_thickness_min: float
    pointed_teeth: list
    tip_thickness_min: float
    pressure_angle_deviation_max_deg: float
    problems: list = field(default_factory=list)
    undercut_root_thickness_min: float | None = None   # of the undercut teeth (None: none)
    root_thickness_limit: float = 0.0                   # MIN_ROOT_THICKNESS modules, mm
    profile_shift: float = 0.0                          # x the gear was cut with (modules)
    convex_radius_min: float = np.inf                   # smallest convex radius of curvature, mm

    @property
    def failing(self) -> list:
        """The problems that fail the design (:data:`FAILING_PROBLEMS`): (code, message)."""
        return [(code, message) for code, message in self.problems if code in FAILING_PROBLEMS]


@dataclass(frozen=True)
class GeneratedPair:
    """A pair as cut: ``system`` the pair's basic rack, ``systems`` each gear's own (the
    basic rack with that gear's profile shift)."""

    pair: PitchPair
    curves: tuple
    system: ToothSystem
    teeth: int
    profiles: tuple
    checks: tuple
    phases: tuple
    spaces: tuple = ()
    systems: tuple = ()


def _choose_cutters(curve: ArcLengthCurve, teeth: int, system: ToothSystem, phase: float,
                    force_shaper: bool):
    """Rack where the pitch curve is convex round a space, a shaper where it is concave."""
    pitch = system.pitch
    s = np.linspace(0.0, curve.length, 64 * teeth, endpoint=False)
    curvature = curve.curvature(s)
    concave_min = float(curvature.min())
    shaper_teeth = None
    if concave_min < 0:
        shaper_teeth = _fitting_shaper(1.0 / -concave_min, system.module)
    elif force_shaper:
        shaper_teeth = 24  # a convex curve takes any pinion cutter: a common size
    cutters, concave = [], []
    for k in range(teeth):
        centre = phase + (k + 0.5) * pitch
        near = np.abs(np.mod(s - centre + curve.length / 2, curve.length) - curve.length / 2) \
            <= 1.5 * pitch
        local_concave = bool((curvature[near] < 0).any())
        if local_concave:
            concave.append(k)
        if (local_concave or force_shaper) and shaper_teeth is not None:
            cutters.append(CutterChoice("shaper", shaper_teeth * system.module / 2))
        else:
            cutters.append(CutterChoice("rack"))
    return cutters, concave, concave_min, shaper_teeth


def _tooth_thickness(frame, gear, teeth: int, pitch: float, phase: float, height: float):
    """Width of every tooth along the pitch curve's offset at ``height`` (mm; 0 where it has none).

    Measured on the finished outline: the offset curve is cut by the gear
    polygon into one piece per tooth, so undercut and pointed teeth need no
    special case. ``frame`` is ``(s, point, outward)``, the pitch curve sampled
    densely by arc length (shared by every height).
    """
    import shapely

    s, point, outward = frame
    offset = point + height * outward
    pieces = gear.intersection(shapely.LinearRing(offset))
    pieces = [piece for piece in getattr(pieces, "geoms", [pieces])
              if not piece.is_empty and piece.length > 0.0]
    width = np.zeros(teeth)
    if not pieces:
        return width
    from scipy.spatial import cKDTree

    middles = shapely.get_coordinates(shapely.line_interpolate_point(pieces, 0.5, normalized=True))
    # each piece belongs to the tooth whose centre is nearest its middle along the curve
    nearest = s[cKDTree(offset).query(middles)[1]]
    index = np.round((nearest - phase) / pitch).astype(int) % teeth
    np.add.at(width, index, shapely.length(pieces))
    return width


def _check_gear(name, curve, teeth, system, phase, outline, spaces, concave, concave_min,
                cutters, shaper_teeth):
    import shapely

    problems = []
    gear = shapely.Polygon(outline)
    s = np.arange(4096) * (curve.length / 4096)
    point, _, outward = curve.frame(s)
    pitch_region = shapely.Polygon(point)
    curvature = curve.curvature(s)
    # undercut: a rack-cut tooth where the pitch curve bends tighter than m ha*/sin^2(alpha)
    # (spec), or any cutter's envelope looping in the root, below the pitch curve
    undercut = []
    for k, boundary in enumerate(spaces):
        centre = phase + (k + 0.5) * system.pitch
        near = np.abs(np.mod(s - centre + curve.length / 2, curve.length) - curve.length / 2) \
            <= system.pitch
        tight = cutters[k].kind == "rack" and bool(
            (curvature[near] > 1.0 / system.undercut_radius).any())
        looped = not _simple(shapely.LineString(boundary).intersection(pitch_region))
        if tight or looped:
            undercut.append(k)
    dense = np.arange(8192) * (curve.length / 8192)
    frame = (dense, *curve.frame(dense)[::2])
    root = np.min([_tooth_thickness(frame, gear, teeth, system.pitch, phase, h)
                   for h in system.root_heights], axis=0)
    tip = _tooth_thickness(frame, gear, teeth, system.pitch, phase,
                           system.tip_height - 1e-4 * system.module)
    pointed = [k for k, t in enumerate(tip) if not t > MIN_TIP_THICKNESS * system.module]
    # pressure-angle deviation: angle between the radius and the pitch curve's normal
    radial = point / np.linalg.norm(point, axis=1, keepdims=True)
    deviation = float(np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", radial, outward)),
                                                   0, 1))).max())
    problems += _check_problems(name, concave, concave_min, shaper_teeth, system)
    limit = MIN_ROOT_THICKNESS * system.module
    undercut_root = float(root[undercut].min()) if undercut else None
    problems += _undercut_problems(name, undercut, root, limit, system)
    problems += _pointed_problems(name, pointed, float(tip.min()), system)
    kinds = {c.kind for c in cutters}
    return GearCheck(
        convex=not concave, concave_teeth=concave, curvature_min=concave_min,
        cutter=" and ".join(sorted(kinds)), shaper_teeth=shaper_teeth if "shaper" in kinds else None,
        undercut_teeth=undercut, root_thickness_min=float(root.min()), pointed_teeth=pointed,
        tip_thickness_min=float(tip.min()), pressure_angle_deviation_max_deg=deviation,
        problems=problems, undercut_root_thickness_min=undercut_root, root_thickness_limit=limit,
        profile_shift=float(system.profile_shift),
        convex_radius_min=float(1.0 / curvature.max()) if curvature.max() > 0 else np.inf)


def _undercut_problems(name, undercut, root, limit, system) -> list:
    """The undercut finding: a warning while the undercut teeth keep ``limit`` mm of root
    thickness (``root``: per tooth), a failure below it; none without undercut teeth.

    What avoids it (a profile shift, more teeth) depends on the gear's mates and on the
    mechanism's parameters: :func:`cadgen.gears.advice.advise_train` appends it."""
    if not undercut:
        return []
    root = np.asarray(root, dtype=float)
    undercut_root = float(root[undercut].min())
    thin = [k for k in undercut if root[k] < limit]
    measured = (f"remaining root thickness down to {undercut_root:.3f} mm "
                f"({undercut_root / system.module:.3f} m)")
    if thin:
        return [("undercut_root_too_thin",
                 f"the {name} gear's teeth {_list(thin)} are undercut below the "
                 f"root-thickness limit: {measured}, under {limit:.3f} mm "
                 f"({MIN_ROOT_THICKNESS:g} m)")]
    return [("undercut", f"the {name} gear's teeth {_list(undercut)} are "
             f"undercut; {measured}, at least the {limit:.3f} mm "
             f"({MIN_ROOT_THICKNESS:g} m) limit, so a warning")]


def _pointed_problems(name, pointed, tip, system) -> list:
    """The pointed-teeth finding: a warning (``pointed_teeth``), with the means that is the
    gear system's own (``gears.addendum``), or, for a gear cut with a positive profile shift,
    a failure (``profile_shift_pointed``: the file's shift is refused where it is measured).
    :func:`cadgen.gears.advice.advise_train` adds the tooth count's and the shift's values."""
    if not pointed:
        return []
    measured = (f"the {name} gear's teeth {_list(pointed)} are pointed (tip thickness down to "
                f"{tip:.3f} mm, below {MIN_TIP_THICKNESS:g} m = "
                f"{MIN_TIP_THICKNESS * system.module:.3f} mm)")
    if system.profile_shift > 0:
        return [("profile_shift_pointed",
                 f"{measured} at the profile shift {system.profile_shift:+g} it is cut with "
                 f"(gears.profile_shift.{shift_key(name)}, given or its mate's opposite): a "
                 "smaller shift thickens them")]
    return [("pointed_teeth", f"{measured}: a smaller gears.addendum would thicken them")]


def _simple(geometry) -> bool:
    """True when the clipped envelope crosses neither itself nor its other pieces."""
    return geometry.is_empty or geometry.is_simple


def _list(indices, limit=8):
    shown = ", ".join(str(k) for k in indices[:limit])
    return shown + (f" and {len(indices) - limit} more" if len(indices) > limit else "")


def angle_at_arc(curve: ArcLengthCurve, s: float) -> float:
    """Polar angle (body frame) of the pitch-curve point at arc length ``s``."""
    point = curve.frame(np.array([s]))[0][0]
    return float(np.arctan2(point[1], point[0]))


def arc_at_angle(curve: ArcLengthCurve, angle: float, samples: int = 4096) -> float:
    """Arc length of the pitch-curve point at polar angle ``angle`` (the curve is star-shaped
    about its centre): a dense table, then Newton's method on the polar angle."""
    s = np.arange(samples) * (curve.length / samples)
    points = curve.frame(s)[0]
    polar = np.unwrap(np.arctan2(points[:, 1], points[:, 0]))
    turn = np.sign(polar[-1] - polar[0])
    target = polar[0] + np.mod(turn * (angle - polar[0]), 2 * np.pi) * turn
    guess = float(np.interp(turn * target, turn * np.append(polar, polar[0] + turn * 2 * np.pi),
                            np.append(s, curve.length)))
    for _ in range(3):
        point, tangent, _ = curve.frame(np.array([guess]))
        p, t = point[0], tangent[0]
        rate = (p[0] * t[1] - p[1] * t[0]) / (p @ p)     # d(polar angle)/ds
        error = np.angle(np.exp(1j * (np.arctan2(p[1], p[0]) - angle)))
        guess -= error / rate
    return float(np.mod(guess, curve.length))


def mating_phase(drive_curve: ArcLengthCurve, drive_phase: float, driven_curve: ArcLengthCurve,
                 pitch: float) -> float:
    """Phase of the driven gear so that it meshes with the drive at the contact of ``tau = 0``.

    With the drive's nearest tooth centre ``e`` behind the contact (along the
    drive's arc), the driven gear needs a space centre ``e`` ahead of the contact
    along its own arc (the two tangents run opposite at an external mesh).
    """
    s_drive = float(drive_curve.arc_of_source(np.array([0.0]))[0])
    s_driven = float(driven_curve.arc_of_source(np.array([0.0]))[0])
    behind = np.mod(s_drive - drive_phase, pitch)
    return float(np.mod(s_driven + behind + pitch / 2, driven_curve.length))


def _check_problems(name, concave, concave_min, shaper_teeth, system):
    if concave and shaper_teeth is not None and shaper_teeth < MIN_SHAPER_TEETH:
        return [("concave_too_tight",
                 f"the {name} gear's pitch curve is concave down to a radius of "
                 f"{1 / -concave_min:.2f} mm (teeth {_list(concave)}): no pinion cutter "
                 f"of at least {MIN_SHAPER_TEETH} teeth fits at module {system.module:.3f} mm")]
    return []


def generate_gear(name, curve: ArcLengthCurve, teeth: int, system: ToothSystem, phase: float, *,
                  force_shaper: bool = False, bore_radius: float = 0.0, flank_points: int = 48,
                  symmetric: bool = True):
    """Tooth one gear (rack on convex stretches, shaper on concave ones) and check it.

    A :class:`~cadgen.gears.spur.CircleCurve` is cut by :func:`~cadgen.gears.spur.circular_gear`
    (one tooth, turned) unless ``symmetric`` is False (every tooth, as any other curve).
    """
    if symmetric:
        from cadgen.gears.spur import CircleCurve, circular_gear

        if isinstance(curve, CircleCurve):
            try:
                return circular_gear(name, curve, teeth, system, phase,
                                     force_shaper=force_shaper, bore_radius=bore_radius,
                                     flank_points=flank_points)
            except (ValueError, shapely.errors.GEOSException) as error:
                raise DesignError.single(f"gears.{name.replace(' ', '_')}", "gear_not_cuttable",
                                         f"the {name} gear cannot be cut: the tooth spaces do "
                                         f"not form a valid outline ({error})") from None
    cutters, concave, concave_min, shaper_teeth = _choose_cutters(curve, teeth, system, phase,
                                                                  force_shaper)
    if shaper_teeth is not None and shaper_teeth < MIN_SHAPER_TEETH:
        cutters = [CutterChoice("rack")] * teeth  # none fits: show what a rack would do
    try:
        # the root fillet gets half as many points as a flank (its arc is shorter): a fixed
        # 16 left a 5e-3 mm chord error in every root (benchmarks/gears.py)
        outline, spaces = gear_outline(curve, teeth, system, phase=phase, cutters=cutters,
                                       flank_points=flank_points,
                                       fillet_points=max(16, flank_points // 2))
    except (ValueError, shapely.errors.GEOSException) as error:
        reasons = "; ".join(m for _, m in _check_problems(name, concave, concave_min,
                                                          shaper_teeth, system))
        detail = reasons or f"the tooth spaces do not form a valid outline ({error})"
        raise DesignError.single(f"gears.{name.replace(' ', '_')}", "gear_not_cuttable",
                                 f"the {name} gear cannot be cut: {detail}") from None
    profile = GearProfile(name, outline, curve.polyline(2048), teeth, system.module, bore_radius)
    check = _check_gear(name, curve, teeth, system, phase, outline, spaces, concave, concave_min,
                        cutters, shaper_teeth)
    return profile, check, spaces


def generate_pair(pair: PitchPair, teeth, *, module: float | None = None,
                  system: ToothSystem | None = None, force_shaper: bool = False,
                  bore_radius: float = 0.0, flank_points: int = 48, drive_phase=None,
                  drive_gear=None, symmetric: bool = True, shifts=None,
                  shortening=(0.0, 0.0)) -> GeneratedPair:
    """Tooth both gears of a pair, phased to assemble at ``tau = 0``, with their checks.

    ``teeth`` is one count or (drive, driven). The module follows from the
    perimeter (``P / (pi z)``) unless a tooth system is given. In a train, pass
    the drive's ``drive_phase`` and already generated ``drive_gear`` (profile,
    check, spaces) so a gear in two meshes is cut once with one phase. A circular pair
    (:func:`circle_pair`) is cut on exact circles, one tooth turned (``symmetric``, see
    :func:`generate_gear`).

    ``shifts`` (drive, driven) are the gears' profile-shift coefficients; by default the
    system's for the drive and its opposite for the driven gear. A non-circular pair's must
    sum to zero (V-zero): the pitch curves and the centre distance stay as they are, and so
    do the phases (tooth centres do not move). A circular pair's may not (a V pair, cut on
    its reference circles; the caller meshes it at its working centre distance).
    """
    teeth = (teeth, teeth) if np.isscalar(teeth) else tuple(teeth)
    curves = (pair.curve(0), pair.curve(1))
    if system is None:
        system = ToothSystem(module if module is not None else curves[0].length / (np.pi * teeth[0]))
    if shifts is None:
        shifts = (system.profile_shift, -system.profile_shift)
    shifts = tuple(float(x) for x in shifts)
    # V-zero keeps a non-circular pair's pitch curves; circular gears may take any two shifts
    # (a V pair: they mesh at another centre distance, :func:`cadgen.gears.circular.
    # working_shift_sum`), cut on their reference circles, tooth centres where they were
    if len(shifts) != 2 or (not pair.radii and not abs(shifts[0] + shifts[1]) <= 1e-12):
        raise ValueError(f"the profile shifts of a pair must sum to zero (V-zero), not {shifts}")
    # ``shortening`` (modules, each gear's): tips cut lower so a V pair keeps its clearance
    systems = tuple(dataclasses.replace(system, profile_shift=x, addendum=system.addendum - k)
                    if (x != system.profile_shift or k) else system
                    for x, k in zip(shifts, shortening))
    if drive_phase is None:  # a tooth centred on the start contact
        drive_phase = float(curves[0].arc_of_source(np.array([0.0]))[0])
    elif drive_gear is not None:
        # a gear carried from another mesh: its phase is the body angle of a tooth centre
        # (arc lengths of two meshes start at different contacts: half a turn apart on an
        # idler, which is half a pitch off for an odd tooth count)
        drive_phase = arc_at_angle(curves[0], drive_phase)
    phases = (drive_phase, mating_phase(curves[0], drive_phase, curves[1], system.pitch))
    options = dict(force_shaper=force_shaper, bore_radius=bore_radius, flank_points=flank_points,
                   symmetric=symmetric)
    first = drive_gear or generate_gear(pair.names[0], curves[0], teeth[0], systems[0],
                                        phases[0], **options)
    second = generate_gear(pair.names[1], curves[1], teeth[1], systems[1], phases[1], **options)
    return GeneratedPair(pair, curves, system, teeth, (first[0], second[0]),
                         (first[1], second[1]), phases, (first[2], second[2]), systems)
