"""Tooth profiles of non-circular (and circular) gears by cutter enveloping.

A cutter rolls without slipping on the gear's pitch curve; each tooth space is
the region the cutter tooth sweeps, and its boundary is the envelope of the
cutter tooth's outline. For every point of the cutter outline (with its normal
``nu``) the envelope condition, "the normal passes through the instantaneous
centre of rotation (the pitch point)", fixes the instant of generation:

* rack (pitch line): in rack coordinates ``(x, y)`` (x along the pitch line,
  y outward from the gear), the instant is ``s = x - y nu_x / nu_y``, and the
  generated point is ``P(s) + (x - s) t(s) + y n(s)``, closed form and
  vectorized (the flank is the involute-like envelope, the tip fillet gives the
  trochoidal root fillet, the tip flat the root curve);
* shaper (pinion cutter of pitch radius ``r_c``, for concave stretches): the
  normal line of a cutter point meets the cutter's pitch circle at the pitch
  point, a line-circle intersection, again in closed form.

Where the envelope of one tooth space loops back on itself (a swallowtail) the
cutter's tip undercuts the flank; the loop lies inside the swept region and the
union of the space's pieces is the true cut. The gear is the blank (bounded by
the addendum curve) minus the union of all tooth spaces (shapely).

A profile shift x (:attr:`ToothSystem.profile_shift`) moves the rack's outline ``x m``
outward (y) while its rolling line stays on the pitch curve, gives a shaper the shift -x,
and moves the blank's addendum curve out by ``x m``: on a circle, the textbook shifted spur
gear (``tests/test_profile_shift.py``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:   # only named in annotations: any curve with frame() and length will do
    from kinematics.arclength import ArcLengthCurve

__all__ = ["ToothSystem", "rack_tooth_outline", "rack_space_boundary", "shaper_space_boundary",
           "gear_outline", "CutterChoice", "GearProfile"]


@dataclass(frozen=True)
class ToothSystem:
    """The basic rack of the gear (lengths in mm except coefficients x module).

    Parameters
    ----------
    module : float
    pressure_angle : float
        rad (20 deg by default).
    addendum, dedendum : float
        Coefficients of the module (1.0 and 1.25).
    tip_radius : float
        Cutter tip rounding, coefficient of the module (0.38: the standard rack
        fillet); it makes the root fillet.
    backlash : float
        Circumferential backlash on the pitch curve (mm) taken off each tooth of
        this gear (a pair's backlash is the sum of its two gears').
    profile_shift : float
        Profile shift coefficient x (times the module; positive away from the gear's
        centre): the cutter's teeth stand ``x m`` further out while it rolls on the pitch
        curve, so the teeth are ``2 x m tan(alpha)`` thicker on it, the tip and the root
        ``x m`` further out, and the undercut limit is ``m (ha* - x) / sin^2(alpha)``
        (:mod:`kinematics.profile_shift`).
    """

    module: float
    pressure_angle: float = np.radians(20.0)
    addendum: float = 1.0
    dedendum: float = 1.25
    tip_radius: float = 0.38
    backlash: float = 0.0
    profile_shift: float = 0.0

    def __post_init__(self):
        shift = self.profile_shift
        checks = {"module": self.module > 0, "pressure_angle": 0 < self.pressure_angle < np.pi / 3,
                  "addendum": self.addendum > 0, "dedendum": self.dedendum > 0,
                  "tip_radius": self.tip_radius >= 0, "backlash": self.backlash >= 0,
                  # the tip stays outside the pitch curve, the root inside it
                  "profile_shift": (bool(np.isfinite(shift))
                                    and -self.addendum < shift < self.dedendum)}
        bad = [name for name, ok in checks.items() if not ok]
        if bad:
            raise ValueError(f"tooth system: {', '.join(f'{n} = {getattr(self, n)!r}' for n in bad)} "
                             "out of range")

    @property
    def pitch(self) -> float:
        return np.pi * self.module

    @property
    def addendum_height(self) -> float:
        return self.addendum * self.module

    @property
    def dedendum_depth(self) -> float:
        return self.dedendum * self.module

    @property
    def shift_height(self) -> float:
        """``x m``: how far out of the pitch curve the cutter's reference line runs (mm)."""
        return self.profile_shift * self.module

    @property
    def tip_height(self) -> float:
        """The blank's tip (addendum curve) above the pitch curve: ``(ha* + x) m``."""
        return (self.addendum + self.profile_shift) * self.module

    @property
    def root_depth(self) -> float:
        """The root below the pitch curve: ``(hf* - x) m``."""
        return (self.dedendum - self.profile_shift) * self.module

    @property
    def undercut_radius(self) -> float:
        """Smallest radius of curvature a rack cuts without undercut: ``m (ha* - x) / sin^2(alpha)``."""
        return (self.addendum - self.profile_shift) * self.module / np.sin(self.pressure_angle) ** 2

    @property
    def root_heights(self) -> np.ndarray:
        """Heights (mm, from the pitch curve) the root thickness is measured at: from the top
        of the root fillet (``-(hf* - rho_f - x) m``) up to the pitch curve, six of them."""
        low = -(self.dedendum - self.tip_radius - self.profile_shift) * self.module
        return np.linspace(min(low, 0.0), 0.0, 6)


@dataclass(frozen=True)
class CutterChoice:
    """Which cutter made a tooth space: ``"rack"``, or ``"shaper"`` with its pitch radius."""

    kind: str
    pitch_radius: float = np.inf


def rack_tooth_outline(system: ToothSystem, *, flank_points: int = 48, fillet_points: int = 16,
                       top: float | None = None):
    """Outline of one rack tooth centred at x = 0, from the top of its left flank to the top of its right.

    Returns
    -------
    xy : (k, 2) float
        Rack coordinates: x along the pitch line (the line that rolls on the pitch
        curve), y outward from the gear (the tooth points to -y, its tip at
        ``-dedendum + x m``: the whole outline stands ``x m`` out for a profile shift x;
        ``top`` is measured from the rack's own reference line).
    normal : (k, 2) float
        Unit normals pointing out of the rack tooth (into the gear's material).
    """
    m, alpha = system.module, system.pressure_angle
    depth, radius = system.dedendum_depth, system.tip_radius * m
    top = system.addendum_height + 0.6 * m if top is None else top
    width = system.pitch / 2 + system.backlash          # rack tooth = gear space at the pitch line
    tan, sin, cos = np.tan(alpha), np.sin(alpha), np.cos(alpha)
    centre_y = -depth + radius
    left_centre = -(width / 2 + centre_y * tan) + radius / cos
    if left_centre > 1e-12:
        raise ValueError(f"tip radius {system.tip_radius:g} m is too large for this rack: "
                         "the two tip fillets overlap")
    tangent_y = centre_y - radius * sin
    # left flank, top down to the fillet
    y = np.linspace(top, tangent_y, flank_points)
    left = np.stack([-(width / 2 + y * tan), y], axis=-1)
    left_normal = np.tile([-cos, -sin], (flank_points, 1))
    # left fillet: normal turns from the flank's to straight down
    angle = np.linspace(np.pi + alpha, 1.5 * np.pi, fillet_points)[1:]
    arc_normal = np.stack([np.cos(angle), np.sin(angle)], axis=-1)
    arc = np.array([left_centre, centre_y]) + radius * arc_normal
    # tip flat between the fillet centres (may be a single point)
    flat_x = np.linspace(left_centre, -left_centre, max(3, fillet_points // 2))[1:-1]
    flat = np.stack([flat_x, np.full_like(flat_x, -depth)], axis=-1)
    flat_normal = np.tile([0.0, -1.0], (len(flat_x), 1))
    mirror = np.array([-1.0, 1.0])
    xy = np.vstack([left, arc, flat, (arc * mirror)[::-1], (left * mirror)[::-1]])
    normal = np.vstack([left_normal, arc_normal, flat_normal, (arc_normal * mirror)[::-1],
                        (left_normal * mirror)[::-1]])
    if system.profile_shift:   # (an unshifted rack keeps its exact numbers: no + 0.0)
        xy[:, 1] += system.shift_height
    return xy, normal


@functools.lru_cache(maxsize=32)
def _rack_tooth(system: ToothSystem, *, flank_points: int = 48, fillet_points: int = 16):
    """:func:`rack_tooth_outline`, remembered (read-only arrays): every space a rack cuts rolls
    the same rack tooth."""
    xy, normal = rack_tooth_outline(system, flank_points=flank_points,
                                    fillet_points=fillet_points)
    xy.setflags(write=False)
    normal.setflags(write=False)
    return xy, normal


def rack_space_boundary(curve: ArcLengthCurve, centre: float, system: ToothSystem, **outline):
    """The envelope bounding one tooth space cut by a rack, in the gear frame.

    Parameters
    ----------
    curve : ArcLengthCurve
        The gear's pitch curve.
    centre : float
        Arc length of the space's centre on the pitch curve.

    Returns
    -------
    (k, 2) float
        From the top of the left flank round the root to the top of the right.
    """
    xy, normal = _rack_tooth(system, **outline)
    x = xy[:, 0] + centre
    y = xy[:, 1]
    # the instant each rack point is on the envelope: its normal passes the pitch point
    s = x - y * normal[:, 0] / normal[:, 1]
    point, tangent, outward = curve.frame(s)
    return point + (x - s)[:, None] * tangent + y[:, None] * outward


def shaper_space_boundary(curve: ArcLengthCurve, centre: float, system: ToothSystem,
                          cutter_teeth: int, *, flank_points: int = 48, fillet_points: int = 16):
    """The envelope bounding one tooth space cut by a shaper (pinion cutter) of ``cutter_teeth``.

    The cutter's pitch circle (radius ``z_c m / 2``) rolls on the pitch curve
    from outside; it can cut a concave stretch whose radius of curvature
    exceeds its pitch radius.
    """
    xy, normal, radius = _shaper_tooth(system, cutter_teeth, flank_points, fillet_points)
    # pitch point of each cutter point: its normal line meets the cutter pitch circle
    along = np.einsum("ij,ij->i", xy, normal)
    reach = along**2 - (np.einsum("ij,ij->i", xy, xy) - radius**2)
    if np.any(reach < 0):
        raise ValueError("a cutter normal misses the pitch circle (cutter tooth too long)")
    roots = np.stack([-along - np.sqrt(reach), -along + np.sqrt(reach)], axis=-1)
    # the pitch point is the intersection nearer the cutter point: an involute point lies on
    # its base tangent on the same side of the base point as its pitch-circle point
    choice = np.argmin(np.abs(roots), axis=1)
    hit = xy + roots[np.arange(len(xy)), choice][:, None] * normal
    omega = np.arctan2(hit[:, 1], hit[:, 0])
    # rolling: the cutter-frame contact angle is -(s - centre)/r_c
    s = centre - radius * omega
    point, tangent, outward = curve.frame(s)
    cutter_centre = point + radius * outward
    # rotate cutter coordinates so the contact direction (angle omega) maps to -n(s)
    turn = np.arctan2(-outward[:, 1], -outward[:, 0]) - omega
    cos, sin = np.cos(turn), np.sin(turn)
    return cutter_centre + np.stack([cos * xy[:, 0] - sin * xy[:, 1],
                                     sin * xy[:, 0] + cos * xy[:, 1]], axis=-1)


@functools.lru_cache(maxsize=32)
def _shaper_tooth(system: ToothSystem, teeth: int, flank_points: int, fillet_points: int):
    """One tooth of a pinion cutter centred on the +x axis: outline, outward normals, pitch radius.

    Remembered (read-only arrays): every space a shaper cuts rolls the same cutter tooth, and
    its flank points come from a root search each.

    Involute flanks of the base circle ``r cos(alpha)``, thickness at the pitch
    circle equal to the gear's space (``p/2 + backlash``), tip at ``r + dedendum``
    rounded with ``tip_radius`` tangent to flank and tip circle; the flank runs
    down to the base circle or the cutter's own root, whichever is higher.

    A profile shift x of the gear is the cutter's own shift -x (the pair cutter-gear is
    V-zero, rolling on the pitch circle and the pitch curve): its teeth
    ``2 x m tan(alpha)`` thinner at the pitch circle, tip and root ``x m`` lower. On a
    circle this cuts exactly the shifted spur gear a rack shifted by ``x m`` cuts.
    """
    from kinematics.scalar import brentq

    m, alpha = system.module, system.pressure_angle
    radius = teeth * m / 2
    base = radius * np.cos(alpha)
    tip = radius + system.dedendum_depth - system.shift_height
    rounding = system.tip_radius * m
    thickness = system.pitch / 2 + system.backlash
    if system.profile_shift:   # (an unshifted cutter keeps its exact numbers)
        thickness -= 2 * system.shift_height * np.tan(alpha)
    half = thickness / (2 * radius)  # half tooth angle at the pitch circle
    involute = np.tan(alpha) - alpha

    def flank(rad):  # polar angle of the upper (+) flank at radius rad
        pressure = np.arccos(np.clip(base / rad, -1, 1))
        return half + involute - (np.tan(pressure) - pressure)

    def point(rad):
        return rad * np.array([np.cos(flank(rad)), np.sin(flank(rad))])

    def normal_at(rad):  # outward normal of the + flank (points away from the tooth axis)
        # the flank unwinds clockwise from the base point at polar angle flank - pressure;
        # its tangent is radial from that base point, its normal tangent to the base circle
        pressure = np.arccos(np.clip(base / rad, -1, 1))
        direction = flank(rad) - pressure
        return np.array([-np.sin(direction), np.cos(direction)])

    # tip rounding: circle tangent to the tip circle (inside) and the flank
    def gap(rad):
        centre_distance = tip - rounding
        p, n = point(rad), normal_at(rad)
        centre = p - rounding * n
        return np.linalg.norm(centre) - centre_distance

    # the cutter reaches 0.6 m deeper than the gear's addendum, like the rack: below its base
    # circle its flank is radial (a real cutter's root), which still sweeps the gear's tips
    root = radius - system.tip_height - 0.6 * m
    low = max(base * (1 + 1e-9), root)
    touch = brentq(gap, low, tip) if rounding > 0 else tip
    arc_centre = point(touch) - rounding * normal_at(touch)
    start = np.arctan2(*normal_at(touch)[::-1])
    stop = np.arctan2(arc_centre[1], arc_centre[0])
    if stop > start:
        stop -= 2 * np.pi
    radii = np.linspace(low, touch, flank_points)
    flank_xy = np.array([point(r) for r in radii])
    flank_n = np.array([normal_at(r) for r in radii])
    if root < low:  # radial continuation from the cutter root to the base circle
        angle = flank(low)
        radial = np.linspace(root, low, max(4, flank_points // 4))[:-1]
        direction = np.array([np.cos(angle), np.sin(angle)])
        flank_xy = np.vstack([radial[:, None] * direction, flank_xy])
        flank_n = np.vstack([np.tile([-direction[1], direction[0]], (len(radial), 1)), flank_n])
    theta = np.linspace(start, stop, fillet_points)[1:]
    arc_n = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    arc_xy = arc_centre + rounding * arc_n
    upper = np.vstack([flank_xy, arc_xy])
    upper_n = np.vstack([flank_n, arc_n])
    mirror = np.array([1.0, -1.0])
    # order: from the top (root side) of the - flank, round the tip, to the + flank's root side
    xy = np.vstack([(upper * mirror), upper[::-1]])
    normal = np.vstack([(upper_n * mirror), upper_n[::-1]])
    xy.setflags(write=False)
    normal.setflags(write=False)
    return xy, normal, radius


def gear_outline(curve: ArcLengthCurve, teeth: int, system: ToothSystem, *, phase: float = 0.0,
                 cutters=None, blank_points: int = 4096, secondary_positions: int = 8,
                 **outline):
    """Tooth outline of a gear: the addendum blank minus every tooth space.

    Parameters
    ----------
    curve : ArcLengthCurve
        Pitch curve; its length must be ``teeth * pi * module``.
    phase : float
        Arc length of the first tooth's centre (spaces are half a pitch further).
    cutters : list of CutterChoice, optional
        One per tooth space (default: rack everywhere).
    secondary_positions : int
        Rolling positions per pitch at which a shaper's neighbouring teeth are
        subtracted too (secondary cutting); the scallops they leave shrink with
        the square of the step.

    Returns
    -------
    outline : (n, 2) float
        Counter-clockwise, not closed.
    spaces : list of (k, 2) float
        Each tooth space's envelope (for checks).
    """
    import shapely

    pitch = system.pitch
    if not np.isclose(curve.length, teeth * pitch, rtol=1e-9):
        raise ValueError(f"pitch curve length {curve.length:.6f} mm does not hold {teeth} teeth "
                         f"of module {system.module:g} ({teeth * pitch:.6f} mm)")
    s = np.arange(blank_points) * (curve.length / blank_points)
    point, _, outward = curve.frame(s)
    blank = shapely.Polygon(point + system.tip_height * outward)
    spaces, polygons = [], []
    for k in range(teeth):
        centre = phase + (k + 0.5) * pitch
        cutter = cutters[k] if cutters is not None else CutterChoice("rack")
        if cutter.kind == "rack":
            boundary = rack_space_boundary(curve, centre, system, **outline)
        else:
            teeth_c = int(round(2 * cutter.pitch_radius / system.module))
            boundary = shaper_space_boundary(curve, centre, system, teeth_c, **outline)
        spaces.append(boundary)
        # close the space outside the blank, along the outward normals
        ends = np.array([centre - pitch / 2, centre, centre + pitch / 2])
        p, _, n = curve.frame(ends)
        outside = p + 3.0 * system.module * n
        ring = np.vstack([boundary, outside[::-1]])
        polygons.append(shapely.make_valid(shapely.Polygon(ring)))
    # a shaper also cuts at a second instant (its normal meets its pitch circle twice): the
    # cutter's own neighbouring teeth and roots trim tip corners next to concave stretches.
    # Those secondary cuts come from the cutter at discrete rolling positions; each position
    # lies inside the swept region, so the exact flanks above are never over-cut.
    shaped = [k for k in range(teeth) if cutters is not None and cutters[k].kind == "shaper"]
    if shaped:
        polygons += _secondary_shaper_cuts(curve, system, phase, shaped, cutters,
                                           secondary_positions)
    removed = shapely.make_valid(shapely.union_all(polygons))
    gear = shapely.make_valid(blank.difference(removed))
    if gear.geom_type != "Polygon":
        parts = sorted((g for g in getattr(gear, "geoms", [gear]) if g.geom_type == "Polygon"),
                       key=lambda g: -g.area)
        if not parts:
            raise ValueError("the tooth spaces leave no gear body")
        gear = parts[0]
    ring = np.asarray(gear.exterior.coords)[:-1]
    if shapely.LinearRing(ring).is_ccw is False:
        ring = ring[::-1]
    return ring, spaces


def _shaper_polygon(system: ToothSystem, cutter_teeth: int, span: int | None = None):
    """The pinion cutter as a polygon (its ``2 span + 1`` teeth round the +x axis, or all)."""
    import shapely

    xy, _, radius = _shaper_tooth(system, cutter_teeth, 24, 12)
    indices = range(cutter_teeth) if span is None else range(-span, span + 1)
    angles = 2 * np.pi * np.array(list(indices)) / cutter_teeth
    ring = np.vstack([xy @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
                      for a in angles])
    if span is not None:  # close the partial cutter through its centre
        ring = np.vstack([ring, [[0.0, 0.0]]])
    return shapely.make_valid(shapely.Polygon(ring)), radius  # tip arcs may overlap on the axis


def _placed_shaper(cutter, radius, curve, position, reference):
    """The cutter rolled to ``position``, with its tooth 0 on the contact at ``reference``."""
    import shapely.affinity

    p, _, n = curve.frame(np.array([position]))
    omega = -(position - reference) / radius          # cutter angle of the contact point
    turn = np.arctan2(-n[0, 1], -n[0, 0]) - omega
    c, s = np.cos(turn), np.sin(turn)
    centre = p[0] + radius * n[0]
    return shapely.affinity.affine_transform(cutter, [c, -s, s, c, centre[0], centre[1]])


def _secondary_shaper_cuts(curve, system, phase, spaces, cutters, per_pitch):
    pitch = system.pitch
    polygons = []
    cache = {}
    for k in spaces:
        teeth_c = int(round(2 * cutters[k].pitch_radius / system.module))
        if teeth_c not in cache:
            cache[teeth_c] = _shaper_polygon(system, teeth_c, span=1)
        cutter, radius = cache[teeth_c]
        centre = phase + (k + 0.5) * pitch
        for offset in np.linspace(-pitch, pitch, 2 * per_pitch + 1):
            polygons.append(_placed_shaper(cutter, radius, curve, centre + offset, centre))
    return polygons


def simulated_rack_cut(curve: ArcLengthCurve, teeth: int, system: ToothSystem, *,
                       phase: float = 0.0, positions_per_pitch: int = 200, blank_points: int = 4096):
    """The slow reference: subtract the rack polygon at many rolling positions from the blank.

    Independent of the envelope condition: it only rolls the rack (pitch line
    tangent to the pitch curve at ``P(s)``, rack x = s there) and takes boolean
    differences. The scallops it leaves between positions shrink with the square
    of the step. Returns the outline, counter-clockwise.
    """
    import shapely

    pitch = system.pitch
    s = np.arange(blank_points) * (curve.length / blank_points)
    point, _, outward = curve.frame(s)
    blank = shapely.Polygon(point + system.tip_height * outward)
    tooth, _ = rack_tooth_outline(system, flank_points=24, fillet_points=16,
                                  top=system.addendum_height + 2.0 * system.module)
    centres = phase + (np.arange(teeth) + 0.5) * pitch
    racks = []
    for position in np.arange(teeth * positions_per_pitch) * (pitch / positions_per_pitch):
        p, t, n = curve.frame(np.array([position]))
        nearest = centres[np.abs(np.mod(centres - position + curve.length / 2, curve.length)
                                 - curve.length / 2) < 1.6 * pitch]
        for centre in nearest:
            offset = np.mod(centre - position + curve.length / 2, curve.length) - curve.length / 2
            x = tooth[:, 0] + offset
            racks.append(shapely.Polygon(p + x[:, None] * t + tooth[:, 1:2] * n))
    gear = blank.difference(shapely.union_all(racks))
    if gear.geom_type != "Polygon":
        gear = max(gear.geoms, key=lambda g: g.area)
    ring = np.asarray(gear.exterior.coords)[:-1]
    return ring if shapely.LinearRing(ring).is_ccw else ring[::-1]


def simulated_shaper_cut(curve: ArcLengthCurve, teeth: int, system: ToothSystem,
                         cutter_teeth: int, *, phase: float = 0.0, positions_per_pitch: int = 120,
                         blank_points: int = 4096):
    """The slow reference for shaping: subtract the whole pinion cutter at many rolling positions.

    The cutter (all its teeth) rolls its pitch circle on the pitch curve from
    outside; tooth 0 cuts the space centred at ``phase + p/2`` and each further
    tooth the next space, one pitch of rolling apart.
    """
    import shapely

    pitch = system.pitch
    cutter, radius = _shaper_polygon(system, cutter_teeth)
    s = np.arange(blank_points) * (curve.length / blank_points)
    point, _, outward = curve.frame(s)
    blank = shapely.Polygon(point + system.tip_height * outward)
    first = phase + 0.5 * pitch
    cuts = [_placed_shaper(cutter, radius, curve, position, first) for position in
            first + np.arange(teeth * positions_per_pitch) * (pitch / positions_per_pitch)]
    gear = blank.difference(shapely.union_all(cuts))
    if gear.geom_type != "Polygon":
        gear = max(gear.geoms, key=lambda g: g.area)
    out = np.asarray(gear.exterior.coords)[:-1]
    return out if shapely.LinearRing(out).is_ccw else out[::-1]

# ----------------------------------------------------------------------------------------------
# The cut gear: its profile

@dataclass(frozen=True)
class GearProfile:
    """One gear as it will be cut.

    Attributes
    ----------
    name : str
        e.g. ``"central"``, ``"intermediate 1"``; used in file names (spaces become ``-``).
    outline : (n, 2) float
        Closed tooth outline in the gear's body frame (mm), counter-clockwise, the
        first point not repeated at the end. Dense: consecutive points are at
        most a small fraction of a module apart.
    pitch_curve : (m, 2) float
        Closed pitch curve in the same frame, counter-clockwise, not repeated.
    teeth : int
    module : float
        mm.
    bore_radius : float
        Radius of the shaft bore at the body-frame origin (mm); 0 for none.
    centre : (2,) float
        Rotation centre in the body frame (the origin, normally).
    hole : (k, 2) float, optional
        The hub's hole in the body frame (the bore with its keyway or D-flat, closed,
        counter-clockwise, the first point not repeated; see :mod:`cadgen.machine.hubs`).
        When set it is what is cut, in place of the circle of ``bore_radius``.
    """

    name: str
    outline: np.ndarray
    pitch_curve: np.ndarray
    teeth: int
    module: float
    bore_radius: float = 0.0
    centre: tuple = (0.0, 0.0)
    notes: dict = field(default_factory=dict)
    hole: np.ndarray | None = None
    # values computed from this profile by later stages (see derived()); a changed copy
    # (dataclasses.replace) starts empty, and neither pickles nor compares nor keys a cache
    _derived: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def derived(self, key, compute):
        """``compute()`` the first time ``key`` is asked for on this profile, then remembered.

        For what several stages need from one cut gear (its thinned cutting outline: the
        solid, its DXF file and the train sheet); ``key`` must name everything besides the
        profile that the value depends on (a tolerance, say).
        """
        try:
            return self._derived[key]
        except KeyError:
            value = self._derived[key] = compute()
            return value

    def __getstate__(self):
        state = dict(self.__dict__)
        state["_derived"] = {}
        return state

    def __setstate__(self, state):
        for name, value in state.items():
            object.__setattr__(self, name, value)

    @property
    def hole_reach(self) -> float:
        """mm, the farthest the hole (or the round bore) reaches from the centre: a disc of
        this radius holds everything cut at the hub (the outline's thinning keeps clear of it)."""
        if self.hole is None:
            return float(self.bore_radius)
        offsets = np.asarray(self.hole, dtype=float) - np.asarray(self.centre, dtype=float)
        return float(np.max(np.hypot(offsets[:, 0], offsets[:, 1])))

    @property
    def file_stem(self) -> str:
        return self.name.replace(" ", "-")

    def placed(self, angle: float, offset=(0.0, 0.0)):
        """Outline and pitch curve rotated by ``angle`` (rad) about the centre, then moved by ``offset``."""
        c, s = np.cos(angle), np.sin(angle)
        rotation = np.array([[c, -s], [s, c]])
        centre = np.asarray(self.centre, dtype=float)
        move = np.asarray(offset, dtype=float)
        return ((self.outline - centre) @ rotation.T + centre + move,
                (self.pitch_curve - centre) @ rotation.T + centre + move)
