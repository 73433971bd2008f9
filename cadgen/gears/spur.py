"""Circular gears by their symmetry: one tooth cut by the cutter envelope, the rest turned copies.

A circular gear is the special pitch curve of the generator (:mod:`cadgen.gears.teeth`): the
same rack or shaper envelope, on an exact circle (:class:`CircleCurve`) instead of a spline
through samples. Every tooth of a circular gear is the first one turned by a multiple of the
angular pitch ``2 pi / z``, so the generator runs on one angular pitch (a wedge from the middle
of one tooth space to the middle of the next, minus the spaces that reach into it) and the
outline is that piece turned ``z`` times; the checks (undercut, root and tip thickness) are
measured on that one tooth and hold for every tooth. The general path (the whole blank minus
every space, every tooth measured) gives the same gear; ``tests/test_spur.py`` compares them.

numpy only at import; shapely inside the functions.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["CircleCurve", "circular_gear", "BLANK_POINTS", "THICKNESS_POINTS"]

#: Addendum-circle vertices per full turn, at least (the general path's blank has 4096): each
#: angular pitch gets ``ceil(BLANK_POINTS / z)`` chords of the tip circle.
BLANK_POINTS = 4096
#: Samples per full turn of the offset circles the tooth thickness is measured along (as the
#: general path's 8192).
THICKNESS_POINTS = 8192
#: Tooth spaces either side of space 0 whose cuts can reach into the wedge round it: a rack's
#: space reaches half a pitch past its centre, a shaper's secondary cuts (its neighbouring
#: teeth, rolled a pitch either way) two and a half pitches.
_RACK_REACH, _SHAPER_REACH = 1, 3


class CircleCurve:
    """A circle of ``radius`` parametrized by arc length, counter-clockwise: the interface of
    :class:`kinematics.arclength.ArcLengthCurve`, exact.

    Parameters
    ----------
    radius : float
        mm, > 0.
    start : float
        rad, polar angle (body frame) of the point at arc length 0.
    rate : float
        ``d psi / d tau`` of the contact's polar angle in the source parameter ``tau`` (1 for a
        drive turning once per cycle, ``-ratio`` for its mate): :meth:`arc_of_source` is then
        ``radius * rate * tau``, the arc length from the contact at ``tau = 0``.
    """

    def __init__(self, radius: float, start: float = 0.0, rate: float = 1.0):
        radius, start, rate = float(radius), float(start), float(rate)
        if not (math.isfinite(radius) and radius > 0):
            raise ValueError(f"a circle's radius must be a finite number > 0 mm, got {radius!r}")
        if not (math.isfinite(start) and math.isfinite(rate) and rate != 0):
            raise ValueError(f"start and rate must be finite (rate not 0), got {start!r}, {rate!r}")
        self.radius, self.start, self.rate = radius, start, rate
        self.length = 2 * math.pi * radius
        self.reversed = rate < 0   # the source turns clockwise (as ArcLengthCurve says)

    def __repr__(self) -> str:
        return f"CircleCurve(radius={self.radius!r}, start={self.start!r}, rate={self.rate!r})"

    def __eq__(self, other) -> bool:
        return (isinstance(other, CircleCurve)
                and (self.radius, self.start, self.rate) == (other.radius, other.start, other.rate))

    def __hash__(self) -> int:
        return hash((self.radius, self.start, self.rate))

    def _angle(self, s):
        return self.start + np.mod(np.asarray(s, dtype=float), self.length) / self.radius

    def arc_of_source(self, tau):
        """Arc length of the contact at source parameter ``tau``."""
        return np.mod(self.radius * self.rate * np.asarray(tau, dtype=float), self.length)

    def point(self, s):
        """``P(s)``, shape ``s.shape + (2,)``."""
        angle = self._angle(s)
        return self.radius * np.stack([np.cos(angle), np.sin(angle)], axis=-1)

    def frame(self, s):
        """``(P, t, n)`` at ``s``: point, unit tangent, outward unit normal."""
        angle = self._angle(s)
        outward = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
        tangent = np.stack([-outward[..., 1], outward[..., 0]], axis=-1)
        return self.radius * outward, tangent, outward

    def curvature(self, s):
        """``1 / radius`` everywhere (convex)."""
        return np.full(np.shape(s), 1.0 / self.radius)

    def polyline(self, count: int = 2048):
        return self.point(np.arange(count) * (self.length / count))


def _turn(points, angle: float):
    """``points`` (n, 2) turned counter-clockwise by ``angle`` about the origin."""
    c, s = math.cos(angle), math.sin(angle)
    return np.asarray(points, dtype=float) @ np.array([[c, s], [-s, c]])


def _arc(radius: float, start: float, stop: float, chords: int) -> np.ndarray:
    angle = np.linspace(start, stop, chords + 1)
    return radius * np.column_stack([np.cos(angle), np.sin(angle)])


def _space_polygons(curve, system, phase, cutters, indices, outline):
    """The tooth spaces ``indices`` (relative to tooth 0) as polygons closed outside the blank,
    as :func:`cadgen.gears.teeth.gear_outline` closes them; and space 0's envelope."""
    import shapely

    from cadgen.gears.teeth import rack_space_boundary, shaper_space_boundary

    pitch, polygons, first = system.pitch, [], None
    for k in indices:
        centre = phase + (k + 0.5) * pitch
        cutter = cutters[k % len(cutters)]
        if cutter.kind == "rack":
            boundary = rack_space_boundary(curve, centre, system, **outline)
        else:
            teeth_c = int(round(2 * cutter.pitch_radius / system.module))
            boundary = shaper_space_boundary(curve, centre, system, teeth_c, **outline)
        if k == 0:
            first = boundary
        p, _, n = curve.frame(np.array([centre - pitch / 2, centre, centre + pitch / 2]))
        ring = np.vstack([boundary, (p + 3.0 * system.module * n)[::-1]])
        polygons.append(shapely.make_valid(shapely.Polygon(ring)))
    return polygons, first


def _tooth_piece(curve, teeth, system, phase, cutters, outline):
    """One angular pitch of the gear as a polygon: the wedge from the middle of tooth 0 to the
    middle of tooth 1, out to the addendum circle, minus every cut reaching into it (space 0
    whole, half of each tooth); and space 0's envelope, and the wedge's first angle.

    The wedge's sides run through the teeth's tips, where the addendum circle's vertices
    are: the piece's outline starts and ends on a vertex of the blank, so the turned copies
    join vertex to vertex with nothing but the generator's points in between.
    """
    import shapely

    from cadgen.gears.teeth import _secondary_shaper_cuts

    pitch = 2 * math.pi / teeth
    middle = curve.start + phase / curve.radius
    chords = math.ceil(BLANK_POINTS / teeth)
    tip = curve.radius + system.tip_height
    wedge = shapely.Polygon(np.vstack([[0.0, 0.0], _arc(tip, middle, middle + pitch, chords)]))
    shaped = any(c.kind == "shaper" for c in cutters)
    reach = _SHAPER_REACH if shaped else _RACK_REACH
    indices = [0] + [k for k in range(-reach, reach + 1) if k != 0]
    polygons, space = _space_polygons(curve, system, phase, cutters, indices, outline)
    if shaped:
        polygons += _secondary_shaper_cuts(curve, system, phase, indices, _cyclic(cutters),
                                           outline.get("secondary_positions", 8))
    piece = shapely.make_valid(wedge.difference(shapely.make_valid(shapely.union_all(polygons))))
    parts = [g for g in getattr(piece, "geoms", [piece]) if g.geom_type == "Polygon"]
    body = [g for g in parts if g.intersects(shapely.Point(0.0, 0.0))]
    if not body:
        raise ValueError("the tooth spaces leave no gear body")
    return body[0], space, middle


class _cyclic(list):
    """Cutters indexed modulo the tooth count (the wedge's neighbours have negative indices)."""

    def __getitem__(self, index):
        return list.__getitem__(self, index % len(self))


def _chain(piece) -> np.ndarray:
    """The pitch's stretch of outline: the piece's ring without the wedge's centre, from the
    tip on the wedge's first side up to (not including) the tip on its second side."""
    import shapely

    ring = np.asarray(piece.exterior.coords)[:-1]
    if not shapely.LinearRing(ring).is_ccw:
        ring = ring[::-1]
    centre = int(np.argmin(np.hypot(ring[:, 0], ring[:, 1])))
    if np.any(ring[centre] != 0.0):   # overlays keep input vertices exactly
        raise ValueError("the tooth piece does not reach the gear's centre")
    # counter-clockwise from the centre: out along the first side to tooth 0's tip, round
    # space 0, back from tooth 1's tip (the next piece's first point, turned)
    return np.roll(ring, -centre, axis=0)[1:-1]


def circular_gear(name, curve: CircleCurve, teeth: int, system, phase: float, *,
                  force_shaper: bool = False, bore_radius: float = 0.0, flank_points: int = 48):
    """Tooth a circular gear (rack, or a 24-tooth shaper when ``force_shaper``) and check it:
    ``(GearProfile, GearCheck, spaces)`` as :func:`cadgen.gears.pairs.generate_gear` returns.

    The generator and the checks are the general path's (:func:`cadgen.gears.teeth.gear_outline`,
    :func:`cadgen.gears.pairs._check_gear`) on one angular pitch; the rest of the gear is that
    pitch turned, so every tooth has the same findings.
    """
    import shapely

    from cadgen.gears.pairs import (MIN_TIP_THICKNESS, MIN_ROOT_THICKNESS, GearCheck,
                                    _pointed_problems, _undercut_problems)
    from cadgen.gears.teeth import CutterChoice, GearProfile

    if not isinstance(curve, CircleCurve):
        raise TypeError(f"circular_gear needs a CircleCurve, not {type(curve).__name__}")
    if not np.isclose(curve.length, teeth * system.pitch, rtol=1e-9):
        raise ValueError(f"pitch circle length {curve.length:.6f} mm does not hold {teeth} teeth "
                         f"of module {system.module:g} ({teeth * system.pitch:.6f} mm)")
    shaper_teeth = 24 if force_shaper else None   # a convex curve takes any pinion: a common size
    cutter = (CutterChoice("shaper", shaper_teeth * system.module / 2) if force_shaper
              else CutterChoice("rack"))
    cutters = [cutter] * teeth
    outline_options = dict(flank_points=flank_points, fillet_points=max(16, flank_points // 2))
    pitch = 2 * math.pi / teeth
    piece, space, middle = _tooth_piece(curve, teeth, system, phase, cutters, outline_options)
    chain = _chain(piece)
    outline = np.vstack([_turn(chain, k * pitch) for k in range(teeth)])
    spaces = [_turn(space, k * pitch) for k in range(teeth)]
    profile = GearProfile(name, outline, curve.polyline(2048), teeth, system.module, bore_radius)

    # checks on tooth 0, the general path's definitions (cadgen.gears.pairs._check_gear)
    tight = cutter.kind == "rack" and 1.0 / curve.radius > 1.0 / system.undercut_radius
    pitch_disc = shapely.Polygon(curve.polyline(4096))
    looped = not _simple_clip(shapely.LineString(space).intersection(pitch_disc))
    undercut = list(range(teeth)) if (tight or looped) else []
    root = min(_width(piece, curve.radius + h, middle, pitch) for h in system.root_heights)
    tip = _width(piece, curve.radius + system.tip_height - 1e-4 * system.module, middle, pitch)
    pointed = list(range(teeth)) if not tip > MIN_TIP_THICKNESS * system.module else []
    limit = MIN_ROOT_THICKNESS * system.module
    problems = _undercut_problems(name, undercut, [root] * teeth, limit, system)
    problems += _pointed_problems(name, pointed, tip, system)
    check = GearCheck(
        convex=True, concave_teeth=[], curvature_min=1.0 / curve.radius, cutter=cutter.kind,
        shaper_teeth=shaper_teeth, undercut_teeth=undercut, root_thickness_min=float(root),
        pointed_teeth=pointed, tip_thickness_min=float(tip),
        # the radius is the circle's normal everywhere: the pressure angle never deviates
        pressure_angle_deviation_max_deg=0.0, problems=problems,
        undercut_root_thickness_min=float(root) if undercut else None,
        root_thickness_limit=limit, profile_shift=float(system.profile_shift),
        convex_radius_min=float(curve.radius))
    return profile, check, spaces


def _simple_clip(geometry) -> bool:
    return geometry.is_empty or geometry.is_simple


def _width(piece, radius: float, middle: float, pitch: float) -> float:
    """A tooth's width along the circle of ``radius`` (mm), as the general path measures it:
    along the polygon of ``THICKNESS_POINTS`` chords a turn. The wedge holds the second half
    of tooth 0 and the first of tooth 1, one tooth between them."""
    import shapely

    chords = math.ceil(THICKNESS_POINTS / (2 * math.pi / pitch))
    arc = shapely.LineString(_arc(radius, middle, middle + pitch, chords))
    inside = piece.intersection(arc)
    pieces = [g for g in getattr(inside, "geoms", [inside]) if not g.is_empty and g.length > 0]
    return float(sum(g.length for g in pieces))
