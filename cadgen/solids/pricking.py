"""The pricking mechanism's solids: gears, gear case, rocker, needle, and the inclined ground.

Frames: the mechanism plane is z = 0 (x forward, y up in the plane). The carrier
angle of a pose is the carrier's turn since the outer dead centre (the gears'
start position), in the carrier's sense. Bodies:

``case``
    The gear case (a split housing round the sun, the intermediate pair and the
    planet: ``gear-case-base`` and ``gear-case-cover``, and the shafts
    ``shaft-sun``, ``shaft-intermediate``, ``shaft-planet``) turning with the
    carrier about O; origin O, at the start pose equal to the world.
``planet``
    Origin B, x along the rocker: the rocker (l1, from B) and the needle (l2,
    perpendicular to it at the rocker's end, its tip at D).
``ground``
    The soil slab with its surface at the mechanism plane's surface line
    (``y_min + depth / cos(theta)``) for the file's first inclination, tilted by
    theta about the travel direction, as the inclined mechanism plane sees it.

Each gear rides on the case and turns by the pair's rotation at the pose; the sun
is fixed in the world (it turns backwards relative to the case).

Axial stack: the case's cavity (stage 1 layer, then stage 2 layer; end walls,
cavity height, layers and parting plane from the drivetrain's
:class:`~cadgen.machine.model.HousingStack`), the rocker ``gap`` above the case's
roof, and the needle beside the rocker.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.solids.parts import Part, gear_solid, placed_assembly, planar_transform

__all__ = ["pricking_assembly", "GEARLESS_KINDS"]

#: Part kinds built the same with or without the gears (see
#: :data:`cadgen.solids.planting.GEARLESS_KINDS`). Not the gear case: it is drawn round the
#: gears' own outlines (without them, round a coarser and larger envelope), so its sweep
#: waits for the gears; nor the ground, whose length reaches past the largest of those
#: discs (a build of solids without sweeps once took the gearless ground's mesh).
GEARLESS_KINDS = frozenset({"rocker", "needle"})


def _carrier_angle(design, angle):
    """Carrier angle ``phi1`` after the carrier turned by ``angle``: ``(phi1 in its first turn,
    phi1)``."""
    motion = design.motion
    turns, rest = divmod(float(angle), 2 * math.pi)
    phi1 = motion.phi1_start + motion.sense * rest
    return phi1, phi1 + motion.sense * 2 * math.pi * turns


def _pose_parameters(design, angle):
    """Curve parameter ``v`` and carrier angle ``phi1`` after the carrier turned by ``angle``."""
    first, phi1 = _carrier_angle(design, angle)
    return float(design.motion.invert(np.array([first]))[0]), phi1


def pricking_assembly(params, design, train, field, *, drivetrain=None, soil: bool = True):
    """Every solid of the pricking mechanism and the poses of their bodies.

    ``field`` is the list of :class:`~kinematics.pricking_field.InclinationResult`;
    the ground uses the first (``soil`` False, a bench run: no ground). ``drivetrain`` is
    the design's :class:`~cadgen.machine.model.Drivetrain`; None computes it
    (:func:`cadgen.machine.drivetrain.drivetrain`). Returns ``(assembly,
    {"gear-case": SplitHousing})``.
    """
    from kinematics.pricking_field import needle_geometry

    from cadgen.assembly.machine import pricking_model

    from cadgen.solids.housings import ShellSize
    from dataclasses import replace

    from cadgen.solids.case_drive import case_drive_parts, sprocket_tapped_holes
    from cadgen.solids.machine_parts import (printed_housing_parts, shaft_part, spacer_parts,
                                             stack_housing)

    if drivetrain is None:
        from cadgen.machine.drivetrain import drivetrain as compute_drivetrain

        drivetrain = compute_drivetrain(params, design)
    stack = drivetrain.stacks["gear-case"]

    segments = params.solids.segments_per_circle
    link = design.linkage
    centre = np.asarray(link.centre, dtype=float)
    motion = design.motion
    needle = needle_geometry(design)
    housing = params.housing
    gap = housing.axial_gap
    start = motion.phi1_start
    poses = {}

    def pose_of(angle):
        # the inverse kinematics is a bisection: solve each pose once for every part
        if angle not in poses:
            poses[angle] = _pose_parameters(design, angle)
        return poses[angle]

    def prepare(angles):
        # one vectorised inverse for many poses (the same values the scalar solve gives)
        fresh = [float(a) for a in angles if float(a) not in poses]
        if fresh:
            first, phi1 = np.array([_carrier_angle(design, a) for a in fresh]).T
            for angle, v, p in zip(fresh, motion.invert(first), phi1):
                poses[angle] = (float(v), float(p))

    def carrier_pose(angle):
        # the case turns with the carrier: no inverse solve (the planet's pose needs one)
        _, phi1 = _carrier_angle(design, angle)
        return planar_transform(phi1 - start, centre) @ planar_transform(0.0, -centre)

    def planet_pose(angle):
        v, phi1 = pose_of(angle)
        B = centre + 2 * link.a * np.array([math.cos(phi1), math.sin(phi1)])
        tip = motion.tip(np.array([v]))[0]
        axis = float(needle.axis_angle(motion.phi2(np.array([v]))[0]))
        root = tip - needle.needle * np.array([math.cos(axis), math.sin(axis)])
        rocker = math.atan2(root[1] - B[1], root[0] - B[0])
        return planar_transform(rocker, B)

    def body_pose(body, angle):
        if body == "case":
            return carrier_pose(angle)
        if body == "planet":
            return planet_pose(angle)
        return np.eye(4)

    module = max(design.modules)
    clearance, wall = housing.clearance_for(module), housing.wall_for(module)
    faces = [params.gears.face_width_for(m) for m in design.modules]
    layers = [z for z, _ in stack.layers]
    parts, discs, frames = [], {}, {}
    if train is not None and train.stages:
        from cadgen.gears.trains import _placements

        stage_of = {}
        for index, stage in enumerate(train.stages):
            for name in stage.generated.pair.names:
                stage_of.setdefault(name, index)
        for profile, _, at_start in _placements(train):
            index = stage_of[profile.name]
            stage = train.stages[index]
            which = stage.generated.pair.names.index(profile.name)
            offset = np.asarray(at_start) - centre
            radius = float(np.max(np.linalg.norm(profile.outline - np.asarray(profile.centre),
                                                 axis=1)))
            key = round(float(np.hypot(*offset)), 6)
            discs[key] = max(discs.get(key, 0.0), radius)

            def local(angle, stage=stage, which=which, at=centre + offset, z=layers[index]):
                # in the case's frame the line of centres stays where it was at the start, so
                # a gear sits where it started, turned by the pair's rotation at the pose
                v, _ = pose_of(angle)
                tau = motion.cycle(np.array([v]))   # the pairs' cycle starts at the Rmax dead centre
                turn = float(stage.generated.pair.rotations(tau)[which][0])
                return planar_transform(stage.placement[0] + turn, at, z)

            solid, outline = gear_solid(profile, faces[index], segments, path="gears.face_width",
                                        chord_tolerance=params.gears.chord_tolerance)
            parts.append(Part(profile.file_stem, "gear", "case", solid, local, outline=outline))
            frames[profile.name] = (local, float(profile.notes.get("keyway_angle_rad", 0.0)))
    # the case: round the discs the gears sweep at O, A and B (2a from O)
    line = np.array([math.cos(start), math.sin(start)])
    if not discs:   # no gears generated: a coarse envelope, each gear within the centre distance
        discs = {0.0: link.a, round(link.a, 6): link.a, round(2 * link.a, 6): link.a}
    circles = [(*(centre + d * line), r) for d, r in sorted(discs.items())]
    height, floor, roof = stack.cavity_height, stack.floor_wall, stack.roof_wall
    held = drivetrain.rules.get("case_drive")   # the bracket and the case's sprocket
    tapped = sprocket_tapped_holes(held, centre, floor) if held else ()
    case = stack_housing(params, circles, ShellSize(clearance, wall, gap, module), stack,
                         drivetrain.seats("gear-case"), z_cavity_bottom=0.0, segments=segments,
                         path="housing.gear-case", tapped=tapped)
    # cut into bolted segments when printed and too big for the printer (splices kept on it)
    case_parts, joints = printed_housing_parts("gear-case", case, "case", params)
    case = replace(case, joints=tuple(joints))
    parts[:0] = case_parts
    # the shafts turn with their gears, keyseats under the gears' keyways; the planet shaft's
    # under the rocker's too (its keyway towards +x of the planet's frame, seen from the case)
    hub = drivetrain.fixings.get("rocker")
    rocker_z = height + roof + gap
    frames["rocker"] = (lambda angle: np.linalg.solve(body_pose("case", angle),
                                                      body_pose("planet", angle)), 0.0)
    retention = {r.shaft: r for r in drivetrain.retention}
    shafts = [shaft_part(shaft, case, "case", segments=segments, gears=frames,
                         hubs=(("rocker", rocker_z, rocker_z + hub["length"], hub["key"]),)
                         if hub and shaft.name == "planet" else (),
                         retention=retention.get(shaft.name))
              for shaft in drivetrain.shafts if shaft.housing == "gear-case"]
    parts += shafts
    for part, shaft in zip(shafts, (s for s in drivetrain.shafts if s.housing == "gear-case")):
        parts += spacer_parts(part, retention.get(shaft.name), case.z_cavity_bottom, segments)
    if held:
        sun = next(s for s in drivetrain.shafts if s.name == "sun")
        sun_part = next(p for p in shafts if p.name == "shaft-sun")
        parts += case_drive_parts(held, sun, sun_part, centre, floor, gap, segments)
    arm = _rocker_and_needle(params, link, needle, z0=rocker_z, segments=segments,
                             hub=hub, clamp=drivetrain.fixings.get("needle"))
    parts += arm
    if soil:
        reach = 2 * link.a + link.l + max(r for _, _, r in circles)
        # the slab spans the machine along z: from under the case to above the needle's holder
        z_top = max(float(part.solid.bounding_box()[5]) for part in arm) + wall
        parts.append(_inclined_ground(
            params, field[0], (float(centre[0] - reach), float(centre[0] + reach)),
            (-floor, z_top), segments))
    assembly = placed_assembly(parts, body_pose, pricking_model, drivetrain, train,
                               {"gear-case": case}, segments=segments)
    assembly.prepare = prepare
    return assembly, {"gear-case": case}


def _inclined_ground(params, inclination, x_range, z_range, segments):
    """The soil slab of the first inclination, tilted into the mechanism's frame."""
    from cadgen.solids.ground import ground_part

    theta = math.radians(inclination.inclination_deg)
    ground = ground_part(params.ground, inclination.surface_level * math.cos(theta), x_range,
                         z_range, ridge_centre=0.0, segments=segments)
    tilt = np.eye(4)
    c, s = math.cos(theta), math.sin(theta)
    # vertical-frame (X, Y, Z) -> mechanism frame: y = Y cos + Z sin, z = -Y sin + Z cos
    tilt[1:3, 1:3] = [[c, s], [-s, c]]
    ground.local = lambda angle, tilt=tilt: tilt
    return ground


def _rocker_and_needle(params, link, needle, *, z0, segments, hub=None, clamp=None):
    """The rocker bar from B along +x (l1) and the needle from its end, perpendicular, to D.

    With the drivetrain's fixings: the rocker's boss at B (``hub``, keyed to the planet shaft,
    up from the bar, its keyway towards +x) and the needle's holder at the bar's end (``clamp``:
    a sleeve along the needle on top of the bar, a tapped hole down through its wall for the
    set screw); the needle then runs through the holder's bore from its back face. Without
    them the needle is joined to the bar's end, as one body."""
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()

    from cadgen.solids.extrude import extrude
    from cadgen.solids.outline import hull_of_circles
    from cadgen.solids.fixing_features import keyed_boss

    linkage = params.linkage
    half = linkage.rocker_width / 2
    # the bar's own end at B stays its half width: the hub's boss (wider) stands round it, and
    # two coincident cylinders would leave the union's walls with zero-area slivers
    rocker = extrude(hull_of_circles([(0.0, 0.0, half), (link.rocker, 0.0, half)], segments),
                     linkage.rocker_thickness, z0=z0, path="linkage.rocker_thickness",
                     outline_path="rocker outline")
    if hub:
        rocker = keyed_boss(rocker, hub, z0, segments)
    radius = linkage.needle_diameter / 2
    cone = min(3 * linkage.needle_diameter, 0.5 * link.needle)
    top = z0 + linkage.rocker_thickness
    if clamp:
        # the holder: a sleeve along the needle (y), sunk 1 mm into the bar's top so they join
        outside, width = clamp["outside"] / 2, linkage.rocker_width
        axis_z = top + outside - 1.0
        holder = _stand_along_y(m3d.Manifold.cylinder(width, outside, outside, segments),
                                width).translate((link.rocker, 0.0, axis_z))
        bore = _stand_along_y(m3d.Manifold.cylinder(width + 2.0, clamp["bore"] / 2,
                                                    clamp["bore"] / 2, segments),
                              width + 2.0).translate((link.rocker, 0.0, axis_z))
        tap = m3d.Manifold.cylinder(outside + 1.0, clamp["tap_drill"] / 2, clamp["tap_drill"] / 2,
                                    segments).translate((link.rocker, 0.0, axis_z))
        rocker = rocker + holder - bore - tap
        back = width / 2   # the needle enters the holder at its back face
        from cadgen.solids.bought_places import set_screw_item

        bought = (set_screw_item(clamp, link.rocker, axis_z, ("needle",)),)
    else:
        axis_z, back, bought = z0 + linkage.rocker_thickness / 2, 0.0, ()
    length = link.needle + back
    shaft = m3d.Manifold.cylinder(length - cone, radius, radius, segments)
    point = m3d.Manifold.cylinder(cone, radius, 0.0, segments).translate((0, 0, length - cone))
    # built along +z from its back end; turn +z onto the needle's direction in the plane (+-y),
    # its back end behind the rocker's end by ``back``
    body = (shaft + point).rotate((-90.0 * needle.side, 0.0, 0.0))
    body = body.translate((link.rocker, -needle.side * back, axis_z))
    return [Part("rocker", "rocker", "planet", rocker, bought=bought),
            Part("needle", "needle", "planet", body)]


def _stand_along_y(solid, length: float):
    """A solid built along +z from 0 to ``length``, turned to run along y, centred on y = 0."""
    return solid.rotate((-90.0, 0.0, 0.0)).translate((0.0, -length / 2, 0.0))
