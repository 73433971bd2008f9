"""The studio's animation of the planting mechanism: the report's, with the parts inside.

:func:`studio_planting_animation` takes the report's animation data
(:func:`cadgen.report.animation.planting_animation`: poses uniform in the carrier angle,
arms, planter outlines, envelope circles, trails, soil) and adds moving items of two
kinds: in the report's format (``frames`` of flat ``[x0, -y0, x1, -y1, ...]`` lists,
0.1 mm; circles ``[cx, -cy]`` with ``r``), and, for a shape that moves rigidly,
``local`` (its flat points in its own frame, y flipped) with ``frames`` of ``[x, y,
rotate_deg]``, drawn with ``transform="translate(x, y) rotate(deg)"`` (a tenth of the
data: a gear polygon is sent once, not once per pose):

- ``pitch_curves``: the gears of gearbox 2 of each arm at their true centres and angles.
  The spec's train: the central non-circular gear at C does not rotate at all (its
  shaft is the pure-translation planet of train 1), so relative to gearbox 2 (direction
  ``gamma = phic + phi``) it turns by ``-phi``: its body polar angle ``t`` points along
  ``gamma`` when ``t = phi``; body point ``r1(t) u(t)`` is at world angle ``t + phic``.
  The intermediate gear at D has radius ``a - r1(t)`` at body polar angle ``pi - F(t)``
  and turns by ``+F(phi)`` relative to gearbox 2 (``F`` the closure law's integral:
  ``PlantingMechanism.intermediate_rotation``), so at every pose both curves touch at
  ``C + r1(phi) u(gamma)``, having rolled equal arc lengths (the tests check both). The
  circular pair (radius ``r`` at D and E) are circles with a spoke each, the spoke
  starting at their contact point: D's turns with ``F``, E's (the planet, carrying the
  planter) by ``-F``, so E's world angle is ``phic + Psi``.
- ``housings``: each gearbox's outline, the convex hull of its kinematic envelope circles
  (``evaluation.housing_circles``, i.e. :func:`cadgen.solids.housings.housing_circles`:
  the largest gear tip about each axis plus clearance, wall and bolt flange, the
  housing's outermost edge, explicit radii in the file winning), drawn by
  :func:`cadgen.solids.outline.hull_of_circles`, the function the solids' housings are
  built with. Gearbox 2 per arm, in its frame (C, ``gamma``); gearbox 1 once, round O and
  both arms' A, B, C, turning with carrier 1 (``-phi``).
- ``duckbill``: each arm's two blades (hinge to tip), opened by the cam law: the blade
  opening ``beta`` at each carrier angle is the cam design's law
  (:func:`cadgen.cam.design.design_cam`, ``profile.follower_at_carrier``), each blade
  turned about its hinge (the right one counter-clockwise, as the solids turn them). If
  the cam stage fails for the design, the bill stays closed and ``duckbill_note`` says
  why.
- ``advance_mm_per_turn`` (``{"<spacing>": 2 S}``, the absolute motion
  ``X = x + (S / pi) phi`` of ``PlantingMechanism.absolute_motion``) and ``events``
  (catching, entry, lowest, exit with their carrier angle and nearest frame).

Everything is vectorised over the poses; the rounding of the added frames is numpy's.
"""

from __future__ import annotations

import math

import numpy as np

from kinematics.planar import perp, unit

__all__ = ["POSES", "PITCH_SAMPLES", "HULL_SEGMENTS", "RigidBody", "studio_planting_animation",
           "gear_pitch_curves", "housing_outlines", "blade_opening", "blade_lines"]

#: Samples of each non-circular pitch curve per frame (10 deg apart is a few tenths of a mm
#: of chord sag on a 40-mm gear: below a pixel in a view a metre tall).
PITCH_SAMPLES = 48
#: Sides of the polygon circumscribed about each envelope circle in the housing hulls.
HULL_SEGMENTS = 32
#: Decimals of the added frames (the report's: 0.1 mm).
DECIMALS = 1
#: Poses per carrier turn (3 deg apart; the report has 180). The report's animation rounds
#: every coordinate on its own (0.11 ms a pose here, a fifth of the planting answer's
#: time), and the evaluate answer has a 100-ms budget: 120 poses keep it, and still give
#: 15 frames a second at the page's 8-s turn.
POSES = 120


def _flat(stack) -> list:
    """``(frames, points, 2)`` mm -> per frame ``[x0, -y0, ...]`` rounded (SVG's y down)."""
    stack = np.asarray(stack, dtype=float)
    flipped = np.stack([stack[..., 0], -stack[..., 1]], axis=-1)
    return np.round(flipped.reshape(len(stack), -1), DECIMALS).tolist()


def _transform(local, origin, angle) -> np.ndarray:
    """Per-frame local points ``(n, m, 2)`` at ``origin`` (n, 2) turned by ``angle`` (n,).

    Not :func:`cadgen.report.animation.placed`, which places one shape: here the shape
    itself changes from frame to frame (the blades open).
    """
    axis = unit(np.asarray(angle, dtype=float))[:, None, :]
    return (np.asarray(origin)[:, None, :] + local[..., :1] * axis + local[..., 1:] * perp(axis))


# --------------------------------------------------------------------------- rigid bodies
class RigidBody:
    """A shape that moves without deforming: ``local`` (m, 2) mm placed at ``origin`` (n, 2)
    turned by ``angle`` (n,) rad, one pose per frame."""

    def __init__(self, local, origin, angle):
        self.local = np.asarray(local, dtype=float)
        self.origin = np.asarray(origin, dtype=float)
        self.angle = np.broadcast_to(np.asarray(angle, dtype=float), (len(self.origin),))

    def world(self) -> np.ndarray:
        """(n, m, 2) mm: the shape at every pose (what the page draws)."""
        from cadgen.report.animation import placed

        return placed(self.local, self.origin, self.angle)

    def item(self, kind: str, cls: str) -> dict:
        """A moving item the page places with an SVG transform: ``local`` (SVG units, y down)
        once, and per frame ``[x, y, rotate_deg]`` (``translate(x, y) rotate(deg)``; a
        counter-clockwise turn in the y-up plane is a negative SVG rotation)."""
        local = np.round(np.column_stack([self.local[:, 0], -self.local[:, 1]]).ravel(), DECIMALS)
        frames = np.column_stack([np.round(self.origin[:, 0], DECIMALS),
                                  np.round(-self.origin[:, 1], DECIMALS),
                                  np.round(-np.degrees(self.angle), 2)])
        return {"type": kind, "cls": cls, "local": local.tolist(), "frames": frames.tolist()}


# --------------------------------------------------------------------------- gears
def gear_pitch_curves(mechanism, phi, arm: int = 0, samples: int = PITCH_SAMPLES) -> dict:
    """Gearbox 2's gears of one arm at carrier angles ``phi``, as rigid bodies.

    Returns
    -------
    dict
        ``"central"``, ``"intermediate"``: :class:`RigidBody` of the pitch curves, body
        samples at the gear rotation ``t = 2 pi j / samples`` (the intermediate's sample j
        is its point of contact with the central's sample j); ``"spoke D"``, ``"spoke
        E"``: the circular gears' marks (centre to pitch circle); ``"centres"``: {"C",
        "D", "E"} (n, 2); ``"radius"``: the circular gears' pitch radius ``r``.
    """
    phi = np.asarray(phi, dtype=float)
    shifted = phi + np.pi * arm
    centres = mechanism.positions(phi, arm=arm, points=("C", "D", "E"))
    gamma = mechanism.phic + shifted                     # direction of gearbox 2, C -> D
    turned = mechanism.intermediate_rotation(shifted)    # F: intermediate vs gearbox 2
    t = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    r1 = mechanism.pitch_curve.radius(t)
    a, r = mechanism.centre_distance, mechanism.r
    central_body = r1[:, None] * unit(t)
    intermediate_body = (a - r1)[:, None] * unit(np.pi - mechanism.intermediate_rotation(t))
    spoke = np.array([[0.0, 0.0], [r, 0.0]])
    return {
        # the central gear's shaft does not turn: its body frame keeps the angle phic
        "central": RigidBody(central_body, centres["C"], mechanism.phic),
        "intermediate": RigidBody(intermediate_body, centres["D"], gamma + turned),
        # both marks start at the circular pair's contact (D's towards E, E's towards D)
        "spoke D": RigidBody(spoke, centres["D"], gamma + turned),
        "spoke E": RigidBody(spoke, centres["E"], gamma + np.pi - turned),
        "centres": centres, "radius": r,
    }


def _pitch_items(mechanism, phi) -> list:
    items = []
    for arm in (0, 1):
        name = f"arm{arm + 1}"
        gears = gear_pitch_curves(mechanism, phi, arm)
        for key in ("central", "intermediate"):
            items.append(gears[key].item("polygon", f"pitch {key} {name}"))
        for point in ("D", "E"):
            centre = gears["centres"][point]
            items.append({"type": "circle", "cls": f"pitch circular {name}",
                          "r": round(float(gears["radius"]), DECIMALS),
                          "frames": _flat(centre[:, None, :])})
            items.append(gears[f"spoke {point}"].item("polyline", f"pitch spoke {name}"))
    return items


# --------------------------------------------------------------------------- housings
def housing_outlines(mechanism, circles, phi) -> dict:
    """The gearboxes' housing outlines at carrier angles ``phi`` as rigid bodies (module doc).

    Returns ``{"gearbox1": RigidBody, "gearbox2 arm1": ..., "gearbox2 arm2": ...}`` (the
    keys present for the gearboxes that have circles).
    """
    from cadgen.solids.outline import hull_of_circles

    phi = np.asarray(phi, dtype=float)
    radius = {(c.gearbox, c.point): float(c.radius) for c in circles}
    out = {}
    a, r = mechanism.centre_distance, mechanism.r
    along = {"C": 0.0, "D": a, "E": a + 2 * r}
    box2 = [(along[p], 0.0, radius["gearbox2", p]) for p in along if ("gearbox2", p) in radius]
    if box2:
        local = hull_of_circles(box2, HULL_SEGMENTS)
        for arm in (0, 1):
            centre = mechanism.positions(phi, arm=arm, points=("C",))["C"]
            out[f"gearbox2 arm{arm + 1}"] = RigidBody(local, centre,
                                                      mechanism.phic + phi + np.pi * arm)
    line = unit(np.array(mechanism.phi0))
    box1 = [(0.0, 0.0, radius["gearbox1", "O"])] if ("gearbox1", "O") in radius else []
    for sign in (1.0, -1.0):   # both arms hang on carrier 1: one housing round all its axes
        for axis, distance in mechanism.carrier_radii.items():
            if ("gearbox1", axis) in radius:
                x, y = sign * distance * line
                box1.append((x, y, radius["gearbox1", axis]))
    if box1:
        # carrier 1 turns clockwise: the layout drawn at phi = 0 turned by -phi about O
        out["gearbox1"] = RigidBody(hull_of_circles(box1, HULL_SEGMENTS),
                                    np.zeros((len(phi), 2)), -phi)
    return out


# --------------------------------------------------------------------------- duckbill
def blade_opening(params, mechanism, evaluation, phi) -> tuple[np.ndarray, object, str | None]:
    """``(beta (n,) rad, linkage or None, note)``: the blades' opening by the cam law.

    The cam design's law (:func:`cadgen.cam.design.design_cam`: its linkage, its timing
    from the planting events, its follower program over the cam angle ``F``) without
    the contour's checks, which the animation does not need and which cost 7 ms (a
    test holds it equal to ``design_cam(...).profile.follower_at_carrier``). A design
    whose cam stage fails (linkage or timing impossible) keeps the bill closed
    (``beta = 0``) and the note says why.
    """
    from kinematics.errors import MechanismError
    from kinematics.motion_laws import FollowerProgram

    from cadgen.cam.design import linkage_of, timing_of

    phi = np.asarray(phi, dtype=float)
    try:
        linkage = linkage_of(params)
        timing = timing_of(params, mechanism, evaluation.events)
        cam_angle = mechanism.intermediate_rotation
        program = FollowerProgram(
            linkage.lever_lift,
            rise=(float(cam_angle(timing.opening[0])), float(cam_angle(timing.opening[1]))),
            fall=(float(cam_angle(timing.closing[0])), float(cam_angle(timing.closing[1]))),
            rise_law=params.cam.rise_law, fall_law=params.cam.return_law)
        beta = linkage.opening_of_lever(program(cam_angle(phi))[0])
    except MechanismError as error:
        problems = getattr(error, "problems", None) or []
        why = "; ".join(p.message for p in problems) or " ".join(str(error).split())
        return np.zeros(phi.shape), None, ("the duckbill is drawn closed: the cam stage fails "
                                           f"for this design ({why})")
    if not np.all(np.isfinite(beta)):
        return np.zeros(phi.shape), linkage, (
            "the duckbill is drawn closed: the cam law gives no finite blade opening")
    return beta, linkage, None


def blade_lines(params, linkage, beta) -> np.ndarray:
    """Both blades (hinge, tip) in the planter frame at openings ``beta``: (n, 2, 2, 2).

    ``[:, 0]`` the right blade, ``[:, 1]`` the left; each row hinge then tip. Closed
    (``beta = 0``) both tips meet at the duckbill tip N = (-L1, -L2).
    """
    planter = params.planter
    if linkage is not None:
        length, closed = linkage.blade_length, linkage.closed_half_angle
    else:
        length, closed = params.cam.duckbill.blade_length, params.cam.closed_half_angle_rad
    L1, L2 = planter.L1, planter.L2
    offset = length * math.sin(closed)
    hinge_y = -L2 + length * math.cos(closed)
    beta = np.asarray(beta, dtype=float)
    blades = []
    for sign in (1.0, -1.0):
        hinge = np.array([-L1 + sign * offset, hinge_y])
        closed_tip = np.array([-L1, -L2]) - hinge
        turn = sign * beta   # the right blade counter-clockwise, the left mirrored
        cos, sin = np.cos(turn), np.sin(turn)
        tip = hinge + np.stack([cos * closed_tip[0] - sin * closed_tip[1],
                                sin * closed_tip[0] + cos * closed_tip[1]], axis=-1)
        blades.append(np.stack([np.broadcast_to(hinge, tip.shape), tip], axis=1))
    return np.stack(blades, axis=1)


def _duckbill_items(params, mechanism, evaluation, phi) -> tuple[list, str | None]:
    # arm 2 is arm 1 half a turn on: its blades open by the law at phi + pi
    both, linkage, note = blade_opening(params, mechanism, evaluation,
                                        np.concatenate([phi, phi + np.pi]))
    items = []
    for arm, beta in enumerate(np.split(both, 2)):
        blades = blade_lines(params, linkage, beta)
        hub = mechanism.positions(phi, arm=arm, points=("E",))["E"]
        psi = mechanism.attitude(phi + np.pi * arm)
        for side, name in ((0, "right"), (1, "left")):
            world = _transform(blades[:, side], hub, psi)
            items.append({"type": "polyline", "cls": f"duckbill {name} arm{arm + 1}",
                          "frames": _flat(world)})
    return items, note


# --------------------------------------------------------------------------- the whole
def _widened_view(view: list, stacks) -> list:
    """The report's view box ``[x, y, w, h]`` (SVG units) grown to hold ``stacks`` too."""
    points = np.concatenate([np.asarray(s, dtype=float).reshape(-1, 2) for s in stacks])
    low_x, high_x = points[:, 0].min(), points[:, 0].max()
    low_y, high_y = -points[:, 1].max(), -points[:, 1].min()   # SVG y points down
    pad = 0.03 * max(high_x - low_x, high_y - low_y)
    x0 = min(view[0], low_x - pad)
    y0 = min(view[1], low_y - pad)
    x1 = max(view[0] + view[2], high_x + pad)
    y1 = max(view[1] + view[3], high_y + pad)
    return [round(float(v), 1) for v in (x0, y0, x1 - x0, y1 - y0)]


def studio_planting_animation(params, mechanism, evaluation, *, with_soil: bool = True) -> dict:
    """The report's planting animation with the gears, housings, duckbill, advance and events.

    Parameters
    ----------
    params : PlantingParameters
    mechanism : kinematics.planting.PlantingMechanism
    evaluation : kinematics.evaluation.PlantingEvaluation
    with_soil : bool
        False on a bench run (no soil line, no absolute motion to speak of).
    """
    from cadgen.report.animation import planting_animation

    data = planting_animation(params, mechanism, evaluation, poses=POSES)
    poses = data["poses"]
    phi = np.linspace(0.0, 2 * np.pi, poses, endpoint=False)   # the report's poses
    if not with_soil:
        data["soil"] = None
        data["legend"] = [item for item in data["legend"] if item[0] != "soil"]
    data["pitch_curves"] = _pitch_items(mechanism, phi)
    outlines = housing_outlines(mechanism, evaluation.housing_circles, phi)
    data["housings"] = [body.item("polygon", f"housing-outline {name}")
                        for name, body in outlines.items()]
    data["duckbill"], data["duckbill_note"] = _duckbill_items(params, mechanism, evaluation, phi)
    if outlines:
        data["view"] = _widened_view(data["view"], [b.world() for b in outlines.values()])
    data["legend"] += [("pitch central arm1", "gear pitch curves: non-circular pair at C and D, "
                                              "circular pair at D and E"),
                       ("housing-outline gearbox2", "gearbox housings (hull of the envelope "
                                                    "circles)"),
                       ("duckbill right arm1", "duckbill blades, opened by the cam")]
    events = evaluation.events
    data["advance_mm_per_turn"] = {f"{float(h.spacing):g}": 2.0 * h.spacing
                                   for h in evaluation.holes} if with_soil else {}
    data["events"] = [{"name": name, "deg": round(math.degrees(angle), 2),
                       "frame": int(round(angle / (2 * np.pi) * poses)) % poses}
                      for name, angle in (("catching", 0.0), ("entry", events.entry),
                                          ("lowest", events.lowest), ("exit", events.exit))]
    return data
