"""The duckbill linkage as parts: the sizes of its lever, push rod, links, pins, roller and spring.

The linkage's geometry is :class:`kinematics.duckbill.DuckbillLinkage`'s (planter frame: origin
at E, x along ``u(Psi)``): lever H-I-G, roller at I, push rod on the duckbill axis with the pin
G in its slot, links J-P2, blades hinged at O1. This module gives each part its sizes and each
joint its bought items (numbers only: :mod:`cadgen.solids.duckbill` cuts what they say), and
sizes the return spring from the follower's loads (:mod:`cadgen.machine.follower`,
:mod:`cadgen.machine.springs`).

Layers (z, normal to the mechanism's plane; mm from the cam's bottom face, which is seated on
gearbox 2's roof). The cam plate ``[0, t_cam]``; the roller in it, its top face level with the
cam's; the lever in its own layer one axial gap above the cam (the planter's plate one gap
above the lever: :func:`cadgen.params.cam.CamParameters.lever_layer`); the push rod, the links
and the blades' cranks in the duckbill tube, about its axis. Nothing of the linkage reaches below
the cam's bottom face: gearbox 2 turns under it.

* lever: a steel plate, the bell crank H-I-G (two arms round bosses at H, I, G); under its I
  boss a spacer boss down to the roller's inner ring. It turns on an ISO 2341 clevis pin at H
  in a lug of the planter's plate.
* roller: the small deep-groove ball bearing as wide across as the cam's roller
  (:func:`cadgen.machine.pins.roller_bearing`), on an ISO 2338 pin pressed into the lever and
  held by a DIN 471 ring under the bearing (no room for a split pin above gearbox 2's roof).
* push rod: a turned rod on the duckbill axis, guided in a web across the tube, a collar at
  its top with the slot the pin G (long: from the lever up through a slot in the tube's wall)
  slides in, its lower end flattened to an eye at P2 between the two links.
* links: plates J-P2 each side of the rod's eye; the blades' cranks O1-J in the tube's middle
  plane.
* blades: each on an ISO 2341 pin at O1 through a knuckle of the blade between two ears of the
  tube.
* return spring: round the push rod between the web and the collar: it pushes the rod up
  (closing the blades, pressing the roller on the cam).
"""

from __future__ import annotations

import math

import numpy as np

from kinematics.errors import Problem

from cadgen.machine.catalogue import CatalogueError
from cadgen.machine.follower import Body, follower_forces
from cadgen.machine.pins import clevis_pin_length, retaining_ring, roller_bearing, PIN_LENGTHS
from cadgen.machine.springs import design_compression_spring

__all__ = ["duckbill_fixing", "duckbill_report", "duckbill_geometry", "linkage_bodies", "stadium",
           "lever_arms", "plate_properties", "PIN_DIAMETERS", "LINK_THICKNESS", "ROD_DIAMETER"]

#: Pin diameters at each joint (mm). The loads are tens of newtons (the report gives them):
#: the sizes are the smallest that keep a plate's eye and the pins easy to handle; G's pin is
#: a cantilever from the lever to the rod (about 50 mm, beyond ISO 2341's range of the
#: thinner pins), hence the thickest.
PIN_DIAMETERS = {"H": 5.0, "G": 8.0, "P2": 4.0, "J": 4.0, "O1": 5.0}
#: Links and the blades' cranks: steel plate (mm).
LINK_THICKNESS = 3.0
#: The push rod (mm): turned; its eye at P2 is the rod flattened to a link's thickness.
ROD_DIAMETER = 8.0
#: A pin's hole over its diameter (mm): a running clearance fit (about H11/h11).
PIN_HOLE_CLEARANCE = 0.2
#: Axial gap (mm) between neighbouring plates on one pin, and round a moving part.
SIDE_GAP = 0.5
#: The web that guides the push rod and seats the spring (mm thick).
WEB_THICKNESS = 5.0
#: The knuckle of a blade spans this (mm) either side of the tube's middle plane, its ears the
#: next EAR_THICKNESS beyond.
KNUCKLE_HALF = 4.5
EAR_THICKNESS = 4.0
#: Room (mm) kept clear beyond the ears along the hinge pin, for its head and its split pin.
PIN_END_ROOM = 6.0
#: The collar's least diameter (mm) and its wall round the G slot.
COLLAR_DIAMETER_MIN = 18.0
COLLAR_WALL = 3.0
#: Steel, for the roller (kg/m^3); a ball bearing is about this much steel between its bore
#: and its outside (the rest is the space round the balls).
STEEL_DENSITY = 7850.0
BEARING_FILL = 0.6
#: The roller's pin ends at least this far (mm) above gearbox 2's roof, which turns under it.
ROOF_CLEARANCE = 0.5


def boss_radius(d: float) -> float:
    """A plate's eye round a ``d`` mm pin: a wall of half the pin, at least 3 mm."""
    return d / 2 + max(3.0, d / 2)


def _circle(centre, radius, segments):
    angles = 2 * np.pi * np.arange(segments) / segments
    return np.asarray(centre, dtype=float) + radius * np.column_stack([np.cos(angles),
                                                                      np.sin(angles)])


def stadium(p, q, r_p: float, r_q: float, segments: int = 96) -> np.ndarray:
    """The convex hull of two discs (a link, a lever's arm), counter-clockwise (n, 2).

    The outer tangents touch both circles at the angles ``alpha +- gamma`` (``alpha`` the
    direction from ``p`` to ``q``, ``cos gamma = (r_p - r_q) / |q - p|``): the hull is ``q``'s
    arc between them round ``alpha`` and ``p``'s arc round ``alpha + pi``, each vertex on its
    circle (about ``segments`` per full turn).
    """
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    distance = float(np.hypot(*(q - p)))
    if distance <= abs(r_p - r_q):
        raise ValueError(f"a stadium needs two discs neither inside the other, not centres "
                         f"{distance:g} mm apart with radii {r_p:g} and {r_q:g} mm")
    alpha = math.atan2(q[1] - p[1], q[0] - p[0])
    gamma = math.acos((r_p - r_q) / distance)
    arcs = []
    for centre, radius, start, span in ((q, r_q, alpha - gamma, 2 * gamma),
                                        (p, r_p, alpha + gamma, 2 * math.pi - 2 * gamma)):
        count = max(2, int(math.ceil(segments * span / (2 * math.pi))) + 1)
        angles = start + span * np.linspace(0.0, 1.0, count)[:-1]
        arcs.append(centre + radius * np.column_stack([np.cos(angles), np.sin(angles)]))
    return np.vstack(arcs)


def lever_arms(geometry: dict, segments: int = 96) -> tuple:
    """The lever's two arms at rest (planter frame), H-I and H-G, as stadiums (its outline is
    their union)."""
    points, radius = geometry["points"], geometry["lever"]["boss_radius"]
    return tuple(stadium(points["H"], points[end], radius["H"], radius[end], segments)
                 for end in ("I", "G"))


def _clip(subject, clip) -> np.ndarray:
    """The intersection of two convex counter-clockwise polygons (Sutherland-Hodgman)."""
    out = [np.asarray(v, dtype=float) for v in subject]
    clip = np.asarray(clip, dtype=float)
    for a, b in zip(clip, np.roll(clip, -1, axis=0)):
        edge = b - a
        inside = [float(edge[0] * (v[1] - a[1]) - edge[1] * (v[0] - a[0])) >= 0.0 for v in out]
        kept = []
        for k, v in enumerate(out):
            w, w_in = out[k - 1], inside[k - 1]
            if inside[k] != w_in:   # the edge w-v crosses the clip line: keep the crossing
                d = v - w
                t = (edge[0] * (a[1] - w[1]) - edge[1] * (a[0] - w[0])) / (
                    edge[0] * d[1] - edge[1] * d[0])
                kept.append(w + t * d)
            if inside[k]:
                kept.append(v)
        out = kept
        if not out:
            break
    return np.asarray(out, dtype=float).reshape(-1, 2)


def plate_properties(outline, holes, thickness: float, density: float) -> tuple:
    """A plate's mass (kg), centre (mm) and moment of inertia about its centre along z (kg m^2).

    Polygon area moments (shoelace forms) of the outline less its round ``holes`` (``(x, y,
    r)`` rows).
    """
    x, y = np.asarray(outline, dtype=float).T
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    first = np.array([np.sum((x + xn) * cross), np.sum((y + yn) * cross)]) / 6.0
    second = np.sum(cross * (x**2 + x * xn + xn**2 + y**2 + y * yn + yn**2)) / 12.0
    for hx, hy, hr in holes:
        hole = math.pi * hr**2
        area -= hole
        first -= hole * np.array([hx, hy])
        second -= hole * (hr**2 / 2 + hx**2 + hy**2)
    centre = first / area
    mass = density * thickness * area * 1e-9
    inertia = density * thickness * (second - area * float(centre @ centre)) * 1e-15
    return mass, centre, inertia


def _blade_properties(linkage, geometry, density, wall, samples=(160, 48, 8)) -> tuple:
    """A blade (the right one at rest), as :func:`cadgen.solids.planting._planter_parts` cuts
    it: half the solid between a cone from the tip N to radius ``e + wall`` at the hinges'
    height and the same cone of radius ``e`` raised ``wall / sin(d0)``, with its knuckle and
    crank; mass (kg), centre (mm), inertia about it (kg m^2), by a midpoint sum over the shell."""
    L1, L2 = linkage.L1, linkage.L2
    height = linkage.blade_length * math.cos(linkage.closed_half_angle)
    e = linkage.hinge_offset
    rise = wall / math.sin(linkage.closed_half_angle)
    n_h, n_a, n_r = samples
    h = (np.arange(n_h) + 0.5) / n_h * height
    outer = (e + wall) * h / height
    inner = np.clip(e * (h - rise) / height, 0.0, None)
    u = (np.arange(n_r) + 0.5) / n_r
    r = inner[:, None] + (outer - inner)[:, None] * u[None, :]           # (h, r)
    around = (np.arange(n_a) + 0.5) / n_a * math.pi - math.pi / 2        # the half at x >= -L1
    dV = (r * ((outer - inner)[:, None] / n_r) * (height / n_h))[:, :, None] * (math.pi / n_a)
    x = -L1 + r[:, :, None] * np.cos(around)[None, None, :]
    y = (-L2 + h)[:, None, None] + 0.0 * x
    dm = density * dV * 1e-9 * np.ones_like(x)
    masses = [float(dm.sum())]
    centres = [np.array([np.sum(dm * x), np.sum(dm * y)]) / dm.sum()]
    inertias = [float(np.sum(dm * ((x - centres[0][0]) ** 2 + (y - centres[0][1]) ** 2))) * 1e-6]
    hinge, crank = geometry["points"]["O1"], geometry["points"]["J"]
    knuckle = geometry["hinge"]["knuckle_radius"]
    m, c, i = plate_properties(_circle(hinge, knuckle, 64), [], 2 * KNUCKLE_HALF, density)
    masses.append(m), centres.append(c), inertias.append(i)
    lug = stadium(hinge, crank, knuckle, geometry["crank"]["eye_radius"], 64)
    m, c, i = plate_properties(lug, [], LINK_THICKNESS, density)
    masses.append(m), centres.append(c), inertias.append(i)
    total = sum(masses)
    centre = sum(mk * ck for mk, ck in zip(masses, centres)) / total
    inertia = sum(ik + mk * float((ck - centre) @ (ck - centre)) * 1e-6
                  for mk, ck, ik in zip(masses, centres, inertias))
    return total, centre, inertia


def duckbill_geometry(params, linkage, fits=None) -> dict:
    """Every size of the linkage's made parts and the pins' grips (mm; see the module notes).

    ``points`` are the linkage's joints at rest (closed duckbill) in the planter frame, the
    right blade's; ``z`` the layers, from the cam's bottom face.
    """
    cam, gap = params.cam, params.housing.axial_gap
    extra = getattr(fits, "bolt_hole_extra", 0.0)
    hole = {name: d + PIN_HOLE_CLEARANCE + extra for name, d in PIN_DIAMETERS.items()}
    lam0 = 0.0
    points = {"H": linkage.lever_pivot, "I": linkage.roller_centre(lam0)[0][0],
              "G": linkage.rod_pin(lam0)[0], "O1": linkage.hinge,
              "J": linkage.crank_pin(0.0)[0],
              "P2": np.array([-linkage.L1, float(linkage.push_rod_end(0.0)[0])])}
    points = {k: [float(v) for v in p] for k, p in points.items()}
    lever_bottom = cam.thickness + gap
    tube_axis = (cam.thickness + gap + cam.lever_layer(gap) + params.planter.arm_thickness
                 + linkage.hinge_offset)
    # G moves along x by l_HG (1 - cos lambda) over the lift: the slot's length along x
    g_shift = linkage.rod_arm * (1.0 - math.cos(linkage.lever_lift))
    slot_length = PIN_DIAMETERS["G"] + 2 * g_shift + 2 * PIN_HOLE_CLEARANCE + extra
    collar_height = hole["G"] + 2 * COLLAR_WALL
    collar = max(COLLAR_DIAMETER_MIN, slot_length + 2 * COLLAR_WALL)
    link_eye = boss_radius(PIN_DIAMETERS["P2"])
    # the web sits above the links' upper eyes (they rise no higher than at rest)
    web_bottom = points["P2"][1] + link_eye + 1.0
    collar_bottom = points["G"][1] - collar_height / 2
    return {
        "points": points, "L1": float(linkage.L1),
        "z": {"lever_bottom": lever_bottom, "tube_axis": tube_axis,
              "cam_top": cam.thickness},
        "lever": {"thickness": cam.lever.thickness,
                  "boss_radius": {"H": boss_radius(PIN_DIAMETERS["H"]),
                                  "I": boss_radius(4.0), "G": boss_radius(PIN_DIAMETERS["G"])},
                  "hole": {"H": hole["H"], "G": hole["G"]}},
        "lug": {"radius": boss_radius(PIN_DIAMETERS["H"]) + 1.5},
        "rod": {"diameter": ROD_DIAMETER, "eye_thickness": LINK_THICKNESS,
                "eye_hole": hole["P2"], "collar_diameter": collar,
                "collar_height": collar_height, "collar_bottom": collar_bottom,
                "slot_length": slot_length, "slot_width": hole["G"],
                "bottom": points["P2"][1] - ROD_DIAMETER / 2,
                "stroke": float(linkage.stroke)},
        "web": {"bottom": web_bottom, "thickness": WEB_THICKNESS,
                "hole": ROD_DIAMETER + PIN_HOLE_CLEARANCE + extra,
                "room": collar_bottom - web_bottom - WEB_THICKNESS},
        "tube_slot": {"width": hole["G"] + 2 * SIDE_GAP + 2 * g_shift,
                      "top": points["G"][1] + hole["G"] / 2 + SIDE_GAP,
                      "bottom": points["G"][1] - linkage.stroke - hole["G"] / 2 - SIDE_GAP},
        "link": {"thickness": LINK_THICKNESS, "eye_radius": link_eye, "hole": hole["P2"],
                 "length": float(linkage.blade_link),
                 # the right link's faces, from the tube's axis (the left one mirrored)
                 "z": (LINK_THICKNESS / 2 + SIDE_GAP, 1.5 * LINK_THICKNESS + SIDE_GAP)},
        "crank": {"thickness": LINK_THICKNESS, "eye_radius": boss_radius(PIN_DIAMETERS["J"]),
                  "hole": hole["J"]},
        "hinge": {"knuckle_radius": boss_radius(PIN_DIAMETERS["O1"]),
                  "knuckle_half": KNUCKLE_HALF, "ear_from": KNUCKLE_HALF + SIDE_GAP,
                  "ear_thickness": EAR_THICKNESS, "ear_radius": boss_radius(PIN_DIAMETERS["O1"]),
                  "hole": hole["O1"], "clearance": SIDE_GAP,
                  "pin_end_room": PIN_END_ROOM},
    }


def linkage_bodies(params, linkage, geometry, fits) -> list:
    """The linkage's moving bodies with their masses (estimated from the parts' outlines)."""
    density = {kind: (fits.material(kind).density if fits is not None else STEEL_DENSITY)
               for kind in ("lever", "push-rod", "link", "blade")}
    points, lever = geometry["points"], geometry["lever"]
    # the two arms, less their overlap round H counted twice, less the pin holes
    first, second = lever_arms(geometry, 64)
    overlap = _clip(first, second)
    parts = [plate_properties(first, [(*points[name], lever["hole"][name] / 2)
                                      for name in ("H", "G")], lever["thickness"],
                              density["lever"]),
             plate_properties(second, [], lever["thickness"], density["lever"])]
    m_o, c_o, i_o = plate_properties(overlap, [], lever["thickness"], density["lever"])
    m = parts[0][0] + parts[1][0] - m_o
    c = (parts[0][0] * parts[0][1] + parts[1][0] * parts[1][1] - m_o * c_o) / m
    i = sum(ik + mk * float((ck - c) @ (ck - c)) * 1e-6 for mk, ck, ik in parts) - (
        i_o + m_o * float((c_o - c) @ (c_o - c)) * 1e-6)
    bodies = [Body("lever", "lever", m, i, tuple(c))]
    roller = geometry["roller"]
    ring = math.pi / 4 * (roller["D"] ** 2 - roller["d"] ** 2) * roller["B"]
    bodies.append(Body("roller", "roller", STEEL_DENSITY * BEARING_FILL * ring * 1e-9, 0.0,
                       tuple(points["I"])))
    rod = geometry["rod"]
    length = rod["collar_bottom"] - rod["bottom"]
    volume = (math.pi / 4 * rod["diameter"] ** 2 * length
              + math.pi / 4 * rod["collar_diameter"] ** 2 * rod["collar_height"])
    bodies.append(Body("push rod", "rod", density["push-rod"] * volume * 1e-9, 0.0,
                       tuple(points["P2"])))
    link = geometry["link"]
    outline = stadium((0.0, 0.0), (link["length"], 0.0), link["eye_radius"], link["eye_radius"],
                      64)
    m, c, i = plate_properties(outline, [(0.0, 0.0, link["hole"] / 2),
                                         (link["length"], 0.0, link["hole"] / 2)],
                               link["thickness"], density["link"])
    for side in ("right", "left"):
        bodies.append(Body(f"link {side}", f"link-{side}", m, i, tuple(c)))
    m, c, i = _blade_properties(linkage, geometry, density["blade"], params.planter.shell_wall)
    bodies.append(Body("blade right", "blade-right", m, i, tuple(c)))
    mirrored = (-2 * linkage.L1 - c[0], c[1])
    bodies.append(Body("blade left", "blade-left", m, i, mirrored))
    return bodies


def _pin_entry(joint: str, d: float, grip: float, count: int, what: str) -> dict:
    pin = clevis_pin_length(d, grip)
    items = [{"kind": "clevis pin", "description": f"clevis pin {pin['pin']} ({what})",
              "designation": pin["pin"], "count": count},
             {"kind": "washer", "description": f"washer {pin['washer']}",
              "designation": pin["washer"], "count": count},
             {"kind": "split pin", "description": f"split pin {pin['split']}",
              "designation": pin["split"], "count": count}]
    return {"joint": joint, "d": d, "grip": grip, "length": pin["length"],
            "head_diameter": pin["head_diameter"], "head_height": pin["head_height"],
            "washer_outside": pin["washer_outside"], "washer_thickness": pin["washer_thickness"],
            "designation": pin["pin"], "items": items}


def _roller(params, geometry) -> tuple:
    """The roller's bearing, its pressed pin and ring, placed in z; and their problems."""
    cam, problems = params.cam, []
    bearing = roller_bearing(2 * cam.roller_radius)
    if bearing["B"] > cam.thickness + 1e-9:
        problems.append(Problem("cam.thickness", "roller_wider_than_cam",
                                f"the {bearing['designation']} roller is {bearing['B']:g} mm wide, "
                                f"more than the {cam.thickness:g} mm cam"))
    ring = retaining_ring(bearing["d"])
    top = cam.thickness                                  # level with the cam's top face
    bottom = top - bearing["B"]
    lever_top = geometry["z"]["lever_bottom"] + geometry["lever"]["thickness"]
    # the ring's groove needs some pin beyond it; the longest standard pin that ends there
    lowest = bottom - ring["thickness"] - ring["groove_width"]
    needed = lever_top - lowest
    length = next((v for v in PIN_LENGTHS if v >= needed - 1e-9), PIN_LENGTHS[-1])
    end = lever_top - length
    if end < ROOF_CLEARANCE:
        problems.append(Problem("cam.thickness", "roller_pin_reaches_roof",
                                f"the roller's pin ends {end:.1f} mm above gearbox 2's roof, "
                                f"less than {ROOF_CLEARANCE:g} mm: a thicker cam leaves room"))
    pin = f"ISO 2338 {bearing['d']:g} m6 x {length:g} - St"
    items = [{"kind": "bearing",
              "description": (f"deep-groove ball bearing {bearing['designation']}-2Z "
                              f"({bearing['d']:g} x {bearing['D']:g} x {bearing['B']:g} mm), "
                              "the cam roller"),
              "designation": bearing["designation"], "count": 1},
             {"kind": "parallel pin",
              "description": f"parallel pin {pin}, pressed into the lever, grooved for the ring",
              "designation": pin, "count": 1},
             {"kind": "retaining ring", "description": f"retaining ring {ring['designation']}",
              "designation": ring["designation"], "count": 1}]
    return ({**bearing, "top": top, "bottom": bottom, "pin_length": length, "pin_end": end,
             "pin": pin, "ring": ring["designation"], "ring_thickness": ring["thickness"],
             "spacer_radius": bearing["d"] / 2 + 1.2, "items": items}, problems)


def duckbill_fixing(params, mechanism, cam, fits=None) -> tuple:
    """The linkage's parts, pins, roller and return spring: ``(fixing, problems)``.

    ``fixing`` is a JSON-ready dict (:func:`duckbill_geometry`'s sizes, ``roller``, ``pins``
    by joint with their bought items, ``spring`` (EN 13906-1), ``follower`` (the loads),
    ``bodies`` (the masses used)); ``problems`` the failing checks, each at its field.
    """
    linkage, problems = cam.linkage, []
    geometry = duckbill_geometry(params, linkage, fits)
    try:
        geometry["roller"], found = _roller(params, geometry)
        problems += found
        geometry["lever"]["boss_radius"]["I"] = boss_radius(geometry["roller"]["d"])
    except CatalogueError as error:
        return None, [Problem("cam.roller_radius", "roller_not_in_catalogue", str(error))]
    rod, web = geometry["rod"], geometry["web"]
    # G drives the rod through its collar's slot: off the duckbill axis (a rod arm given in
    # the file) the slot must still lie inside the collar
    offset = abs(geometry["points"]["G"][0] + linkage.L1)
    if offset + rod["slot_length"] / 2 > rod["collar_diameter"] / 2 - COLLAR_WALL:
        problems.append(Problem("cam.lever.rod_arm", "rod_pin_off_axis",
                                f"the lever's pin G is {offset:.1f} mm off the duckbill axis: "
                                "the push rod's collar cannot hold its slot (leave rod_arm to "
                                "its default, L1 - base radius)"))
    if web["room"] < rod["stroke"] + 2.0:
        problems.append(Problem("cam.lever.roller_arm", "no_room_for_spring",
                                f"{web['room']:.1f} mm between the push rod's collar and its "
                                f"web leave no room for a spring with a {rod['stroke']:.1f} mm "
                                "stroke: a longer blade link or roller arm makes some"))
    if problems:
        return None, problems
    bodies = linkage_bodies(params, linkage, geometry, fits)
    speed = params.field.carrier_speed_rpm
    forces = follower_forces(linkage, cam.profile, cam.cam_angle, mechanism, bodies, speed)
    spring, why = design_compression_spring(
        max(forces.required_preload, 1e-3), rod["stroke"], web["room"],
        inside_min=rod["diameter"] + 1.0, outside_max=rod["collar_diameter"] - 2.0)
    if spring is None:
        problems.append(Problem("cam.lever", "spring_not_found",
                                f"no return spring gives {forces.required_preload:.1f} N in the "
                                f"{web['room']:.1f} mm between the web and the collar: {why}"))
    else:
        forces = follower_forces(linkage, cam.profile, cam.cam_angle, mechanism, bodies, speed,
                                 spring_force=lambda s: spring.preload + spring.rate * s)
    z = geometry["z"]
    tube_axis, lever_bottom = z["tube_axis"], z["lever_bottom"]
    grips = {
        "H": params.planter.arm_thickness + params.housing.axial_gap
        + geometry["lever"]["thickness"],
        "G": tube_axis + rod["collar_diameter"] / 2 - lever_bottom,
        "P2": 3 * LINK_THICKNESS + 2 * SIDE_GAP,
        "J": 2 * LINK_THICKNESS + SIDE_GAP,
        "O1": 2 * (KNUCKLE_HALF + SIDE_GAP + EAR_THICKNESS),
    }
    what = {"H": "the lever on the planter", "G": "lever to push rod, in its slot",
            "P2": "push rod to both links", "J": "link to blade crank",
            "O1": "blade hinge"}
    pins = {}
    for joint, d in PIN_DIAMETERS.items():
        try:
            pins[joint] = _pin_entry(joint, d, grips[joint], 1, what[joint])
        except CatalogueError as error:
            problems.append(Problem("cam.lever", "pin_not_in_catalogue", str(error)))
    if spring is not None:
        spring_items = [{"kind": "compression spring", "description": spring.designation,
                         "designation": (f"EN 13906-1 {spring.wire:g} x "
                                         f"{spring.mean_diameter:.1f} x "
                                         f"{spring.free_length:.1f} n{spring.active_coils:g}"),
                         "count": 1}]
    else:
        spring_items = []
    fixing = {**geometry, "pins": pins,
              "spring": spring.as_dict() if spring is not None else None,
              "spring_items": spring_items,
              "follower": {**forces.as_dict(), "carrier_speed_rpm": speed},
              "bodies": [{"name": b.name, "mass_kg": b.mass, "inertia_kgm2": b.inertia}
                         for b in bodies]}
    return fixing, problems


def duckbill_report(fixing: dict) -> dict:
    """report.json's ``duckbill``: the return spring (EN 13906-1), the roller and its contact
    force, the follower's loads, each joint's pin and the masses the loads were computed with."""
    roller = fixing["roller"]
    follower = fixing["follower"]
    return {
        "spring": fixing["spring"],
        "roller": {"bearing": roller["designation"], "bore_mm": roller["d"],
                   "outside_mm": roller["D"], "width_mm": roller["B"], "pin": roller["pin"],
                   "ring": roller["ring"],
                   "contact_force_max_n": follower["contact_force_max_n"],
                   "contact_force_min_n": follower["contact_force_min_n"]},
        "follower": follower,
        "pins": {joint: {"designation": pin["designation"], "grip_mm": pin["grip"]}
                 for joint, pin in fixing["pins"].items()},
        "bodies": fixing["bodies"],
        "parts": {"lever_thickness_mm": fixing["lever"]["thickness"],
                  "rod_diameter_mm": fixing["rod"]["diameter"],
                  "link_thickness_mm": fixing["link"]["thickness"],
                  "collar_diameter_mm": fixing["rod"]["collar_diameter"],
                  "spring_room_mm": fixing["web"]["room"], "stroke_mm": fixing["rod"]["stroke"]},
        "rules": {"spring": "EN 13906-1: R = G d^4 / (8 D^3 n), G = 81 500 MPa; tau_k2 = k_Wahl "
                            "8 D F2 / (pi d^3) <= 0.5 Rm (EN 10270-1 DH minimum)",
                  "contact": "spring force >= safety factor x the largest need over a "
                             "revolution: inertia at the carrier speed, the planter frame's "
                             "acceleration, gravity in the worst direction"},
    }
