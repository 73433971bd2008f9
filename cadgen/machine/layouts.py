"""Where each axis of a mechanism is and what it carries: the layouts the drivetrain sizes.

:func:`planting_axes` and :func:`pricking_axes` give each mechanism's axes (their housing,
position, gears and loads, where a shaft leaves its housing, what it carries beyond it) and
housing cavities; :func:`planting_bases` stacks the planting housings along z (the frame,
the sleeve's flange, gearbox 1, the hollow shaft's flange, gearbox 2). Numbers only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cadgen.gears.circular import planting_modules
from cadgen.machine.loads import planting_loads, pricking_loads

__all__ = ["planting_axes", "pricking_axes", "planting_bases", "carry_flange",
           "STUB_DIAMETERS", "STUB_EXTRA", "CARRY_BOLT", "CARRY_BOLTS", "HOLLOW_WALL_MIN"]

#: A drive shaft's stub below the floor: twice its diameter for a coupling's hub, plus 20 mm to
#: reach past the frame plate it is fixed to.
STUB_DIAMETERS, STUB_EXTRA = 2.0, 20.0


@dataclass(frozen=True)
class _Axis:
    """An axis to size: where it is, what it carries, where it leaves its housing.

    ``mounts``: ``(gear, z_bottom, face_width)`` in the axis's housing, or ``(gear, z_bottom,
    face_width, housing, free)`` for a gear turning in another housing's cavity (``z_bottom``
    from that one's floor) or running ``free`` on the shaft on its own bearings.
    """

    name: str
    housing: str
    side: int
    xy: tuple
    loads: object                 # loads.AxisLoads
    mounts: tuple
    floor_through: bool
    roof_through: bool
    below: object                 # d -> mm beyond the floor's outer face
    above: float
    external_above: object        # (walls, bases) -> z of the external load (the stack's frame)
    note: str = ""
    roof_housing: str | None = None   # the upper bearing's housing (None: the axis's own)
    roof_pair: bool = False       # hollow: both bearings side by side in the housing's roof
    inside: str | None = None     # hollow: the axis that turns inside it
    carries: str | None = None    # hollow: the housing its flange is bolted to


@dataclass(frozen=True)
class _Cavity:
    side_wall: float
    height: float
    parting_z: float
    layers: tuple


def _mount_fields(mount) -> tuple:
    """``(gear, z_bottom, face, housing or None, free)`` of an axis's mount tuple."""
    gear, z, face = mount[:3]
    housing = mount[3] if len(mount) > 3 else None
    free = bool(mount[4]) if len(mount) > 4 else False
    return gear, z, face, housing, free


#: The flange a hollow shaft carries a housing with (ISO 4762 screws into tapped holes of the
#: housing's floor): its bolt, the number of bolts, its thickness in bolt diameters, and the
#: flange's radius beyond the bolt circle, in bolt diameters.
CARRY_BOLT, CARRY_BOLTS, CARRY_FLANGE_THICKNESS, CARRY_FLANGE_MARGIN = "M6", 6, 1.5, 1.25
#: Least wall (mm) of a hollow shaft round its bore, under the keyseat.
HOLLOW_WALL_MIN = 2.0


def carry_flange(outside: float) -> dict:
    """The bolted flange on a hollow shaft of ``outside`` diameter that carries a housing:
    ``CARRY_BOLTS`` screws of ``CARRY_BOLT`` on a circle 1.5 bolt diameters outside the shaft.

    The screws go in from under the flange and engage 1.5 diameters of the carried floor's
    tapped holes (at most two diameters deep, :func:`cadgen.solids.fixing_features.floor_holes`):
    the flange is as thick as the shortest standard ISO 4762 length of at least 3 diameters less
    that engagement (at least ``CARRY_FLANGE_THICKNESS`` diameters), so the screw's end stops in
    its hole, not against its bottom."""
    from cadgen.machine.catalogue import screw_length

    bolt = float(CARRY_BOLT.removeprefix("M"))
    circle = outside / 2 + 1.5 * bolt
    length = screw_length(CARRY_BOLT, (CARRY_FLANGE_THICKNESS + 1.5) * bolt)
    return {"bolt": CARRY_BOLT, "bolts": CARRY_BOLTS, "bolt_circle_radius": circle,
            "radius": circle + CARRY_FLANGE_MARGIN * bolt + bolt / 2,
            "thickness": length - 1.5 * bolt, "screw_length": length}


def planting_bases(cavities, gap: float):
    """``walls -> {housing: z of its cavity floor}`` in gearbox 1's frame: the frame (the
    transmission box) below gearbox 1, the flange of the sleeve that carries gearbox 1 between
    them; gearbox 2 above, the flange of the hollow shaft C that carries it between them. Each
    flange is screwed against the floor it carries; under it the screws' heads turn a gap clear
    of the roof below."""
    from cadgen.machine.catalogue import socket_screw

    flange = carry_flange(0.0)["thickness"]
    under = gap + socket_screw(CARRY_BOLT)["head_height"]

    def bases(walls):
        out = {"gearbox1": 0.0}
        h1 = cavities["gearbox1"].height
        out["gearbox2"] = h1 + walls["gearbox1"][1] + under + flange + walls["gearbox2"][0]
        if "frame" in cavities:
            out["frame"] = -(walls["gearbox1"][0] + under + flange + walls["frame"][1]
                             + cavities["frame"].height)
        return out
    return bases


def planting_axes(params, mechanism, drive=None) -> tuple:
    from cadgen.gears.circular import holding_set_module, planting_drive, train1_set_radii
    from kinematics.errors import DesignError

    housing, gears = params.housing, params.gears
    gap = housing.axial_gap
    module_nc, module_c = planting_modules(mechanism, params.pitch_curve.teeth,
                                           gears.circular_module)
    try:
        module_i = holding_set_module(mechanism, gears.circular_module, gears.pressure_angle_rad)
    except DesignError:   # the teeth stage refuses the set and says why; size as set II's
        module_i = module_c
    face_nc, face_c = gears.face_width_for(module_nc), gears.face_width_for(module_c)
    set_one, set_two = train1_set_radii(mechanism, "I"), train1_set_radii(mechanism, "II")
    face_i = gears.face_width_for(module_i)
    if drive is None:   # the drivetrain redesigns it round its shafts' hubs when they grow
        drive = planting_drive(mechanism, module_c, gears.circular_module,
                               params.field.carrier_speed_rpm, gears.pressure_angle_rad)
    face_d = gears.face_width_for(drive.module_1)
    # gearbox 1: set I (it holds the central gear) below, set II (it carries gearbox 2) above:
    # the planet of set II is on the hollow shaft C, set I's on the shaft C2 inside it
    box1 = face_i + face_c + 3 * gap
    layer1_2 = 2 * gap + face_i
    box2 = face_nc + face_c + 3 * gap
    layer2 = 2 * gap + face_nc
    frame_height = 2 * face_d + 3 * gap
    cavities = {
        "gearbox1": _Cavity(housing.wall_for(max(module_c, module_i)), box1, box1,
                            ((gap, face_i), (layer1_2, face_c))),
        "gearbox2": _Cavity(housing.wall_for(max(module_nc, module_c)), box2,
                            gap + face_nc + gap / 2, ((gap, face_nc), (layer2, face_c))),
        "frame": _Cavity(housing.wall_for(drive.module_1), frame_height, frame_height,
                         ((gap, face_d), (2 * gap + face_d, face_d))),
    }
    bases = planting_bases(cavities, gap)
    loads = planting_loads(mechanism, params.machine, gears.pressure_angle_rad,
                           params.field.carrier_speed_rpm, drive=drive)
    # the cam plate and, a gap above it, the duckbill's lever (its layer below the planter)
    cam = params.cam.thickness + params.cam.lever_layer(gap)
    arm = params.planter.arm_thickness
    a, r = float(mechanism.centre_distance), float(mechanism.r)
    line = (math.cos(mechanism.phi0), math.sin(mechanism.phi0))
    radii = mechanism.carrier_radii

    def planter_plane(walls, base):   # the planter plate's mid-plane above gearbox 2's roof
        # (the cam is seated on the roof, the lever turns a gap above it, the planter a gap
        # above the lever)
        return (base["gearbox2"] + box2 + walls["gearbox2"][1]) + cam + gap + arm / 2

    stub = lambda d: STUB_DIAMETERS * d + STUB_EXTRA   # noqa: E731
    none = lambda d: 0.0   # noqa: E731
    frame_layers = (gap, 2 * gap + face_d)
    input_xy = (-drive.centre_distance, 0.0)
    axes = [
        # the central shaft: in the frame's floor and gearbox 1's roof; its gear in the frame,
        # both suns in gearbox 1; it turns inside the sleeve that carries gearbox 1
        _Axis("O", "frame", 1, (0.0, 0.0), loads["O"],
              (("central shaft gear", frame_layers[0], face_d),
               ("sun I", gap, face_i, "gearbox1", False),
               ("sun", layer1_2, face_c, "gearbox1", False)),
              False, False, none, 0.0, None, "the central shaft: both suns, driven in the frame",
              roof_housing="gearbox1"),
        # the sleeve: bolted to gearbox 1's floor, the transmission driven gear keyed on it,
        # in a pair of bearings in the frame's roof
        _Axis("S", "frame", 1, (0.0, 0.0), loads["S"],
              (("transmission driven gear", frame_layers[1], face_d),),
              False, True, none, 0.0, planter_plane,
              "the sleeve: carries gearbox 1 (carrier 1), turned by the transmission driven gear",
              roof_pair=True, inside="O", carries="gearbox1"),
        _Axis("input", "frame", 1, input_xy, loads["input"],
              (("input gear 1", frame_layers[0], face_d),
               ("input gear 2", frame_layers[1], face_d)),
              True, False, stub, 0.0, None,
              "the input: a keyed end below the frame for a sprocket or coupling"),
    ]
    for side, sign in ((1, 1.0), (2, -1.0)):
        xy = {axis: (sign * radii[axis] * line[0], sign * radii[axis] * line[1])
              for axis in ("A", "B", "C")}
        for axis, two, one in (("A", "idler 1", "idler 1-I"), ("B", "idler 2", "idler 2-I")):
            # the two idlers of an axis turn at different speeds: one is keyed to the shaft,
            # the other runs free on two bearings in its hub, the one with more room under
            # its root circle for them
            index = "AB".index(axis) + 1
            free_one = (set_one[index] - 1.25 * module_i) >= (set_two[index] - 1.25 * module_c)
            mounts = ((one, gap, face_i, None, free_one), (two, layer1_2, face_c, None, not free_one))
            keyed, free = (two, one) if free_one else (one, two)
            axes.append(_Axis(axis, "gearbox1", side, xy[axis], loads[axis], mounts,
                              False, False, none, 0.0, None,
                              f"{keyed} keyed; {free} runs free on two bearings"))
        axes.append(_Axis("C2", "gearbox1", side, xy["C"], loads["C2"],
                          (("planet I", gap, face_i),
                           ("central", gap, face_nc, "gearbox2", False)),
                          False, False, none, 0.0, None,
                          "inner shaft: planet I (set I, it does not turn) holds the central gear "
                          "in gearbox 2 through the hollow shaft C", roof_housing="gearbox2"))
        axes.append(_Axis("C", "gearbox1", side, xy["C"], loads["C"],
                          (("train-1 planet", layer1_2, face_c),),
                          False, True, none, 0.0, planter_plane,
                          "hollow shaft: planet of set II; its flange carries gearbox 2",
                          roof_pair=True, inside="C2", carries="gearbox2"))
    axes += [
        _Axis("D", "gearbox2", 1, (a, 0.0), loads["D"],
              (("intermediate", gap, face_nc), ("gear D", layer2, face_c)),
              False, False, none, 0.0, None),
        _Axis("E", "gearbox2", 1, (a + 2 * r, 0.0), loads["E"],
              (("planet gear E", layer2, face_c),), False, True, none,
              cam + gap + arm, planter_plane,
              "carries the planter; the cam, fixed to gearbox 2, is bored clear of it"),
    ]
    return axes, cavities, loads, bases, drive


def pricking_axes(params, design) -> tuple:
    housing, gears = params.housing, params.gears
    gap = housing.axial_gap
    faces = [gears.face_width_for(m) for m in design.modules]
    cavity = faces[0] + faces[1] + 3 * gap
    layer2 = 2 * gap + faces[0]
    cavities = {"gear-case": _Cavity(housing.wall_for(max(design.modules)), cavity,
                                     gap + faces[0] + gap / 2,
                                     ((gap, faces[0]), (layer2, faces[1])))}
    loads = pricking_loads(design, params.machine, gears.pressure_angle_rad,
                           params.field.carrier_speed_rpm)
    link = design.linkage
    start = design.motion.phi1_start
    centre = [float(v) for v in link.centre]

    def at(distance):
        return (centre[0] + distance * math.cos(start), centre[1] + distance * math.sin(start))

    rocker = params.linkage.rocker_thickness
    axes = [
        _Axis("sun", "gear-case", 1, at(0.0), loads["sun"], (("sun", gap, faces[0]),),
              True, False, lambda d: STUB_DIAMETERS * d + STUB_EXTRA, 0.0, None,
              "fixed to the frame: the case turns about it"),
        _Axis("intermediate", "gear-case", 1, at(link.a), loads["intermediate"],
              (("intermediate 1", gap, faces[0]), ("intermediate 2", layer2, faces[1])),
              False, False, lambda d: 0.0, 0.0, None),
        _Axis("planet", "gear-case", 1, at(2 * link.a), loads["planet"],
              (("planet", layer2, faces[1]),), False, True, lambda d: 0.0, gap + rocker,
              lambda walls, base: cavity + walls["gear-case"][1] + gap + rocker / 2,
              "carries the rocker and the needle"),
    ]
    return axes, cavities, loads, (lambda walls: {"gear-case": 0.0}), None
