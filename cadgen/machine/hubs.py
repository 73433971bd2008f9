"""Gear hubs: the bore on the shaft with its keyway (DIN 6885) or D-flat, and the rim it leaves.

Every gear is bored for its shaft. A torque-carrying gear on a shaft of a parallel-key size
gets a keyway in its bore (DIN 6885-1 form A hub keyway: width ``b``, bottom at ``d/2 + t2``
from the axis on the keyway's centre line); a small shaft gets a D-flat instead (the bore cut
by a chord ``flat_depth`` inside the shaft's surface). The hole is one closed polygon, the
bore and its keyway together, as the DXF's ``BORE`` layer and the STL's through hole need it.

The bore must not cut into the teeth: the rim left between the hole and the root of every
tooth space is measured (the least distance between the two rings) and held against a limit
in modules, the rim backup rule of gear design (ISO 6336-3 and AGMA 2001 count a rim thinner
than 1.2 whole depths as weakening the tooth's bending strength; a rim of one module is the
usual hard minimum below which the rim itself cracks between a root and the keyway).

A non-circular gear's root lies at different radii round the gear, so the keyway is turned to
where it leaves the thickest rim (:func:`best_keyway_angle`).

The outline a bored gear is cut along (:func:`cutting_outline`: thinned to the chord tolerance,
kept clear of the hole's reach) is made here once per gear and tolerance, for the solid, the
gear's DXF file and the train sheet alike.

numpy and shapely only (shapely imported inside the functions).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from kinematics.errors import Problem

__all__ = ["MIN_RIM_MODULES", "WARN_RIM_MODULES", "KEYWAY_ANGLE_STEPS", "KEYWAY_TIE_TOLERANCE",
           "RimCheck", "CuttingOutline", "hub_hole", "best_keyway_angle", "rim_thickness",
           "rim_check", "hub_train", "cutting_outline", "outline_radius_along",
           "set_screw_clearance"]

#: Rim under the hole below this many modules fails (``rim_too_thin``): the common hard minimum
#: of a gear's rim (one module), below which the rim cracks between the root and the bore.
MIN_RIM_MODULES = 1.0
#: Rim below this many modules is a warning (``rim_thin``): the rim backup ratio of ISO 6336-3 /
#: AGMA 2001, 1.2 x the whole depth (2.25 m), under which the tooth's bending strength drops.
WARN_RIM_MODULES = 2.5
#: Directions scanned by :func:`best_keyway_angle` (a 0.5 deg step).
KEYWAY_ANGLE_STEPS = 720
#: mm: directions whose rim is within this of the thickest are tied and the first (the smallest
#: angle) wins. A circular gear's teeth give z directions equal but for rounding (1e-14 mm
#: apart), which must not decide; a non-circular gear's best direction stands out by far more
#: (0.01 mm and up on the bundled designs).
KEYWAY_TIE_TOLERANCE = 1e-6
#: Samples per scanned direction when a ring is resampled for the radial profiles: every bin
#: of the scan then holds points of both rings.
_SAMPLES_PER_STEP = 8


@dataclass(frozen=True)
class RimCheck:
    """The thinnest rim left between one gear's hole and its outline.

    Attributes
    ----------
    gear : str
    thickness : float
        mm, the least distance between the hole and the outline (``nan``: no hole).
    limit : float
        mm, ``MIN_RIM_MODULES`` modules: thinner fails.
    passed : bool
        ``thickness >= limit`` (a gear without a hole passes: nothing is cut into it).
    where : tuple
        ``(point on the outline (x, y), point on the hole (x, y))`` of the thinnest rim, body
        frame, mm; ``()`` without a hole.
    warning_limit : float
        mm, ``WARN_RIM_MODULES`` modules: thinner is reported as a warning.
    module : float
    problems : tuple of Problem
        ``rim_too_thin`` (failing), ``rim_thin`` (warning) or ``hub_not_mounted`` (warning: no
        shaft carries the gear, so it has no hole).
    """

    gear: str
    thickness: float
    limit: float
    passed: bool
    where: tuple
    warning_limit: float = math.nan
    module: float = math.nan
    problems: tuple = ()

    @property
    def warned(self) -> bool:
        """A rim thinner than the warning limit (and maybe than the failing one)."""
        return bool(self.thickness < self.warning_limit)


# --------------------------------------------------------------------------- the hole


def _finite(name: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return number


def _arc(radius: float, start: float, stop: float, segments: int) -> np.ndarray:
    """Points on a circle from angle ``start`` to ``stop`` (both included), counter-clockwise,
    no chord longer than a ``segments``-gon's."""
    count = max(1, math.ceil((stop - start) / (2 * math.pi) * segments))
    angle = np.linspace(start, stop, count + 1)
    return radius * np.column_stack([np.cos(angle), np.sin(angle)])


def hub_hole(diameter: float, *, key=None, flat_depth: float = 0.0, bore_allowance: float = 0.0,
             key_slot_allowance: float = 0.0, angle: float = 0.0, segments: int = 96) -> np.ndarray:
    """The hub's hole: the bore with its keyway or D-flat, centred on the origin.

    Parameters
    ----------
    diameter : float
        mm, the shaft's nominal diameter ``d`` (> 0).
    key : KeySize, optional
        The parallel key: the keyway is ``key.width + key_slot_allowance`` wide and its bottom
        lies ``d/2 + key.hub_depth + key_slot_allowance/2`` from the axis on its centre line
        (DIN 6885's ``d + t2``, each cut edge of the slot moved out by half the allowance).
    flat_depth : float
        mm, D-flat depth from the shaft's surface (0: none; not with a key): the bore is cut
        by a chord ``d/2 - flat_depth + bore_allowance/2`` from the centre.
    bore_allowance : float
        mm, the bore's diametral allowance: the circle's diameter is ``d + bore_allowance``.
    key_slot_allowance : float
        mm, the keyway's width allowance (from the process's fits).
    angle : float
        rad, the direction of the keyway's (or flat's) centre line.
    segments : int
        Chords of the full circle (>= 8); the arcs' points lie exactly on the circle (an
        inscribed polygon, like the round bore's) and the corners where the keyway's sides or
        the flat meet the circle are exact.

    Returns
    -------
    (n, 2) float
        Closed, counter-clockwise, the first point not repeated.

    Raises
    ------
    ValueError
        Naming the bad argument and its value.
    """
    d = _finite("diameter", diameter)
    allowance = _finite("bore_allowance", bore_allowance)
    slot = _finite("key_slot_allowance", key_slot_allowance)
    flat = _finite("flat_depth", flat_depth)
    turn = _finite("angle", angle)
    if d <= 0:
        raise ValueError(f"diameter must be > 0 mm, got {diameter!r}")
    radius = (d + allowance) / 2
    if radius <= 0:
        raise ValueError(f"bore_allowance {bore_allowance!r} leaves no bore of diameter {d:g}")
    if isinstance(segments, bool) or not isinstance(segments, (int, np.integer)) or segments < 8:
        raise ValueError(f"segments must be an integer >= 8, got {segments!r}")
    if flat < 0:
        raise ValueError(f"flat_depth must be >= 0 mm, got {flat_depth!r}")
    if key is not None and flat > 0:
        raise ValueError(f"a hub has a key or a D-flat, not both (key {key!r}, flat_depth {flat:g})")
    if key is not None:
        width = _finite("key.width", key.width) + slot
        hub_depth = _finite("key.hub_depth", key.hub_depth)
        if width <= 0:
            raise ValueError(f"key.width + key_slot_allowance must be > 0 mm, got {width:g}")
        if hub_depth <= 0:
            raise ValueError(f"key.hub_depth must be > 0 mm, got {key.hub_depth!r}")
        half = width / 2
        if half >= radius:
            raise ValueError(f"key: keyway width {width:g} mm is not narrower than the bore "
                             f"({2 * radius:g} mm)")
        bottom = d / 2 + hub_depth + slot / 2
        if bottom <= radius:
            raise ValueError(f"key: keyway bottom {bottom:g} mm from the axis does not reach beyond "
                             f"the bore's radius {radius:g} mm (hub_depth {hub_depth:g})")
        corner = math.sqrt(radius**2 - half**2)
        # keyway bottom, then the bore's arc from one side of the keyway round to the other
        start = math.atan2(half, corner)
        local = np.vstack([[[bottom, -half], [bottom, half]],
                           _arc(radius, start, 2 * math.pi - start, segments)])
    elif flat > 0:
        if flat >= d / 2:
            raise ValueError(f"flat_depth must be less than the shaft's radius {d / 2:g} mm, "
                             f"got {flat_depth!r}")
        chord = d / 2 - flat + allowance / 2
        if not -radius < chord < radius:
            raise ValueError(f"flat_depth {flat:g} with bore_allowance {allowance:g} leaves no "
                             "D-shaped bore")
        start = math.acos(chord / radius)
        local = _arc(radius, start, 2 * math.pi - start, segments)   # the chord closes it
    else:
        local = _arc(radius, 0.0, 2 * math.pi, segments)[:-1]
    cos, sin = math.cos(turn), math.sin(turn)
    return local @ np.array([[cos, sin], [-sin, cos]])


# --------------------------------------------------------------------------- direction and rim


def _resampled(ring: np.ndarray, count: int) -> np.ndarray:
    """``count`` points evenly spaced along a closed ring (its vertices in between dropped)."""
    closed = np.vstack([ring, ring[:1]])
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    s = np.arange(count) * (along[-1] / count)
    return np.column_stack([np.interp(s, along, closed[:, 0]), np.interp(s, along, closed[:, 1])])


def _polar_bins(points: np.ndarray, steps: int):
    """Bin index (of ``steps`` round the circle) and radius of each point."""
    polar = np.mod(np.arctan2(points[:, 1], points[:, 0]), 2 * np.pi)
    return np.minimum((polar * steps / (2 * np.pi)).astype(int), steps - 1), np.hypot(*points.T)


def best_keyway_angle(outline, hole_fn, *, steps: int = KEYWAY_ANGLE_STEPS) -> float:
    """The keyway (or flat) direction that leaves the thickest rim, rad in [0, 2 pi).

    Radial estimate, vectorized: the outline's least radius and the hole's (at angle 0) greatest
    radius in each of ``steps`` angular bins; turning the hole by ``k`` bins leaves the radial
    rim ``min over bins (outline(b) - hole(b - k))`` under the part of the hole reaching beyond
    its circle (the keyway; a D-flat: the whole hole, so the flat faces the nearest root); the
    first largest wins (within :data:`KEYWAY_TIE_TOLERANCE`). A circular gear's rims differ
    only by how the keyway's corners fall against the roots: its z equivalent directions tie
    and the first of them is taken. :func:`rim_thickness` measures the chosen hole exactly.

    Parameters
    ----------
    outline : (n, 2) float
        The gear's closed outline about the origin (the rotation centre).
    hole_fn : callable
        ``angle -> (m, 2) hole`` (e.g. :func:`hub_hole` with its sizes bound).
    steps : int
        Directions scanned.
    """
    outline = np.asarray(outline, dtype=float)
    hole = np.asarray(hole_fn(0.0), dtype=float)
    samples = steps * _SAMPLES_PER_STEP
    outer_bin, outer_radius = _polar_bins(_resampled(outline, samples), steps)
    inner_bin, inner_radius = _polar_bins(_resampled(hole, samples), steps)
    outer = np.full(steps, np.inf)
    np.minimum.at(outer, outer_bin, outer_radius)
    inner = np.zeros(steps)
    np.maximum.at(inner, inner_bin, inner_radius)
    # only the bins where the hole reaches beyond its circle (the keyway) depend on the
    # direction: the rest of the rim is the same for every turn and would tie every direction
    # whose keyway is clear enough. The circle's radius is the one most vertices lie on (the
    # arcs'); a D-flat reaches nowhere beyond it and is judged by the whole rim instead (its
    # flat then faces the nearest root, where the circle would leave the least).
    vertex_radius = np.hypot(hole[:, 0], hole[:, 1])
    circle = float(np.median(vertex_radius))
    edges = np.linalg.norm(np.roll(hole, -1, axis=0) - hole, axis=1)
    if np.ptp(vertex_radius) <= 1e-9 * circle and np.ptp(edges) <= 1e-9 * edges.max():
        return 0.0        # a regular polygon, a round bore: every direction is the same
    beyond = inner > circle * (1 + 1e-9)
    if not beyond.any():
        beyond = np.ones(steps, dtype=bool)
    # hole turned by k bins: its bin b lands on bin (b + k); only the bins beyond the circle
    # count, so the scan is (turns x those bins), the same differences as the full table
    bins = np.flatnonzero(beyond)
    landed = np.mod(np.arange(steps)[:, None] + bins[None, :], steps)
    rim = np.min(outer[landed] - inner[bins][None, :], axis=1)
    best = int(np.flatnonzero(rim >= rim.max() - KEYWAY_TIE_TOLERANCE)[0])
    return float(best * 2 * np.pi / steps)


def rim_thickness(outline, hole):
    """The thinnest material between a hole and the outline round it.

    Parameters
    ----------
    outline, hole : (n, 2), (m, 2) float
        Closed rings, the first point not repeated, in one frame.

    Returns
    -------
    thickness : float
        mm, the least distance between the two rings.
    on_outline, on_hole : (2,) float
        The two ends of that shortest segment.

    Raises
    ------
    ValueError
        If the hole is not strictly inside the outline.
    """
    import shapely

    outline = np.asarray(outline, dtype=float)
    hole = np.asarray(hole, dtype=float)
    outer, inner = shapely.LinearRing(outline), shapely.LinearRing(hole)
    if not shapely.Polygon(outer).contains(shapely.Polygon(inner)):
        raise ValueError("hole is not inside the outline: the bore cuts through the gear")
    line = np.asarray(shapely.shortest_line(inner, outer).coords)
    return float(np.linalg.norm(line[1] - line[0])), line[1], line[0]


def rim_check(profile, hole, *, path: str = "") -> RimCheck:
    """The thinnest rim of ``profile`` with ``hole`` (body frame) against the limits.

    A hole that is not inside the outline fails with thickness 0 (the bore breaks through).
    """
    module = float(profile.module)
    limit, warning = MIN_RIM_MODULES * module, WARN_RIM_MODULES * module
    try:
        thickness, on_outline, on_hole = rim_thickness(profile.outline, hole)
        where = (tuple(on_outline.tolist()), tuple(on_hole.tolist()))
    except ValueError:
        thickness, where = 0.0, ()
    passed = thickness >= limit
    remedies = ("use a smaller shaft (give a smaller diameter in [machine.shafts]) or more "
                "teeth (a larger gear for the same module)")
    problems = ()
    if not passed:
        problems = (Problem(path, "rim_too_thin",
                            f"the {profile.name} gear's rim under its bore is {thickness:.2f} mm "
                            f"thick, below the limit of {limit:.2f} mm ({MIN_RIM_MODULES:g} "
                            f"modules of {module:g} mm): {remedies}"),)
    elif thickness < warning:
        problems = (Problem(path, "rim_thin",
                            f"the {profile.name} gear's rim under its bore is {thickness:.2f} mm "
                            f"thick, below {warning:.2f} mm ({WARN_RIM_MODULES:g} modules, 1.2 x "
                            f"the whole depth): its teeth lose bending strength; {remedies}"),)
    return RimCheck(profile.name, thickness, limit, bool(passed), where, warning, module, problems)


def outline_radius_along(outline, angle: float) -> float:
    """mm: where the ray from the origin at ``angle`` (rad) first leaves ``outline`` (a closed
    ring about the origin): a tooth's tip, or a tooth space's root."""
    import shapely

    ray = shapely.LineString([(0.0, 0.0), (1e4 * math.cos(angle), 1e4 * math.sin(angle))])
    crossing = shapely.LinearRing(np.asarray(outline, dtype=float)).intersection(ray)
    points = np.array([p.coords[0] for p in getattr(crossing, "geoms", [crossing])
                       if not p.is_empty]).reshape(-1, 2)
    return float(np.min(np.hypot(points[:, 0], points[:, 1])))


def set_screw_clearance(profile, shaft, key, designation: str) -> float:
    """mm between a hub set screw's far end and the gear's outline on the keyway's line (< 0:
    the screw stands proud). The screw is radial on the keyway's centre line, its point on
    the key's back (``d/2 - t1 + h`` from the axis), as long as its designation says
    (``... M5 x 8 ...``)."""
    from cadgen.machine.retention import set_screw_size

    _, length = set_screw_size(designation)
    back = shaft.diameter / 2 - key.shaft_depth + key.height
    angle = float(profile.notes.get("keyway_angle_rad", 0.0))
    outline = np.asarray(profile.outline, dtype=float) - np.asarray(profile.centre, dtype=float)
    return outline_radius_along(outline, angle) - (back + length)


# --------------------------------------------------------------------------- the train


def hub_train(train, drivetrain, *, key_slot_allowance: float = 0.0, segments: int = 96):
    """Every gear of a train bored for its shaft, and the rim each bore leaves.

    Parameters
    ----------
    train : cadgen.gears.trains.GearTrain
    drivetrain : cadgen.machine.model.Drivetrain
        ``shaft_of_gear(name)`` gives each gear's mount: ``hub_bore``, ``key``,
        ``flat_depth``, ``bore_allowance``.
    key_slot_allowance : float
        mm, the process's keyway width allowance.
    segments : int
        Chords of a full bore circle.

    Returns
    -------
    train : GearTrain
        A copy whose profiles carry their ``hole`` (body frame, at the profile's centre) and
        ``bore_radius`` (the round bore's); a gear met in two stages gets the same profile in
        both. A gear no shaft carries keeps no hole.
    rim_checks : tuple of RimCheck
        One per distinct gear, in the train's order (see :class:`RimCheck`).
    """
    bored, checks = {}, []
    screws = {gear: designation for held in getattr(drivetrain, "retention", ()) or ()
              for gear, designation in held.set_screws}
    for profile, _, _, _ in train.gears:
        try:
            shaft, mount = drivetrain.shaft_of_gear(profile.name)
        except KeyError:
            bored[profile.name] = profile
            checks.append(RimCheck(profile.name, math.nan, MIN_RIM_MODULES * profile.module, True,
                                   (), WARN_RIM_MODULES * profile.module, float(profile.module),
                                   (Problem("machine.shafts", "hub_not_mounted",
                                            f"no shaft carries the {profile.name} gear: it is "
                                            "drawn without a bore"),)))
            continue
        options = dict(key=mount.key, flat_depth=mount.flat_depth,
                       bore_allowance=mount.bore_allowance, key_slot_allowance=key_slot_allowance,
                       segments=segments)
        centre = np.asarray(profile.centre, dtype=float)
        # the keyway direction is chosen about the rotation centre, in the body frame
        angle = best_keyway_angle(profile.outline - centre,
                                  lambda turn: hub_hole(mount.hub_bore, angle=turn, **options))
        hole = hub_hole(mount.hub_bore, angle=angle, **options) + centre
        # the keyway's direction rides on the profile: the shaft's keyseat goes under it
        holed = dataclasses.replace(profile, hole=hole,
                                    bore_radius=(mount.hub_bore + mount.bore_allowance) / 2,
                                    notes={**profile.notes, "keyway_angle_rad": float(angle)})
        bored[profile.name] = holed
        check = rim_check(holed, hole, path=f"machine.shafts.{shaft.name}")
        screw = screws.get(profile.name)
        if screw is not None and mount.key is not None:
            proud = -set_screw_clearance(holed, shaft, mount.key, screw)
            if proud > 0.0:   # its head among the mating teeth
                check = dataclasses.replace(check, passed=False, problems=check.problems + (
                    Problem(f"machine.shafts.{shaft.name}", "set_screw_proud",
                            f"the {profile.name} gear's {screw} stands {proud:.2f} mm proud of "
                            "the gear on its keyway's line, into the mating teeth: use a "
                            "larger gear or a smaller shaft"),))
        checks.append(check)
    stages = []
    for stage in train.stages:
        profiles = tuple(bored.get(p.name, p) for p in stage.generated.profiles)
        stages.append(dataclasses.replace(
            stage, generated=dataclasses.replace(stage.generated, profiles=profiles)))
    return dataclasses.replace(train, stages=tuple(stages)), tuple(checks)


# --------------------------------------------------------------------------- the cut outline


@dataclass(frozen=True)
class CuttingOutline:
    """A gear's outline as cut, in its body frame (see :func:`cutting_outline`).

    Attributes
    ----------
    outline : (n, 2) float
        Thinned, counter-clockwise, the first point not repeated; read-only.
    tolerance_used : float
        mm, every point of the dense outline lies within this of ``outline`` (``0.0``: the
        dense outline kept as is).
    pitch : (m, 2) float
        The pitch curve thinned to the same tolerance; read-only.
    """

    outline: np.ndarray
    tolerance_used: float
    pitch: np.ndarray


def cutting_outline(profile, chord_tolerance: float) -> CuttingOutline:
    """The outline ``profile`` is cut along: thinned to ``chord_tolerance`` (mm) by
    :func:`cadgen.geometry.contour.thin_outline`, simple and clear of the disc of the hole's
    reach (``profile.hole_reach``), and its pitch curve thinned likewise.

    Computed once per profile and tolerance (remembered on the profile, see
    :meth:`~cadgen.gears.teeth.GearProfile.derived`): the solid, the gear's DXF file and the
    train sheet all draw this one. The tolerance must be finite and > 0 (the DXF writer
    checks it and names it).
    """
    tolerance = float(chord_tolerance)

    def compute():
        from cadgen.geometry.contour import closed_points, thin_outline, thin_ring

        reach = float(getattr(profile, "hole_reach", profile.bore_radius))
        outline, used = thin_outline(closed_points(profile.outline), tolerance, profile.centre,
                                     reach)
        pitch, _ = thin_ring(closed_points(profile.pitch_curve), tolerance)
        for array in (outline, pitch):
            array.setflags(write=False)   # shared by every stage that asks
        return CuttingOutline(outline, used, pitch)

    derived = getattr(profile, "derived", None)
    return derived(("cutting outline", tolerance), compute) if derived else compute()
