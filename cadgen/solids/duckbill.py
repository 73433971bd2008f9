"""The duckbill linkage's solids: lever, push rod, links, and what the shell and blades carry.

Sizes and layers are the machine design's (:mod:`cadgen.machine.duckbill`, the drivetrain's
``fixings["duckbill"]``); this module only cuts them. Every part is built at rest (closed
duckbill, lever angle 0) in the planter's frame, and its ``local(phi)`` follows the cam law
exactly as the blades do (:func:`cadgen.solids.planting._planter_parts`): the lever turns
about H by ``lambda(phi)``, the push rod slides down the duckbill axis by
``s = l_HG sin(lambda)``, each link lies from its blade's crank pin J to the rod's end P2.
So the assembly file, the animation and the sweeps see the linkage where the kinematics put
it.

What the planter shell gains (:func:`shell_features`): a lug from its plate down to H for
the lever's pin; a web across the tube that guides the push rod and seats the return spring;
a slot in the tube's wall the pin G rides up and down in; at each blade's hinge O1 two ears
(the blade's knuckle between them), the tube cut back round the knuckle and beyond the ears
for the pin's head and split pin. What each blade gains (:func:`blade_features`): the knuckle
round O1, the crank O1-J in the tube's middle plane, and room cut round the ears.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.machine.duckbill import lever_arms, stadium
from cadgen.solids.parts import Part, planar_transform

__all__ = ["linkage_parts", "shell_features", "blade_features", "lever_angle", "lever_outline",
           "LINKAGE_KINDS"]

#: The linkage's made part kinds (their materials: :mod:`cadgen.machine.fits`).
LINKAGE_KINDS = frozenset({"lever", "push-rod", "link"})


def lever_angle(cam_design, phi: float) -> float:
    """The lever's angle (rad) at carrier angle ``phi``: the cam law."""
    theta = np.array([float(cam_design.cam_angle(phi))])
    return float(cam_design.profile.program(theta)[0][0])


def _engine():
    from cadgen.solids.extrude import manifold3d_engine

    return manifold3d_engine()


def _cylinder_z(centre, radius, z0, z1, segments):
    """A cylinder along z from ``z0`` to ``z1`` on ``centre`` (x, y)."""
    m3d = _engine()
    return m3d.Manifold.cylinder(z1 - z0, radius, radius, segments).translate(
        (float(centre[0]), float(centre[1]), z0))


def _cylinder_y(x, z, radius, y0, y1, segments):
    """A cylinder along y from ``y0`` to ``y1`` on the line (x, z)."""
    m3d = _engine()
    solid = m3d.Manifold.cylinder(y1 - y0, radius, radius, segments).rotate((-90.0, 0.0, 0.0))
    return solid.translate((x, y0, z))


def _prism(outline, z0, z1, holes=(), path="duckbill"):
    from cadgen.solids.extrude import extrude

    return extrude(outline, z1 - z0, holes=list(holes), z0=z0, path=path, outline_path=path)


def _hole(centre, diameter, segments):
    from cadgen.solids.outline import circle

    return circle(diameter / 2, segments, centre)


# ------------------------------------------------------------------ the moving parts
def lever_outline(fixing, segments: int) -> np.ndarray:
    """The lever's outline at rest (planter frame): its arms H-I and H-G merged."""
    import shapely

    merged = shapely.union_all([shapely.Polygon(arm) for arm in lever_arms(fixing, segments)])
    outline = np.asarray(merged.exterior.coords, dtype=float)[:-1]
    return outline if shapely.Polygon(outline).exterior.is_ccw else outline[::-1]


def _lever(fixing, layout, cam_design, segments):
    points, lever, roller = fixing["points"], fixing["lever"], fixing["roller"]
    bottom = layout.lever_bottom
    top = bottom + lever["thickness"]
    outline = lever_outline(fixing, segments)
    holes = [_hole(points["H"], lever["hole"]["H"], segments),
             _hole(points["G"], lever["hole"]["G"], segments),
             _hole(points["I"], roller["d"], segments)]   # the roller's pin is pressed in
    solid = _prism(outline, bottom, top, holes, "cam.lever.thickness")
    # the spacer boss under I, down to the roller's inner ring (the cam's top face)
    spacer_bottom = layout.cam_bottom + roller["top"]
    solid += (_cylinder_z(points["I"], roller["spacer_radius"], spacer_bottom, bottom + 0.1,
                          segments)
              - _cylinder_z(points["I"], roller["d"] / 2, spacer_bottom - 1.0, bottom + 1.0,
                            segments))
    pivot = np.asarray(points["H"], dtype=float)

    def local(phi):
        turn = planar_transform(lever_angle(cam_design, phi))
        return planar_transform(0.0, pivot) @ turn @ planar_transform(0.0, -pivot)

    return Part("lever", "lever", "planter", solid, local, outline=outline)


def _push_rod(fixing, layout, cam_design, segments):
    """The rod on the duckbill axis: its eye at P2, round through the web, the collar at G."""
    m3d = _engine()
    points, rod = fixing["points"], fixing["rod"]
    x, z = points["P2"][0], layout.tube_axis
    p2 = points["P2"][1]
    radius = rod["diameter"] / 2
    eye_top = p2 + fixing["link"]["eye_radius"] + 0.5   # above the links' eyes
    half = rod["eye_thickness"] / 2
    eye = (m3d.Manifold.cube((rod["diameter"], eye_top - p2, rod["eye_thickness"]))
           .translate((x - radius, p2, z - half))
           + _cylinder_z((x, p2), radius, z - half, z + half, segments)
           - _cylinder_z((x, p2), rod["eye_hole"] / 2, z - half - 1, z + half + 1, segments))
    collar_bottom = rod["collar_bottom"]
    collar_top = collar_bottom + rod["collar_height"]
    shank = _cylinder_y(x, z, radius, eye_top - 0.1, collar_bottom + 0.1, segments)
    collar = _cylinder_y(x, z, rod["collar_diameter"] / 2, collar_bottom, collar_top, segments)
    g = points["G"]
    slot = stadium((g[0] - (rod["slot_length"] - rod["slot_width"]) / 2, g[1]),
                   (g[0] + (rod["slot_length"] - rod["slot_width"]) / 2, g[1]),
                   rod["slot_width"] / 2, rod["slot_width"] / 2, segments)
    reach = rod["collar_diameter"]
    solid = eye + shank + collar - _prism(slot, z - reach, z + reach)
    arm = cam_design.linkage.rod_arm

    def local(phi):
        return planar_transform(0.0, (0.0, -arm * math.sin(lever_angle(cam_design, phi))))

    footprint = np.array([[x - radius, p2 - radius], [x + radius, p2 - radius],
                          [x + radius, collar_bottom],
                          [x + rod["collar_diameter"] / 2, collar_bottom],
                          [x + rod["collar_diameter"] / 2, collar_top],
                          [x - rod["collar_diameter"] / 2, collar_top],
                          [x - rod["collar_diameter"] / 2, collar_bottom],
                          [x - radius, collar_bottom]])
    return Part("push-rod", "push-rod", "planter", solid, local, footprint=footprint)


def _link(fixing, layout, cam_design, side: str, segments):
    """A link, in its own frame (x from J to P2), on its side of the rod's eye."""
    link = fixing["link"]
    length = link["length"]
    outline = stadium((0.0, 0.0), (length, 0.0), link["eye_radius"], link["eye_radius"], segments)
    near, far = link["z"]
    z0, z1 = ((layout.tube_axis + near, layout.tube_axis + far) if side == "right"
              else (layout.tube_axis - far, layout.tube_axis - near))
    holes = [_hole((0.0, 0.0), link["hole"], segments),
             _hole((length, 0.0), link["hole"], segments)]
    solid = _prism(outline, z0, z1, holes, "cam.duckbill.blade_link")
    linkage = cam_design.linkage
    L1 = linkage.L1

    def local(phi):
        beta = float(np.atleast_1d(linkage.opening_of_lever(lever_angle(cam_design, phi)))[0])
        pin = linkage.crank_pin(beta)[0]
        if side == "left":
            pin = np.array([-2.0 * L1 - pin[0], pin[1]])
        end = np.array([-L1, float(linkage.push_rod_end(beta)[0])])
        angle = math.atan2(end[1] - pin[1], end[0] - pin[0])
        return planar_transform(angle, pin)

    return Part(f"blade-link-{side}", "link", "planter", solid, local, outline=outline)


def linkage_parts(fixing, layout, cam_design, segments: int) -> list:
    """The lever, the push rod and both links, each following the cam law (module notes)."""
    return [_lever(fixing, layout, cam_design, segments),
            _push_rod(fixing, layout, cam_design, segments),
            _link(fixing, layout, cam_design, "right", segments),
            _link(fixing, layout, cam_design, "left", segments)]


# ------------------------------------------------------------------ the shell and blades
def _hinges(fixing):
    """Each blade's hinge O1 and crank pin J at rest: ``{"right": (O1, J), "left": ...}``."""
    points, L1 = fixing["points"], fixing["L1"]
    hinge, crank = np.asarray(points["O1"]), np.asarray(points["J"])
    mirror = np.array([-1.0, 1.0])
    offset = np.array([-2.0 * L1, 0.0])
    return {"right": (hinge, crank), "left": (hinge * mirror + offset, crank * mirror + offset)}


def _pin_end_zone(fixing, centre, axis, start: float, segments):
    """Both sides' room along a hinge pin at ``centre``, from ``start`` off the tube's middle
    plane to past the ears: the blade's round the ears (from its knuckle's end), the tube's for
    the pin's head and split pin (from the ears' outer faces)."""
    hinge = fixing["hinge"]
    end = hinge["ear_from"] + hinge["ear_thickness"] + hinge["pin_end_room"]
    radius = hinge["ear_radius"] + hinge["clearance"]
    return (_cylinder_z(centre, radius, axis + start, axis + end, segments)
            + _cylinder_z(centre, radius, axis - end, axis - start, segments))


def _union(solids):
    """One solid of several (manifold3d's batch union: one pass, not one per pair)."""
    m3d = _engine()
    return m3d.Manifold.batch_boolean(list(solids), m3d.OpType.Add)


def shell_features(shell, fixing, layout, segments: int):
    """The planter shell with the lever's lug, the rod's web, the G slot and the hinge ears.

    What is added and what is cut are each gathered into one solid first, so the large shell
    meets two booleans, not one per feature."""
    points, lug = fixing["points"], fixing["lug"]
    arm_top = layout.arm_bottom + layout.arm_thickness
    h = points["H"]
    adds = [_prism(stadium(h, (h[0], 0.0), lug["radius"], lug["radius"], segments),
                   layout.arm_bottom, arm_top, path="planter.arm_thickness")]
    cuts = [_cylinder_z(h, fixing["lever"]["hole"]["H"] / 2, layout.arm_bottom - 1, arm_top + 1,
                        segments)]
    x, axis = -fixing["L1"], layout.tube_axis
    inner = _inner_radius(fixing)
    web = fixing["web"]
    # the web reaches half into the tube's wall, so the two are one solid
    web_top = web["bottom"] + web["thickness"]
    adds.append(_cylinder_y(x, axis, (inner + layout.tube_radius) / 2, web["bottom"], web_top,
                            segments)
                - _cylinder_y(x, axis, web["hole"] / 2, web["bottom"] - 1, web_top + 1, segments))
    # the slot in the tube's wall (the side towards the plate) the pin G rides in
    slot = fixing["tube_slot"]
    half, g = slot["width"] / 2, points["G"][0]
    window = stadium((g, slot["bottom"] + half), (g, slot["top"] - half), half, half, segments)
    cuts.append(_prism(window, axis - layout.tube_radius - 1.0, axis - inner + 1.0))
    hinge = fixing["hinge"]
    beyond = hinge["ear_from"] + hinge["ear_thickness"]
    for centre, _ in _hinges(fixing).values():
        ear_outline = stadium(centre, centre + np.array([0.0, hinge["ear_radius"] + 4.0]),
                              hinge["ear_radius"], hinge["ear_radius"], segments)
        # room for the knuckle, and for the pin's ends beyond the ears
        cuts.append(_cylinder_z(centre, hinge["knuckle_radius"] + hinge["clearance"],
                                axis - hinge["ear_from"], axis + hinge["ear_from"], segments))
        cuts.append(_pin_end_zone(fixing, centre, axis, beyond, segments))
        # the pin's hole through the ears and the tube's wall they stand in (the wall fills the
        # ears' holes where they overlap it: the hinge pin found it)
        cuts.append(_cylinder_z(centre, hinge["hole"] / 2, axis - beyond - 1.0,
                                axis + beyond + 1.0, segments))
        for sign in (1.0, -1.0):
            near, far = sorted((axis + sign * hinge["ear_from"], axis + sign * beyond))
            adds.append(_prism(ear_outline, near, far, [_hole(centre, hinge["hole"], segments)],
                               path="planter.shell_wall"))
    return _union([shell] + adds) - _union(cuts)


def _inner_radius(fixing) -> float:
    """The tube's inner radius: the blades' hinges stand on it."""
    return float(abs(fixing["points"]["O1"][0] + fixing["L1"]))


def blade_features(blade, side: str, fixing, layout, segments: int):
    """A blade with its knuckle at O1 and its crank O1-J (in the tube's middle plane), cut
    clear of the ears and the pin's ends."""
    hinge, crank = _hinges(fixing)[side]
    spec, axis = fixing["hinge"], layout.tube_axis
    knuckle = _cylinder_z(hinge, spec["knuckle_radius"], axis - spec["knuckle_half"],
                          axis + spec["knuckle_half"], segments)
    half = fixing["crank"]["thickness"] / 2
    lug = _prism(stadium(hinge, crank, spec["knuckle_radius"], fixing["crank"]["eye_radius"],
                         segments), axis - half, axis + half, path="cam.duckbill.blade_crank")
    blade = _union([blade - _pin_end_zone(fixing, hinge, axis, spec["knuckle_half"], segments),
                    knuckle, lug])
    return blade - _union([_cylinder_z(hinge, spec["hole"] / 2, axis - 20, axis + 20, segments),
                           _cylinder_z(crank, fixing["crank"]["hole"] / 2, axis - 5, axis + 5,
                                       segments)])
