"""The report's animation of the mechanism through one carrier turn (inline SVG, a small JS loop).

The poses are sampled here, from the kinematic models (the same functions the
metrics and the plots use), and embedded in the page as JSON: the page draws
them, it computes nothing. A pose is uniform in the carrier angle, so the
animation runs at the mechanism's own timing (constant carrier speed).

Planting: both arms' centre lines (O-C carrier, C-E gearbox 2, E-P1-N planter),
the planter outlines (arm plate, duckbill tube and bill), the gearbox envelope
circles, the tip's trail, the tip paths and the soil line. Pricking: the carrier
(O-A-B), the rocker, the needle, the tip loop, the tip's trail and the soil
surface at the first inclination (in the mechanism plane).

Coordinates are mm in the mechanism plane (x forward, y up); the JSON holds
``-y`` so SVG draws it without a flip, rounded to 0.1 mm (far below a pixel).
"""

from __future__ import annotations

import functools
import html
import importlib.resources
import json
import math

import numpy as np

from kinematics.planar import perp as _perp, unit as _unit

from cadgen.report.html_tables import _section

__all__ = ["POSES", "animation_data", "planting_animation", "pricking_animation",
           "animation_section", "placed", "parts_layer", "with_parts"]

#: Poses per carrier turn (2 degrees apart).
POSES = 180
#: Samples of the static paths (the tip path over one turn).
PATH_SAMPLES = 360
#: Seconds per carrier turn in the page.
CYCLE_SECONDS = 8.0


def _xy(points) -> list:
    """``(n, 2)`` mm -> flat ``[x0, -y0, x1, -y1, ...]`` rounded to 0.1 mm (SVG's y points down)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    flat = np.column_stack([points[:, 0], -points[:, 1]]).ravel()
    return [round(float(v), 1) for v in flat]


def _frames(stack) -> list:
    """``(frames, points, 2)`` -> one flat coordinate list per frame."""
    return [_xy(frame) for frame in np.asarray(stack, dtype=float)]


def _bounds(*arrays) -> list:
    """``[xmin, ymin, width, height]`` (SVG units, y down) round everything drawn, padded 6 %."""
    points = np.vstack([np.asarray(a, dtype=float).reshape(-1, 2) for a in arrays])
    low, high = points.min(axis=0), points.max(axis=0)
    pad = 0.06 * float(max(high - low))
    return [round(float(low[0] - pad), 1), round(float(-high[1] - pad), 1),
            round(float(high[0] - low[0] + 2 * pad), 1), round(float(high[1] - low[1] + 2 * pad), 1)]


def _planter_outline(params, mechanism) -> tuple[np.ndarray, np.ndarray]:
    """The planter's two outlines in its own frame (origin E, x along ``u(Psi)``; mm).

    The arm plate (a stadium from E to P1) and the duckbill tube with its bill down
    to the tip N, as the solids build them (``cadgen.solids.planting``).
    """
    planter, duckbill = params.planter, params.cam.duckbill
    L1, L2 = mechanism.L1, mechanism.L2
    half, wall = planter.arm_width / 2, planter.shell_wall
    closed = params.cam.closed_half_angle_rad
    bill = duckbill.blade_length * math.sin(closed)          # the hinges' offset from the axis
    hinge_y = -L2 + duckbill.blade_length * math.cos(closed)
    tube = bill + wall
    arc = np.linspace(-np.pi / 2, np.pi / 2, 7)
    plate = np.vstack([np.column_stack([half * np.cos(arc), half * np.sin(arc)]),
                       np.column_stack([-L1 - half * np.cos(arc), -half * np.sin(arc)])])
    body = np.array([[-L1 - tube, 0.0], [-L1 + tube, 0.0], [-L1 + tube, hinge_y],
                     [-L1, -L2], [-L1 - tube, hinge_y]])
    return plate, body


def _placed(local, origin, angle) -> np.ndarray:
    """``local`` (m, 2) in frames at ``origin`` (n, 2) turned by ``angle`` (n,): (n, m, 2)."""
    axis = _unit(angle)[:, None, :]
    return (np.asarray(origin)[:, None, :] + local[None, :, :1] * axis
            + local[None, :, 1:] * _perp(axis))


#: Public name of :func:`_placed` for the studio's animation (cadgen.studio.animation), which
#: places its gears, housings and blades in moving frames the same way.
placed = _placed


def planting_animation(params, mechanism, evaluation=None, poses: int = POSES, *,
                       soil: bool = True) -> dict:
    """The planting mechanism's animation data (see :func:`animation_section`).

    Parameters
    ----------
    params : PlantingParameters
    mechanism : kinematics.planting.PlantingMechanism
    evaluation : kinematics.evaluation.PlantingEvaluation, optional
        Gives the soil line and the gearbox envelope circles; without it (a build
        whose metrics failed) the arms move without them.
    soil : bool
        False for a bench run (no soil): no soil line.
    """
    phi = np.linspace(0.0, 2 * np.pi, poses, endpoint=False)
    path_phi = np.linspace(0.0, 2 * np.pi, PATH_SAMPLES + 1)
    plate, body = _planter_outline(params, mechanism)
    circles = list(getattr(evaluation, "housing_circles", None) or [])
    static, moving, trails, drawn = [], [], [], []
    for arm in (0, 1):
        name = f"arm{arm + 1}"
        points = mechanism.positions(phi, arm=arm, points=("C", "E", "P1", "N"))
        psi = mechanism.attitude(phi + np.pi * arm)
        tip_path = mechanism.motion(path_phi, "N", arm).position
        static.append({"type": "polyline", "cls": f"path {name}", "points": _xy(tip_path)})
        for circle in circles:
            centre = (np.zeros((poses, 2)) if circle.point == "O" else
                      mechanism.positions(phi, arm=arm, points=(circle.point,))[circle.point])
            if circle.gearbox == "gearbox1" and arm == 1:
                continue   # gearbox 1 is one housing round both arms' carrier
            moving.append({"type": "circle", "cls": f"housing {circle.gearbox}",
                           "r": round(float(circle.radius), 1),
                           "frames": [_xy(c) for c in centre]})
        outlines = [_placed(shape, points["E"], psi) for shape in (plate, body)]
        for outline in outlines:
            moving.append({"type": "polygon", "cls": f"planter {name}",
                           "frames": _frames(outline)})
        chain = np.stack([points[k] for k in ("C", "E", "P1", "N")], axis=1)
        moving.append({"type": "polyline", "cls": f"arm {name}", "frames": _frames(chain)})
        trails.append({"cls": f"trail {name}", "points": _xy(points["N"])})
        drawn += [tip_path, *outlines, chain]
    carrier = np.stack([mechanism.positions(phi, arm=0, points=("C",))["C"], np.zeros((poses, 2)),
                        mechanism.positions(phi, arm=1, points=("C",))["C"]], axis=1)
    moving.insert(0, {"type": "polyline", "cls": "carrier", "frames": _frames(carrier)})
    legend = [("arm arm1", "arm 1: carrier O-C, gearbox C-E, planter E-P1-N"),
              ("arm arm2", "arm 2"), ("trail arm1", "tip trail"), ("path arm1", "tip path")]
    if circles:
        legend.append(("housing gearbox2", "gearbox envelope circles"))
    level = None
    events = getattr(evaluation, "events", None) if soil else None
    if events is not None and events.soil_level is not None and math.isfinite(events.soil_level):
        level = round(-float(events.soil_level), 1)
        legend.append(("soil", "soil surface"))
        drawn.append(np.array([[0.0, events.soil_level]]))
    return {"kind": "planting", "poses": poses, "seconds": CYCLE_SECONDS,
            "angles": [round(float(a), 1) for a in np.degrees(phi)],

            "angle_label": "carrier angle from the catching position",
            "view": _bounds(*drawn), "soil": level, "static": static, "moving": moving,
            "trails": trails, "legend": legend}


def pricking_animation(design, field=None, poses: int = POSES, *, soil: bool = True) -> dict:
    """The pricking mechanism's animation data (see :func:`animation_section`).

    Parameters
    ----------
    design : kinematics.pricking.PrickingDesign
    field : list of kinematics.pricking_field.InclinationResult, optional
        The first inclination gives the soil surface in the mechanism plane.
    soil : bool
        False for a bench run (no soil): no soil line.
    """
    from kinematics.pricking_field import needle_geometry

    motion, link = design.motion, design.linkage
    centre = np.asarray(link.centre, dtype=float)
    turn = np.linspace(0.0, 2 * np.pi, poses, endpoint=False)   # from the outer dead centre
    phi1 = motion.phi1_start + motion.sense * turn
    v = motion.invert(phi1)
    tip = motion.tip(v)
    needle = needle_geometry(design)
    root = tip - needle.needle * _unit(needle.axis_angle(motion.phi2(v)))
    a_point = centre + link.a * _unit(phi1)
    b_point = centre + 2 * link.a * _unit(phi1)
    carrier = np.stack([np.broadcast_to(centre, tip.shape), a_point, b_point], axis=1)
    loop = motion.tip(np.linspace(0.0, motion.period, PATH_SAMPLES + 1))
    joints = [("joint centre", np.broadcast_to(centre, tip.shape)), ("joint", a_point),
              ("joint", b_point)]
    moving = [{"type": "polyline", "cls": "carrier", "frames": _frames(carrier)},
              *({"type": "circle", "cls": cls, "r": round(0.08 * link.a, 1),
                 "frames": [_xy(p) for p in points]} for cls, points in joints),
              {"type": "polyline", "cls": "rocker",
               "frames": _frames(np.stack([b_point, root], axis=1))},
              {"type": "polyline", "cls": "needle",
               "frames": _frames(np.stack([root, tip], axis=1))}]
    legend = [("carrier", "carrier O-A-B (gear case)"), ("rocker", "rocker (planet)"),
              ("needle", "needle"), ("trail arm1", "tip trail"), ("path arm1", "tip loop")]
    drawn = [loop, carrier, root]
    level = None
    if field and soil:
        first = field[0]
        level = round(-float(first.surface_level), 1)
        legend.append(("soil", f"soil surface at {first.inclination_deg:g} deg inclination "
                               "(in the mechanism plane)"))
        drawn.append(np.array([[centre[0], first.surface_level]]))
    return {"kind": "pricking", "poses": poses, "seconds": CYCLE_SECONDS,
            "angles": [round(float(a), 1) for a in np.degrees(turn)],

            "angle_label": "carrier turn from the outer dead centre",
            "view": _bounds(*drawn), "soil": level,
            "static": [{"type": "polyline", "cls": "path arm1", "points": _xy(loop)}],
            "moving": moving, "trails": [{"cls": "trail arm1", "points": _xy(tip)}],
            "legend": legend}


#: The parts' outlines are thinned to this (mm) for the page: far below a pixel at its scale.
PART_OUTLINE_TOLERANCE = 0.1


def _outline_of(part):
    """A part's outline in the plane, in its own frame: a gear's or the cam's cut outline, a
    housing half's flange outline, the duckbill lever's and links' plates, the push rod's
    silhouette; None for the parts drawn by the kinematics (the planter, the blades, the
    rocker, the needle) or seen only edge-on (a shaft). A housing's cover has its base's
    outline: only the base is drawn."""
    if part.kind == "housing" and "-cover" in part.name:
        return None
    shape = part.outline if part.outline is not None else part.footprint
    if shape is None:
        return None
    from shapely.geometry import LinearRing

    ring = LinearRing(np.asarray(shape, dtype=float)).simplify(PART_OUTLINE_TOLERANCE)
    return np.asarray(ring.coords, dtype=float)[:-1]


def parts_layer(assembly, turns) -> dict | None:
    """The machine's parts, placed by the assembly model at every pose: ``{"outlines": {part:
    flat points in its own frame}, "instances": [{"part", "cls", "frames": [x, y, deg] per
    pose]}}`` (SVG frame: y down, so a turn is clockwise), or None when no part has an outline.

    Every instance the assembly model places is drawn where the solids are: the housings
    (the frame's among them), the gears of both trains and the drive, the cam, the duckbill
    linkage's lever, push rod and links (moving by the cam law, as in the assembly).
    """
    turns = [float(t) for t in turns]
    assembly.prepare(turns)
    outlines, instances = {}, []
    for part in assembly.parts:
        outline = _outline_of(part)
        if outline is None:
            continue
        outlines[part.name] = _xy(outline)
        for _, body, phase in part.instances or ((part.name, part.body, 0.0),):
            frames = []
            for turn in turns:
                pose = assembly.body_pose(body, turn + phase) @ part.local(turn + phase)
                frames += [round(float(pose[0, 3]), 1), round(float(-pose[1, 3]), 1),
                           round(-math.degrees(math.atan2(pose[1, 0], pose[0, 0])), 2)]
            instances.append({"part": part.name, "cls": f"part {part.kind}", "frames": frames})
    return {"outlines": outlines, "instances": instances} if instances else None


def _layer_points(layer, every: int = 15) -> np.ndarray:
    """Points of the placed outlines at every ``every``-th pose (the view must hold them)."""
    points = []
    for instance in layer["instances"]:
        local = np.asarray(layer["outlines"][instance["part"]], dtype=float).reshape(-1, 2)
        frames = np.asarray(instance["frames"], dtype=float).reshape(-1, 3)
        for x, y, deg in frames[::every]:
            c, s_ = math.cos(math.radians(deg)), math.sin(math.radians(deg))
            placed = local @ np.array([[c, s_], [-s_, c]]) + (x, y)
            points.append(placed * (1.0, -1.0))   # back to y up, as _bounds takes it
    return np.vstack(points)


def with_parts(data: dict, assembly) -> dict:
    """The animation ``data`` with the machine's parts drawn under it, placed by ``assembly``
    (its model's placements) at the animation's poses; the view grown to hold them."""
    # the poses the animation samples: uniform in the carrier angle, as its own (both
    # mechanisms' assemblies take the same angle from the same start)
    layer = parts_layer(assembly, np.linspace(0.0, 2 * np.pi, data["poses"], endpoint=False))
    if layer is None:
        return data
    view = data["view"]
    corners = np.array([[view[0], -view[1]], [view[0] + view[2], -(view[1] + view[3])]])
    data = dict(data, parts=layer, view=_bounds(corners, _layer_points(layer)))
    data["legend"] = data["legend"] + [("part gear", "the machine's parts as the assembly "
                                                    "model places them (housings, gears, cam, "
                                                    "the duckbill's lever, push rod and links)")]
    return data


def animation_data(params, values: dict, *, soil: bool = True) -> dict | None:
    """The animation data of a build from its stages' values, or ``None`` without kinematics.

    Parameters
    ----------
    params : PlantingParameters or PrickingParameters
    values : dict
        A build's ``run.values``: ``"kinematics"`` (required) and ``"metrics"``
        (optional: the soil line, the housings) when those stages ran.
    soil : bool
        False for a bench run: no soil line (its report leaves out what needs soil).
    """
    if "kinematics" not in values:
        return None
    if params.mechanism == "pricking":
        data = pricking_animation(values["kinematics"], values.get("metrics"), soil=soil)
    else:
        data = planting_animation(params, values["kinematics"], values.get("metrics"), soil=soil)
    parts = values.get("parts")
    if parts is not None and getattr(parts.assembly, "model", None) is not None:
        data = with_parts(data, parts.assembly)
    return data


@functools.cache
def _script() -> str:
    return importlib.resources.files("cadgen.report").joinpath("animation.js").read_text(
        encoding="utf-8")


def animation_section(data: dict | None) -> str:
    """The page's animation section (``""`` without data): an SVG, its controls, its script.

    Parameters
    ----------
    data : dict or None
        From :func:`animation_data`.
    """
    if not data:
        return ""
    if not isinstance(data, dict) or not data.get("moving") or not data.get("angles"):
        raise ValueError(f"animation data must be a dict with poses, not {type(data).__name__}")
    payload = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    legend = "".join(f'<li><svg width="26" height="10" aria-hidden="true"><line class="{cls}" '
                     f'x1="1" y1="5" x2="25" y2="5"/></svg>{html.escape(text)}</li>'
                     for cls, text in data.get("legend", []))
    view = " ".join(str(v) for v in data["view"])
    return _section("animation", "Animation through one carrier turn", (
        f'<p class="note">{len(data["angles"])} poses from the kinematic model, uniform in '
        f'carrier angle ({data["seconds"]:g} s a turn); the trail is the tip\'s path since the '
        "start of the turn. Play, pause, or drag the slider to a pose.</p>"
        f'<div class="cadgen-animation" data-kind="{html.escape(data["kind"])}" data-frame="0">'
        f'<svg class="anim-stage" viewBox="{view}" preserveAspectRatio="xMidYMid meet" '
        'role="img" aria-label="mechanism animation"></svg>'
        '<div class="anim-controls"><button type="button" class="anim-play">Pause</button>'
        f'<input type="range" class="anim-slider" min="0" max="{len(data["angles"]) - 1}" '
        'value="0" step="1" aria-label="pose">'
        f'<span class="anim-angle">{html.escape(data["angle_label"])}: 0 deg</span></div>'
        f'<ul class="anim-legend">{legend}</ul>'
        f'<script type="application/json" class="anim-data">{payload}</script></div>'
        f"<script>{_script()}</script>"))
