"""The planting mechanism's solids: gears, gearbox 1, gearbox 2, cam, planter shell, blades, ground.

Frames. The mechanism plane is z = 0 of the world (x forward, y up), z towards the arms. Bodies and
their poses at carrier angle ``phi`` (arm 2 is arm 1 at ``phi + pi``):

``frame``
    Fixed: the frame (the transmission box) and its input shaft and gears.
``carrier1``
    Gearbox 1 and train 1's gears (both sets), with shafts O and S seen from it:
    turns by ``-phi`` about O (clockwise). Side 2 of the carrier is side 1's parts
    turned half a turn about O (``carrier1:mirrored``).
``gearbox2``
    Origin at C, x along C->D->E (``gamma = phic + phi``): the housing, the four
    gears of the second train, and the cam (fixed to gearbox 2, coaxial with E).
``planter``
    Origin at E, x along ``u(Psi)``: the arm plate E-P1, the duckbill tube, the
    two blades and the linkage that opens them (lever, push rod, links), each moved by
    the cam's law at the pose.
``ground``
    Fixed: the soil (flat or a ridge along the travel), its top at the soil level.

Axial stack (z, from the machine outwards): gearbox 1 (train 1's gears), gearbox 2 (layer 1: the
non-circular pair; layer 2: the 1:1 circular pair), the cam plate (the duckbill's roller in it),
the duckbill lever's layer, the planter's arm plate, and the duckbill tube beside it. Every gap
between them is ``housing.axial_gap``; the housings' end walls, cavity heights, gear layers and
parting planes are the drivetrain's (:class:`~cadgen.machine.model.HousingStack`, end walls thick
enough for the bearing seats). The housings' outlines are the hull of the same envelope discs the
kinematic clearance checks use (largest tip + clearance + wall), so both checks see one housing.

Each housing is split at its parting plane into a base and a cover
(:mod:`cadgen.solids.split_housing`) with the bearing seats bored in its end walls; each shaft is a
part of its housing's body (:mod:`cadgen.solids.machine_parts`).

Each part is built once, in its body's frame; which copies exist (per arm, per side of carrier 1)
and where they ride is the assembly model's to say (:mod:`cadgen.assembly.machine`,
:func:`~cadgen.solids.parts.placed_assembly`). The duckbill linkage (lever, push rod, links, the
blades' knuckles and cranks, the shell's lug, web and hinge ears) is
:mod:`cadgen.solids.duckbill`'s, cut to the sizes the drivetrain gave it (``fixings["duckbill"]``).
The bought items (bearings, keys, screws, nuts, washers, dowels, the linkage's pins, roller and
spring: on the model's joints, in the bill) are placed as solids by the parts that hold them
(:mod:`cadgen.solids.bought`; the linkage's: :mod:`cadgen.solids.duckbill_items`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cadgen.machine.fastening import bolt_circle
from cadgen.solids.fixing_features import (cam_bore_radius, cam_screw_holes, floor_holes,
                                           keyed_boss, mounting_holes)
from cadgen.solids.parts import Part, gear_solid, placed_assembly, planar_transform

__all__ = ["PlantingLayout", "planting_assembly", "cam_bore_radius", "GEARLESS_KINDS"]

#: Part kinds built the same with or without the gears: the housings come from the
#: drivetrain's stacks, not from the gears' outlines. Not the gears, not the shafts (each
#: keyseat turns to its gear's keyway). A build sweeps the gearless assembly beside the teeth
#: and takes these parts' meshes from it (:mod:`cadgen.pipeline.beside`).
GEARLESS_KINDS = frozenset({"housing", "planter", "blade", "cam", "ground", "lever", "push-rod",
                            "link"})


@dataclass(frozen=True)
class PlantingLayout:
    """Axial positions (mm) of the planting mechanism's layers, and its gear face widths."""

    face_nc: float          # non-circular gears
    face_c: float           # circular gears
    gap: float
    box1_floor: float       # cavity floors
    box1_height: float
    box1_wall: float
    box2_floor: float
    box2_height: float
    box2_wall: float
    cam_bottom: float
    cam_thickness: float
    arm_bottom: float
    arm_thickness: float
    tube_axis: float        # z of the duckbill tube's axis
    tube_radius: float      # outer
    box1_floor_wall: float          # end walls: as thick as their deepest bearing seat
    box1_roof_wall: float
    box2_floor_wall: float
    box2_roof_wall: float
    box1_layers: tuple              # absolute z of each gear layer's bottom
    box2_layers: tuple
    frame_floor: float = 0.0        # the frame's (transmission box's) cavity floor
    frame_layers: tuple = ()        # its two gear layers' bottoms (the drive's pairs)
    lever_bottom: float | None = None   # the duckbill lever's lower face (None: no cam, no lever)

    @property
    def layer0(self) -> float:
        """Bottom of gearbox 1's gear layer (train 1)."""
        return self.box1_layers[0]

    @property
    def layer1(self) -> float:
        """Bottom of gearbox 2's first gear layer (the non-circular pair)."""
        return self.box2_layers[0]

    @property
    def layer2(self) -> float:
        """Bottom of gearbox 2's second gear layer (the 1:1 pair)."""
        return self.box2_layers[1]

    @property
    def z_range(self) -> tuple:
        low = self.box1_floor - self.box1_floor_wall
        if self.frame_layers:   # the frame below gearbox 1 (its floor wall: 2 x its seats, say)
            low = min(low, self.frame_floor - 40.0)
        return (low, self.tube_axis + self.tube_radius)


def layout_of(params, mechanism, shells, cam_design, drivetrain) -> PlantingLayout:
    """The axial stack from the drivetrain's housing stacks: end walls, cavities, gear layers.

    Gearbox 1's cavity floor is at z = 0; gearbox 2's floor wall starts above gearbox 1's
    roof's outer face (the carrying flange between, a gap each side); the cam is seated on
    gearbox 2's roof (screwed to it), the planter's plate ``gap`` above the cam.
    """
    gap = params.housing.axial_gap
    face_nc = params.gears.face_width_for(mechanism.module(params.pitch_curve.teeth))
    face_c = params.gears.face_width_for(shells["gearbox1"].module)
    w1, w2 = shells["gearbox1"].wall, shells["gearbox2"].wall
    stack1, stack2 = drivetrain.stacks["gearbox1"], drivetrain.stacks["gearbox2"]
    walls = (stack1.floor_wall, stack1.roof_wall, stack2.floor_wall, stack2.roof_wall)
    box1_height, box2_height = stack1.cavity_height, stack2.cavity_height
    box2_floor = drivetrain.bases.get("gearbox2", box1_height + walls[1] + gap + walls[2])
    cam_bottom = box2_floor + box2_height + walls[3]
    cam_thickness = params.cam.thickness if cam_design is not None else 0.0
    # the duckbill's lever turns a gap above the cam, the planter's plate a gap above the lever
    lever = params.cam.lever_layer(gap) if cam_design is not None else 0.0
    arm_bottom = cam_bottom + cam_thickness + gap + lever
    arm_thickness = params.planter.arm_thickness
    tube_radius = _tube_radius(params, cam_design)
    # the tube stands beside the arm plate, overlapping it by one shell wall so they join
    tube_axis = arm_bottom + arm_thickness + tube_radius - params.planter.shell_wall
    layers1 = tuple(z for z, _ in stack1.layers)
    layers2 = tuple(box2_floor + z for z, _ in stack2.layers)
    frame = drivetrain.stacks.get("frame")
    frame_floor = drivetrain.bases.get("frame", 0.0)
    frame_layers = tuple(frame_floor + z for z, _ in frame.layers) if frame is not None else ()
    return PlantingLayout(face_nc, face_c, gap, 0.0, box1_height, w1, box2_floor, box2_height, w2,
                          cam_bottom, cam_thickness, arm_bottom, arm_thickness, tube_axis,
                          tube_radius, *walls, layers1, layers2, frame_floor, frame_layers,
                          cam_bottom + cam_thickness + gap if cam_design is not None else None)


def _tube_radius(params, cam_design) -> float:
    """Outer radius of the duckbill tube: round the blade hinges plus the shell wall."""
    if cam_design is not None:
        hinge = cam_design.linkage.hinge_offset
    else:
        hinge = params.cam.duckbill.blade_length * math.sin(params.cam.closed_half_angle_rad)
    return hinge + params.planter.shell_wall


# ------------------------------------------------------------------ bodies
def body_poses(mechanism, layout):
    """``(body, phi) -> 4x4`` world transform of each body at carrier angle ``phi``."""

    def pose(body, phi):
        if body in ("carrier1", "ground", "frame"):
            return planar_transform(-phi if body == "carrier1" else 0.0)
        phi_array = np.array([phi])
        if body == "gearbox2":
            centre = mechanism.positions(phi_array, points=("C",))["C"][0]
            return planar_transform(mechanism.phic + phi, centre)
        if body == "planter":
            hub = mechanism.positions(phi_array, points=("E",))["E"][0]
            return planar_transform(float(mechanism.attitude(phi_array)[0]), hub)
        raise KeyError(f"unknown body {body!r}")

    return pose


# ------------------------------------------------------------------ parts
def _gear_parts(params, mechanism, train, layout, segments):
    """Every gear of both trains, in its body, turning with the carrier angle: ``(parts,
    frames)``, ``frames`` each gear's ``{body: (placement, keyway angle)}`` for its shaft's
    keyseat, in its own body and (a gearbox-2 gear) in carrier 1's (:func:`_in_carrier`)."""
    from cadgen.gears.trains import _placements

    from cadgen.gears.circular import TRAIN1_SETS, train1_set_radii

    n = mechanism.n
    F = mechanism.intermediate_rotation
    # each gear's rotation relative to its body, from the catching pose (rad): gearbox 2 turns
    # by +phi, carrier 1 by -phi, the suns and the central shaft's gear by -n phi (absolute)
    relative = {
        "central": lambda phi: -phi,
        "intermediate": lambda phi: float(F(phi)),
        "gear D": lambda phi: float(F(phi)),
        "planet gear E": lambda phi: -float(F(phi)),
        "central shaft gear": lambda phi: -(n - 1) * phi,
        "transmission driven gear": lambda phi: 0.0,
    }
    z_of = {"central": layout.layer1, "intermediate": layout.layer1,
            "gear D": layout.layer2, "planet gear E": layout.layer2}
    for layer, (key, _, _, names) in zip((1, 0), TRAIN1_SETS):   # set I below, set II above
        radii = train1_set_radii(mechanism, key)
        for k, name in enumerate(names):
            # the sun turns at -(n - 1) phi in the carrier; each mesh reverses the sense:
            # idler A +, idler B -, planet + (set II's +2 phi: -phi + 2 phi = +phi, gearbox 2's
            # turn; set I's +phi: it stays still), each times r_sun / r
            sign = -1.0 if k % 2 == 0 else 1.0
            ratio = radii[0] / radii[k]
            relative[name] = lambda phi, sign=sign, ratio=ratio: sign * (n - 1) * phi * ratio
            z_of[name] = layout.box1_layers[layer]
    drive = getattr(train, "drive", None)
    if drive is not None:
        z1, z2, z3, z4 = drive.teeth
        relative["input gear 1"] = lambda phi: n * phi * z2 / z1
        relative["input gear 2"] = lambda phi: phi * z4 / z3
        frame = layout.frame_layers
        z_of.update({"input gear 1": frame[0], "central shaft gear": frame[0],
                     "input gear 2": frame[1], "transmission driven gear": frame[1]})
    in_box2 = {"central", "intermediate", "gear D", "planet gear E"}
    on_frame = {"input gear 1", "input gear 2"}
    start = body_poses(mechanism, layout)
    parts, frames = [], {}
    for profile, angle, centre in _placements(train):
        body = ("gearbox2" if profile.name in in_box2 else
                "frame" if profile.name in on_frame else "carrier1")
        face = params.gears.face_width_for(profile.module)
        z = z_of[profile.name]
        # the gear's placement in its body at the catching pose (both from arm 1 at phi = 0)
        world = planar_transform(angle, centre, z)
        local0 = np.linalg.solve(start(body, 0.0), world)
        turn = relative[profile.name]

        def local(phi, local0=local0, turn=turn):
            return local0 @ planar_transform(turn(phi))

        solid, outline = gear_solid(profile, face, segments, path="gears.face_width",
                           chord_tolerance=params.gears.chord_tolerance)
        # its copies (per side of carrier 1, per arm) are placed by the assembly model
        parts.append(Part(profile.file_stem, "gear", body, solid, local, outline=outline))
        frames[profile.name] = _in_carrier(body, local, start, float(
            profile.notes.get("keyway_angle_rad", 0.0)))
    return parts, frames


def _in_carrier(body, local, start, keyway):
    """A gear's ``(placement, keyway)`` for the keyseat of its shaft; a gearbox-2 gear (the
    central gear, whose shaft C2 rides on carrier 1) also as seen from carrier 1's body, on
    side 1 (arm 1's gearbox 2) and on side 2 (``carrier1:mirrored``, arm 2's, half a carrier
    turn on): ``{"gearbox2": ..., "carrier1": ..., "carrier1:mirrored": ...}`` by the shaft's
    body. A carrier-1 gear's side-2 copy is side 1's turned about O: the same placement."""
    if body == "carrier1":
        return {body: (local, keyway), "carrier1:mirrored": (local, keyway)}
    if body != "gearbox2":
        return {body: (local, keyway)}

    def seen_from_carrier(phi, local=local):
        return np.linalg.solve(start("carrier1", phi), start("gearbox2", phi) @ local(phi))

    def seen_from_side2(phi, local=local):
        # arm 2's gearbox 2 is arm 1's half a carrier turn later; side 2 is side 1 turned
        # half a turn about O at the same carrier angle
        side2 = start("carrier1", phi) @ planar_transform(math.pi)
        return np.linalg.solve(side2, start("gearbox2", phi + math.pi) @ local(phi + math.pi))

    return {"gearbox2": (local, keyway), "carrier1": (seen_from_carrier, keyway),
            "carrier1:mirrored": (seen_from_side2, keyway)}


def _frames_for(frames, body: str) -> dict:
    """Each gear's placement and keyway in ``body`` (where known): a shaft's ``gears``."""
    return {name: views[body] for name, views in (frames or {}).items() if body in views}


def _housing_parts(params, mechanism, circles, shells, layout, segments, drivetrain,
                   gears=None):
    """Both gearboxes as split housings (base and cover), and every shaft of the drivetrain."""
    from dataclasses import replace

    from cadgen.solids.machine_parts import (printed_housing_parts, shaft_part, side2_shaft,
                                             spacer_parts, stack_housing)

    a, r = mechanism.centre_distance, mechanism.r
    radius = {(c.gearbox, c.point): c.radius for c in circles}
    box2 = shells["gearbox2"]
    discs2 = [(0.0, 0.0, radius["gearbox2", "C"] - box2.envelope),
              (a, 0.0, radius["gearbox2", "D"] - box2.envelope),
              (a + 2 * r, 0.0, radius["gearbox2", "E"] - box2.envelope)]
    box1 = shells["gearbox1"]
    line = np.array([math.cos(mechanism.phi0), math.sin(mechanism.phi0)])
    carrier = mechanism.carrier_radii
    discs1 = [(0.0, 0.0, radius["gearbox1", "O"] - box1.envelope)]
    for sign in (1.0, -1.0):   # both arms hang on carrier 1
        for axis in ("A", "B", "C"):
            x, y = sign * carrier[axis] * line
            discs1.append((x, y, radius["gearbox1", axis] - box1.envelope))
    holes = floor_holes(drivetrain)
    passages1, tapped1 = holes.get("gearbox1", ((), ()))
    passages2, tapped2 = holes.get("gearbox2", ((), ()))
    screwed = drivetrain.fixings.get("cam")
    if screwed:   # the cam's screws, tapped into the cover's roof round E
        tapped2 += tuple((x, y, screwed["tap_drill"], screwed["tapped_depth"], "roof")
                         for x, y in bolt_circle(screwed, (a + 2 * r, 0.0)))
    housing1 = stack_housing(params, discs1, box1, drivetrain.stacks["gearbox1"],
                             drivetrain.seats("gearbox1"), z_cavity_bottom=layout.box1_floor,
                             segments=segments, path="housing.gearbox1", passages=passages1,
                             tapped=tapped1)
    housing2 = stack_housing(params, discs2, box2, drivetrain.stacks["gearbox2"],
                             drivetrain.seats("gearbox2"), z_cavity_bottom=layout.box2_floor,
                             segments=segments, path="housing.gearbox2", passages=passages2,
                             tapped=tapped2)
    # a printed half too big for the printer comes in bolted segments; the splices stay on
    # the housing record (the bill of materials counts their bolts)
    parts1, joints1 = printed_housing_parts("gearbox1", housing1, "carrier1", params)
    parts2, joints2 = printed_housing_parts("gearbox2", housing2, "gearbox2", params)
    housing1 = replace(housing1, joints=tuple(joints1))
    housing2 = replace(housing2, joints=tuple(joints2))
    parts = parts1 + parts2
    # one solid per shaft (side 1's, in its body's frame): the assembly model places its copies
    hub = drivetrain.fixings.get("planter")
    planter_hub = (("planter", layout.arm_bottom, layout.arm_bottom + hub["length"], hub["key"],
                    "planter-shell"),) if hub else ()
    held = {(r.shaft, r.side): r for r in drivetrain.retention}
    for shaft in drivetrain.shafts:
        if shaft.housing == "gearbox2":
            housing, body, hubs = housing2, "gearbox2", planter_hub if shaft.name == "E" else ()
        elif shaft.housing == "gearbox1" and shaft.side == 1:
            housing, body, hubs = housing1, "carrier1", ()
        else:
            continue
        stack = held.get((shaft.name, shaft.side))
        part = shaft_part(shaft, housing, body, segments=segments,
                          gears=_frames_for(gears, body), hubs=hubs, retention=stack)
        parts += [part] + spacer_parts(part, stack, housing.z_cavity_bottom, segments)
        if body == "carrier1":
            parts += side2_shaft(shaft, housing, stack, _frames_for(gears, "carrier1"),
                                 _frames_for(gears, "carrier1:mirrored"), segments)
    housings = (housing1, housing2)
    if "frame" in drivetrain.stacks:
        frame, frame_parts = _frame_parts(params, mechanism, drivetrain, layout, segments, gears)
        parts += frame_parts
        housings += (frame,)
    return parts, housings




def _frame_parts(params, mechanism, drivetrain, layout, segments, gears):
    """The frame (the transmission box): a split housing round the drive's two pairs, fixed,
    with its shafts (the central shaft O, the sleeve S carrying gearbox 1, the input)."""
    from cadgen.solids.housings import ShellSize, flange_width
    from dataclasses import replace

    from cadgen.solids.machine_parts import (printed_housing_parts, shaft_part, spacer_parts,
                                             stack_housing)

    drive = drivetrain.drive
    module = drive.module_1
    housing = params.housing
    wall = housing.wall_for(module)
    shell = ShellSize(housing.clearance_for(module), wall, housing.axial_gap, module,
                      flange_width(params, wall))
    shifts = params.gears.profile_shift.resolved()
    keys = ("input_gear_1", "central_shaft_gear", "input_gear_2", "transmission_driven_gear")
    # each gear's tip: one module, grown by a positive profile shift
    tip = [r + module * (1.0 + max(shifts.get(key, 0.0), 0.0))
           for r, key in zip(drive.radii, keys)]
    discs = [(0.0, 0.0, max(tip[1], tip[3])), (-drive.centre_distance, 0.0, max(tip[0], tip[2]))]
    seats = drivetrain.seats("frame")
    floor = drivetrain.stacks["frame"].floor_wall
    frame = stack_housing(params, discs, shell, drivetrain.stacks["frame"], seats,
                          z_cavity_bottom=layout.frame_floor, segments=segments,
                          path="housing.frame",
                          tapped=mounting_holes(discs, shell, seats, floor, segments))
    # printed: cut into bolted segments when too big for the printer, like the gearboxes
    parts, joints = printed_housing_parts("frame", frame, "frame", params)
    frame = replace(frame, joints=tuple(joints))
    for shaft in drivetrain.shafts:
        if shaft.housing != "frame":
            continue
        body = "frame" if shaft.name == "input" else "carrier1"
        stack = next((r for r in drivetrain.retention if r.shaft == shaft.name), None)
        part = shaft_part(shaft, frame, body, segments=segments, gears=_frames_for(gears, body),
                          retention=stack)
        parts += [part] + spacer_parts(part, stack, frame.z_cavity_bottom, segments)
    return frame, parts


def _cam_part(params, mechanism, cam_design, layout, segments, drivetrain=None):
    from cadgen.geometry.contour import thinned_contour
    from cadgen.solids.extrude import extrude
    from cadgen.solids.outline import circle

    points = params.cam.profile_points
    bore = cam_bore_radius(params, drivetrain)
    # the cam's frame is the planter's at the catching pose; it is fixed to gearbox 2 at E
    a, r = mechanism.centre_distance, mechanism.r
    turn = float(mechanism.attitude(np.array([0.0]))[0]) - mechanism.phic
    local0 = planar_transform(turn, (a + 2 * r, 0.0))
    screws = cam_screw_holes(drivetrain, turn)
    holes = [circle(bore, segments)] if bore > 0 else []
    holes += [circle(radius, segments, centre) for centre, radius in screws]
    # the contour cam.dxf holds, so the STL and the cutting file describe the same cam
    contour = thinned_contour(cam_design.profile.working_profile(points),
                              params.gears.chord_tolerance, bore_radius=bore)
    thickness = params.cam.thickness
    solid = extrude(contour, thickness, holes=holes,
                    z0=layout.cam_bottom, path="cam.thickness", outline_path="cam contour")
    screwed = drivetrain.fixings.get("cam") if drivetrain is not None else None
    bought = ()
    if screwed:   # the screws' heads sunk in counterbores: the planter turns just above
        from cadgen.solids.bought_places import tapped_screws
        from cadgen.solids.extrude import manifold3d_engine

        m3d = manifold3d_engine()
        depth, radius = screwed["counterbore_depth"], screwed["counterbore_diameter"] / 2
        floor = layout.cam_bottom + thickness - depth   # the counterbores' floor: the heads'
        for centre, _ in screws:
            solid = solid - m3d.Manifold.cylinder(depth + 1.0, radius, radius, segments).translate(
                (centre[0], centre[1], floor))
        # the screws on that floor, down into the cover roof's tapped holes
        bought = tuple(tapped_screws(screwed["bolt"], screwed["screw_length"],
                                     [centre for centre, _ in screws], floor, up=False,
                                     fitted=("gearbox2-cover",)))
    return Part("cam", "cam", "gearbox2", solid, lambda phi: local0, outline=contour,
                bought=bought)


def _planter_parts(params, cam_design, layout, segments, hub=None, duckbill=None):
    """The planter shell (arm plate E-P1 and the duckbill tube) and the two blades; with the
    linkage's sizes (``duckbill``, the drivetrain's ``fixings["duckbill"]``) and the cam, the
    lever, push rod and links too, and the lugs, web and hinges they need on the shell and the
    blades (:mod:`cadgen.solids.duckbill`).

    ``hub`` (:func:`cadgen.machine.fixings.keyed_hub`, the drivetrain's ``fixings["planter"]``):
    the plate's boss at E, up from the plate, and its bore with the keyway (towards the
    planter's +x, where shaft E's keyseat is cut to meet it).
    """
    from cadgen.solids.extrude import extrude, manifold3d_engine
    from cadgen.solids.outline import hull_of_circles

    m3d = manifold3d_engine()

    planter = params.planter
    L1, L2, wall = planter.L1, planter.L2, planter.shell_wall
    half = planter.arm_width / 2
    plate = extrude(hull_of_circles([(0.0, 0.0, half), (-L1, 0.0, half)], segments),
                    layout.arm_thickness, z0=layout.arm_bottom, path="planter.arm_thickness",
                    outline_path="planter arm plate")
    if hub:
        plate = keyed_boss(plate, hub, layout.arm_bottom, segments)
    if cam_design is not None:
        linkage = cam_design.linkage
        lb, d0, hinge = linkage.blade_length, linkage.closed_half_angle, linkage.hinge
    else:
        lb, d0 = params.cam.duckbill.blade_length, params.cam.closed_half_angle_rad
        hinge = np.array([-L1 + lb * math.sin(d0), -L2 + lb * math.cos(d0)])
    e, hinge_y = float(hinge[0] + L1), float(hinge[1])
    outer = layout.tube_radius
    # the tube: from the blade hinges up to P1, along the planter's y axis
    tube_length = -hinge_y
    tube = (m3d.Manifold.cylinder(tube_length, outer, outer, segments)
            - m3d.Manifold.cylinder(tube_length, outer - wall, outer - wall, segments))
    # built along +z, stood up along +y (a turn of -90 deg about x)
    tube = tube.rotate((-90.0, 0.0, 0.0)).translate((-L1, hinge_y, layout.tube_axis))
    shell = plate + tube
    # the duckbill: a cone shell from the hinge circle (radius e) down to the tip N, split in halves
    height = lb * math.cos(d0)
    cone = m3d.Manifold.cylinder(height, 0.0, e + wall, segments)
    inner = m3d.Manifold.cylinder(height, 0.0, e, segments).translate((0.0, 0.0, wall / math.sin(d0)))
    cone = (cone - inner).rotate((-90.0, 0.0, 0.0)).translate((-L1, -L2, layout.tube_axis))
    beyond_axis = m3d.Manifold.cube((outer * 4, L2 * 2, outer * 4)).translate(
        (-L1, -2 * L2, layout.tube_axis - 2 * outer))
    right, left = cone ^ beyond_axis, cone - beyond_axis
    opening = cam_design.profile if cam_design is not None else None

    def blade_local(sign):
        def local(phi, pivot=np.array([-L1 + sign * e, hinge_y])):   # about its hinge
            if opening is None:
                return np.eye(4)
            lam = opening.program(np.array([float(cam_design.cam_angle(phi))]))[0]
            beta = float(cam_design.linkage.opening_of_lever(lam)[0])
            # a blade turns about its hinge axis (along z): the right one counter-clockwise
            turn = planar_transform(sign * beta)
            return (planar_transform(0.0, pivot) @ turn @ planar_transform(0.0, -pivot))
        return local

    linkage, items = [], {}
    if duckbill is not None and cam_design is not None and layout.lever_bottom is not None:
        from cadgen.solids.duckbill import blade_features, linkage_parts, shell_features
        from cadgen.solids.duckbill_items import linkage_items

        shell = shell_features(shell, duckbill, layout, segments)
        right = blade_features(right, "right", duckbill, layout, segments)
        left = blade_features(left, "left", duckbill, layout, segments)
        linkage = linkage_parts(duckbill, layout, cam_design, segments)
        items = linkage_items(duckbill, layout)   # its pins, roller and spring, by host
    parts = [Part("planter-shell", "planter", "planter", shell),
             Part("blade-right", "blade", "planter", right, blade_local(1.0)),
             Part("blade-left", "blade", "planter", left, blade_local(-1.0))] + linkage
    for part in parts:
        part.bought += tuple(items.get(part.name, ()))
    return parts


def mechanism_extent(mechanism, circles, steps: int = 360) -> tuple:
    """x range (mm) the mechanism sweeps over a revolution: points of both arms plus envelopes."""
    phi = np.linspace(0.0, 2 * np.pi, steps, endpoint=False)
    reach = max(c.radius for c in circles)
    xs = []
    for arm in (0, 1):
        positions = mechanism.positions(phi, arm=arm)
        xs += [p[:, 0] for p in positions.values()]
    xs = np.concatenate(xs)
    return float(xs.min() - reach), float(xs.max() + reach)


def planting_assembly(params, mechanism, train, cam_design, soil_level: float | None, *,
                      drivetrain=None) -> tuple:
    """Every solid of the planting mechanism and the poses of their bodies.

    ``soil_level`` places the ground's surface; None (a bench run, no soil) makes no ground.
    ``drivetrain`` is the mechanism's :class:`~cadgen.machine.model.Drivetrain`
    (shafts, seats, housing stacks); None computes it
    (:func:`cadgen.machine.drivetrain.drivetrain`). Returns ``(assembly, housings,
    layout)``; ``housings`` are the :class:`~cadgen.solids.split_housing.SplitHousing`
    records of gearbox 1 and gearbox 2 (for the enclosure checks: parts
    ``gearbox1-base``, ``gearbox1-cover``, ``gearbox2-base``, ``gearbox2-cover``; or, a
    printed housing too big for the printer, ``gearbox1-base-1``, ... with the splices in
    the record's ``joints``).
    """
    from cadgen.assembly.machine import planting_model
    from cadgen.solids.housings import housing_circles, planting_shells
    from cadgen.solids.ground import ground_part

    if drivetrain is None:
        from cadgen.machine.drivetrain import drivetrain as compute_drivetrain

        drivetrain = compute_drivetrain(params, mechanism)
    cut_for = getattr(train, "drive", None)
    if cut_for is not None and drivetrain.drive is not None and cut_for != drivetrain.drive:
        raise ValueError("the gear train was cut for another drive than the drivetrain's (its "
                         f"teeth {cut_for.teeth}, the drivetrain's {drivetrain.drive.teeth}): "
                         "cut it with planting_train(..., drive=drivetrain.drive)")
    segments = params.solids.segments_per_circle
    shells = planting_shells(params, mechanism)
    circles = housing_circles(params, mechanism)
    layout = layout_of(params, mechanism, shells, cam_design, drivetrain)
    gear_parts, frames = (_gear_parts(params, mechanism, train, layout, segments)
                          if train is not None and train.stages else ([], {}))
    # the planter, keyed to shaft E like planet gear E: its keyway (+x in its frame) seen from
    # gearbox 2, where E's keyseat is cut
    start = body_poses(mechanism, layout)
    frames["planter"] = {"gearbox2": (lambda phi: np.linalg.solve(start("gearbox2", phi),
                                                                 start("planter", phi)), 0.0)}
    # the shafts turn with their gears, keyseats under the gears' keyways
    housing_parts, housings = _housing_parts(params, mechanism, circles, shells, layout, segments,
                                             drivetrain, frames)
    if train is not None and train.stages:   # the gears a set screw holds: drilled, screwed
        from cadgen.solids.retention_items import set_screw_gears

        gear_parts = set_screw_gears(gear_parts, drivetrain,
                                        {p.name: p for p, _, _, _ in train.gears}, segments)
    parts = housing_parts + gear_parts
    if cam_design is not None and cam_design.cuttable:
        parts.append(_cam_part(params, mechanism, cam_design, layout, segments, drivetrain))
    parts += _planter_parts(params, cam_design, layout, segments,
                            drivetrain.fixings.get("planter"), drivetrain.fixings.get("duckbill"))
    x_range = mechanism_extent(mechanism, circles)
    z_range = layout.z_range
    if soil_level is not None:
        parts.append(ground_part(params.ground, soil_level, x_range, z_range,
                                 ridge_centre=layout.tube_axis, segments=segments))
    poses = body_poses(mechanism, layout)

    def pose(body, phi):
        if body == "carrier1:mirrored":   # train 1's gears of the second arm: half a turn about O
            return poses("carrier1", phi) @ planar_transform(math.pi)
        return poses(body, phi)

    return placed_assembly(parts, pose, planting_model, drivetrain, train,
                           dict(zip(("gearbox1", "gearbox2", "frame"), housings)),
                           segments=segments), housings, layout
