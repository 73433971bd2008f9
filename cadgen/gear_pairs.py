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

from dataclasses import dataclass, field

import numpy as np

from kinematics.arclength import ArcLengthCurve

from .gear_profile import GearProfile
from .teeth import CutterChoice, ToothSystem, gear_outline

__all__ = ["PitchPair", "GearCheck", "GeneratedPair", "generate_pair", "MIN_SHAPER_TEETH"]

#: The smallest pinion cutter considered (fewer teeth would undercut itself).
MIN_SHAPER_TEETH = 10
#: A shaper's pitch radius is kept below this fraction of the tightest concave radius it cuts.
SHAPER_CLEARANCE = 0.9
#: A tooth whose tip is thinner than this many modules is pointed.
MIN_TIP_THICKNESS = 0.25


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

    def rotations(self, tau):
        """Body rotations (drive, driven) in rad that put the contact on the x axis."""
        tau = np.asarray(tau, dtype=float)
        return -self.drive(tau)[2], np.pi - self.driven(tau)[2]

    def curve(self, which: int, samples: int = 4096) -> ArcLengthCurve:
        functions = self.drive if which == 0 else self.driven

        def position(tau):
            rho, _, psi, _ = functions(tau)
            return rho[..., None] * np.stack([np.cos(psi), np.sin(psi)], axis=-1)

        def velocity(tau):
            rho, drho, psi, dpsi = functions(tau)
            u = np.stack([np.cos(psi), np.sin(psi)], axis=-1)
            perp = np.stack([-u[..., 1], u[..., 0]], axis=-1)
            return drho[..., None] * u + (rho * dpsi)[..., None] * perp

        breaks = np.asarray(self.breaks) if len(self.breaks) else None
        return ArcLengthCurve.from_parametric(position, velocity, self.period, breaks=breaks,
                                              samples=samples)


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


@dataclass(frozen=True)
class GeneratedPair:
    pair: PitchPair
    curves: tuple
    system: ToothSystem
    teeth: int
    profiles: tuple
    checks: tuple
    phases: tuple
    spaces: tuple = ()


def _choose_cutters(curve: ArcLengthCurve, teeth: int, system: ToothSystem, phase: float,
                    force_shaper: bool):
    """Rack where the pitch curve is convex round a space, a shaper where it is concave."""
    pitch = system.pitch
    s = np.linspace(0.0, curve.length, 64 * teeth, endpoint=False)
    curvature = curve.curvature(s)
    concave_min = float(curvature.min())
    shaper_teeth = None
    if concave_min < 0 or force_shaper:
        tightest = 1.0 / -concave_min if concave_min < 0 else np.inf
        largest = int(np.floor(2 * SHAPER_CLEARANCE * tightest / system.module))
        shaper_teeth = min(largest, 40) if np.isfinite(tightest) else 24
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


def _tooth_thickness(curve: ArcLengthCurve, gear, teeth: int, pitch: float, phase: float,
                     height: float, samples: int = 8192):
    """Width of every tooth along the pitch curve's offset at ``height`` (mm; 0 where it has none).

    Measured on the finished outline: the offset curve is cut by the gear
    polygon into one piece per tooth, so undercut and pointed teeth need no
    special case.
    """
    import shapely

    s = np.arange(samples) * (curve.length / samples)
    point, _, outward = curve.frame(s)
    offset = shapely.LinearRing(point + height * outward)
    pieces = gear.intersection(offset)
    width = np.zeros(teeth)
    for piece in getattr(pieces, "geoms", [pieces]):
        if piece.is_empty or piece.length == 0.0:
            continue
        middle = np.asarray(piece.interpolate(0.5, normalized=True).coords)[0]
        nearest = s[np.argmin(np.linalg.norm(point + height * outward - middle, axis=1))]
        k = int(np.round((nearest - phase) / pitch)) % teeth
        width[k] += piece.length
    return width


def _check_gear(name, curve, teeth, system, phase, outline, spaces, concave, concave_min,
                cutters, shaper_teeth):
    import shapely

    problems = []
    gear = shapely.Polygon(outline)
    s = np.arange(4096) * (curve.length / 4096)
    point, _, outward = curve.frame(s)
    blank = shapely.Polygon(point + (system.addendum_height - 1e-6) * outward)
    # an envelope that loops inside the blank: the cutter's tip has cut into the flank
    undercut = [k for k, boundary in enumerate(spaces)
                if not _simple(shapely.LineString(boundary).intersection(blank))]
    root = _tooth_thickness(curve, gear, teeth, system.pitch, phase, -0.25 * system.module)
    tip = _tooth_thickness(curve, gear, teeth, system.pitch, phase,
                           system.addendum_height - 1e-4 * system.module)
    pointed = [k for k, t in enumerate(tip) if not t > MIN_TIP_THICKNESS * system.module]
    # pressure-angle deviation: angle between the radius and the pitch curve's normal
    radial = point / np.linalg.norm(point, axis=1, keepdims=True)
    deviation = float(np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", radial, outward)),
                                                   0, 1))).max())
    if concave and shaper_teeth is not None and shaper_teeth < MIN_SHAPER_TEETH:
        problems.append(("concave_too_tight",
                         f"the {name} gear's pitch curve is concave down to a radius of "
                         f"{1 / -concave_min:.2f} mm (teeth {_list(concave)}): no pinion cutter "
                         f"of at least {MIN_SHAPER_TEETH} teeth fits (module {system.module:.3f}); "
                         "use a smaller module (more teeth) or a rounder pitch curve"))
    if undercut:
        problems.append(("undercut", f"the {name} gear's teeth {_list(undercut)} are undercut; "
                         f"remaining root thickness down to {root[undercut].min():.3f} mm: use a "
                         "smaller module (more teeth), a profile shift, or a shaper cutter"))
    if pointed:
        problems.append(("pointed_teeth", f"the {name} gear's teeth {_list(pointed)} are pointed "
                         f"(tip thickness down to {tip.min():.3f} mm, below "
                         f"{MIN_TIP_THICKNESS:g} m): use fewer teeth (a larger module) or a "
                         "smaller addendum"))
    kinds = {c.kind for c in cutters}
    return GearCheck(
        convex=not concave, concave_teeth=concave, curvature_min=concave_min,
        cutter=" and ".join(sorted(kinds)), shaper_teeth=shaper_teeth if "shaper" in kinds else None,
        undercut_teeth=undercut, root_thickness_min=float(root.min()), pointed_teeth=pointed,
        tip_thickness_min=float(tip.min()), pressure_angle_deviation_max_deg=deviation,
        problems=problems)


def _simple(geometry) -> bool:
    """True when the clipped envelope crosses neither itself nor its other pieces."""
    return geometry.is_empty or geometry.is_simple


def _list(indices, limit=8):
    shown = ", ".join(str(k) for k in indices[:limit])
    return shown + (f" and {len(indices) - limit} more" if len(indices) > limit else "")


def generate_pair(pair: PitchPair, teeth: int, *, module: float | None = None,
                  system: ToothSystem | None = None, force_shaper: bool = False,
                  bore_radius: float = 0.0, flank_points: int = 48) -> GeneratedPair:
    """Tooth both gears of a pair, phased to assemble at ``tau = 0``, with their checks.

    The module follows from the perimeter (``P / (pi z)``) unless a tooth
    system is given, whose module must then fit the perimeter.
    """
    curves = (pair.curve(0), pair.curve(1))
    if system is None:
        system = ToothSystem(module if module is not None else curves[0].length / (np.pi * teeth))
    start = (float(curves[0].arc_of_source(np.array([0.0]))[0]),
             float(curves[1].arc_of_source(np.array([0.0]))[0]))
    # drive: a tooth centred on the start contact; driven: a space there
    phases = (start[0], start[1] - system.pitch / 2)
    profiles, checks, all_spaces = [], [], []
    for index, (name, curve, phase) in enumerate(zip(pair.names, curves, phases)):
        cutters, concave, concave_min, shaper_teeth = _choose_cutters(curve, teeth, system, phase,
                                                                      force_shaper)
        if shaper_teeth is not None and shaper_teeth < MIN_SHAPER_TEETH:
            cutters = [CutterChoice("rack")] * teeth  # none fits: show the rack's result
        outline, spaces = gear_outline(curve, teeth, system, phase=phase, cutters=cutters,
                                       flank_points=flank_points)
        profiles.append(GearProfile(name, outline, curve.polyline(2048), teeth, system.module,
                                    bore_radius))
        checks.append(_check_gear(name, curve, teeth, system, phase, outline, spaces, concave,
                                  concave_min, cutters, shaper_teeth))
        all_spaces.append(spaces)
    return GeneratedPair(pair, curves, system, teeth, tuple(profiles), tuple(checks), phases,
                         tuple(all_spaces))
