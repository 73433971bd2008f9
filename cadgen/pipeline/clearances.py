"""The clearances of the solids through a revolution (FCL): arm against arm, housings against ground.

Each is a certified least distance (:func:`cadgen.sweep.search.certified_distance`)
from the speed and acceleration bounds of the moving bodies, per radian of carrier
angle (see that module for the formula ``v + w * reach + u``):

* gearbox 2 (base and cover) and the cam ride on gearbox 2, whose origin C circles at
  ``Rc`` while the body turns at rate 1: points move at most ``Rc + reach``
  (acceleration the same);
* a shaft of gearbox 2 also turns on its axis with its gears (rate at most ``S``, the
  largest of 1 and ``max |dF/dphi|``; angular acceleration at most ``A``, the largest
  ``|d2F/dphi2|`` over 20,000 samples plus 25 %): ``Rc + reach + S r`` and
  ``Rc + reach + (2 S + S^2 + A) r`` with ``r`` its radius;
* the planter shell rides on the planter: E's bounds plus its turn (rate at most
  ``max |1 - i|``, angular term read off the planting model's P1 bound) times its
  reach from E;
* a blade also turns on its hinge by the cam's law. Its rate and acceleration
  there are the largest over 20,000 samples of the revolution plus 25 % (the law
  is smooth: cycloidal or 3-4-5), times its reach from the hinge, with the
  Coriolis term ``2 w beta'``; its reach from E is at most the hinge's distance
  from E plus that reach, however far it opens;
* the duckbill linkage's lever, push rod and links move in the planter by the cam law: each
  gets the planter's bounds at its reach from E plus its own motion there (the lever's turn
  about H, the rod's slide, a link's crank pin and turn), sampled like the blades', with the
  Coriolis term;
* gearbox 1 (base and cover) turns about O at rate 1; the ground and the frame are fixed;
  the pricking gear case and the sprocket under it turn about O at rate 1.

Which instances are swept is read from the assembly model's placements (the copies on each
arm; every housing, by the body it rides on), so a part the model adds is swept or refused
with its name, never left out. The bought solids riding on those parts are swept with them
(:mod:`cadgen.solids.bought`: a flange's screw heads, nuts and washers, the keys of the shafts
that leave gearbox 2, the cam's screws), each bounded by its host's motion over its own reach:
a screw head standing off a housing is what comes nearest the other arm or the soil.

Each part instance gets its own part's bounds (arm 2 moves like arm 1), and a pair
of parts is certified with the sum of its two parts' (a cam against a planter shell
with theirs, not the fastest blade's): :func:`cadgen.sweep.search.certified_distance`
with ``instance_bounds``; the report's Lipschitz constant is the largest pair's. The
result replaces the kinematic estimate (centre lines, envelope circles) of the
metric; the report keeps both.
"""

from __future__ import annotations

import math
import re

import numpy as np

__all__ = ["arm_groups", "arm_interference", "ground_clearance"]

#: Part kinds enclosed by a housing of their own arm: not swept arm against arm (the housing
#: around them is). The spacers fill gaps inside a cavity (machine.retention) by design.
_ENCLOSED_KINDS = frozenset({"gear", "spacer"})
#: The parts fixed in gearbox 2's body (the first group of :func:`_arm_part_bounds`).
_GEARBOX2_FIXED = ("gearbox2-base", "gearbox2-cover", "cam")
#: Gearbox 2's shafts, turning on their axes with their gears.
_GEARBOX2_SHAFTS = ("shaft-D", "shaft-E")
#: The duckbill linkage's parts (lever, push rod, links): they move in the planter by the cam law.
_LINKAGE_KINDS = frozenset({"lever", "push-rod", "link"})
#: A housing half cut into segments to fit a printer: ``<half>-1``, ``<half>-2``, ...
_SEGMENT = re.compile(r"-\d+$")


def arm_groups(assembly, *, bought: bool = False) -> tuple[list, list]:
    """Each planting arm's instances, as the assembly model places them: every part with one
    copy per arm (two copies on one body, half a carrier turn apart), the gears inside
    gearbox 2 left out (its housing stands for them). ``([arm 1's], [arm 2's])``, paired in
    order; a part the clearance bounds do not know then fails loudly, not silently unswept.
    ``bought``: with the bought solids riding on those parts (a flange's screw heads, nuts and
    washers, the keys of the shafts that leave the housing): the sweep's groups."""
    first, second = [], []
    kinds = {part.name: part.kind for part in assembly.parts}
    riding = [part for part in getattr(assembly, "bought", ()) if bought
              and kinds.get(part.host) not in _ENCLOSED_KINDS]
    for part in list(assembly.parts) + riding:
        copies = part.instances
        if part.kind in _ENCLOSED_KINDS or len(copies) != 2:
            continue
        (one, body_one, phase_one), (two, body_two, phase_two) = copies
        if body_one == body_two and math.isclose(abs(phase_two - phase_one), math.pi):
            first.append(one)
            second.append(two)
    return first, second


def _present(names, parts) -> list:
    """The parts of ``names`` in ``parts``: each name itself, or the segments it was cut into."""
    out = []
    for name in names:
        if name in parts:
            out.append(name)
        else:
            out += [part for part in parts
                    if part.startswith(f"{name}-") and _SEGMENT.fullmatch(part[len(name):])]
    return out


#: The certified minimum is within this of the true one (mm), by default (resolution.sweep_atol).
SWEEP_ATOL = 1e-6
#: Screening steps per sweep: the second-order screen needs few (benchmarks/sweep.py).
SWEEP_STEPS = 90
#: Margin on sampled blade rates (see the module notes).
SAMPLED_MARGIN = 1.25
_Z = (0.0, 0.0, 1.0)


def _planter_turn(mechanism):
    closure = mechanism.closure
    spin = max(abs(1.0 - closure.ratio_min), abs(1.0 - closure.ratio_max))
    turn = (mechanism.acceleration_bound("P1") - mechanism.acceleration_bound("E")) / mechanism.L1
    return spin, turn


def _blade_rates(cam, mechanism, samples: int = 20_000):
    """Largest |d beta/d phi| and |d2 beta/d phi2| of the blades over a revolution (sampled, +25 %)."""
    phi = np.linspace(0.0, 2 * np.pi, samples + 1)
    lam = cam.profile.program(cam.cam_angle(phi))[0]
    beta = cam.linkage.opening_of_lever(lam)
    step = phi[1] - phi[0]
    rate = np.gradient(beta, step)
    return (SAMPLED_MARGIN * float(np.max(np.abs(rate))),
            SAMPLED_MARGIN * float(np.max(np.abs(np.gradient(rate, step)))))


def _shaft_rates(mechanism, samples: int = 20_000):
    """Largest spin rate and its rate of gearbox 2's shafts against the carrier angle: the
    central gear's is 1, the intermediate's and planet's ``|dF/dphi|`` (the largest over
    the samples plus 25 %); ``|d2F/dphi2|`` sampled likewise (the central gear's is 0)."""
    phi = np.linspace(0.0, 2 * np.pi, samples + 1)
    F = np.asarray(mechanism.intermediate_rotation(phi), dtype=float)
    step = phi[1] - phi[0]
    rate = np.gradient(F, step)
    return (max(1.0, SAMPLED_MARGIN * float(np.max(np.abs(rate)))),
            SAMPLED_MARGIN * float(np.max(np.abs(np.gradient(rate, step)))))


def _arm_bounds(mechanism, parts, cam, bought=()) -> tuple:
    """(speed, acceleration) bounds of any point of one arm's parts that are present (and of
    the ``bought`` solids riding on them)."""
    bounds = _arm_part_bounds(mechanism, parts, cam, bought)
    return (max(speed for speed, _ in bounds.values()),
            max(acceleration for _, acceleration in bounds.values()))


def _arm_part_bounds(mechanism, parts, cam, bought=()) -> dict:
    """``{part: (speed, acceleration)}`` bounds of any point of each of one arm's parts present,
    and of each ``bought`` solid riding on one of them (its host's motion, its own reach)."""
    rules = _arm_rules(mechanism, parts, cam)
    bounds = {name: rule(parts[name]) for name, rule in rules.items()}
    for part in bought:
        rule = rules.get(part.host)
        if rule is not None:
            bounds[part.name] = rule(part)
    return bounds


def _arm_rules(mechanism, parts, cam) -> dict:
    """``{part present: bound(geometry) -> (speed, acceleration)}``: how fast a point of a solid
    moving as that part moves can go, given the solid (the part itself, or a bought solid
    fixed in it, placed as its ``local`` says)."""
    from cadgen.sweep.scene import part_reach

    rc = mechanism.carrier_radii["C"]
    spin, turn = _planter_turn(mechanism)
    rules = {}

    def fixed(part):
        box = rc + part_reach(part, axis=_Z)
        return box, box

    for name in _present(_GEARBOX2_FIXED, parts):
        rules[name] = fixed
    shafts = [name for name in _GEARBOX2_SHAFTS if name in parts]
    if shafts:
        rate, rate_rate = _shaft_rates(mechanism)

        def spinning(part, shaft):
            # the solid in the shaft's own frame (the shaft itself: as it is), about its axis
            local = np.linalg.solve(shaft.local(0.0), part.local(0.0))
            vertices = part.mesh.vertices @ local[:3, :3].T + local[:3, 3]
            radius = float(np.max(np.linalg.norm(vertices[:, :2], axis=1)))
            reach = float(np.hypot(*shaft.local(0.0)[:2, 3])) + radius
            return (rc + reach + rate * radius,
                    rc + reach + (2 * rate + rate**2 + rate_rate) * radius)

        for name in shafts:
            rules[name] = lambda part, shaft=parts[name]: spinning(part, shaft)
    if "planter-shell" in parts:
        def planter(part):
            reach = part_reach(part, axis=_Z)
            return (mechanism.speed_bound("E") + spin * reach,
                    mechanism.acceleration_bound("E") + turn * reach)

        rules["planter-shell"] = planter
    blades = [name for name in ("blade-right", "blade-left") if name in parts]
    if blades:
        rate, rate_rate = _blade_rates(cam, mechanism) if cam is not None else (0.0, 0.0)

        def blade(part, name):
            if cam is None:   # closed blades ride on the planter like its shell
                reach_e, reach_h = part_reach(part, axis=_Z), 0.0
            else:
                hinge = _hinge(cam.linkage, name)
                reach_h = part_reach(part, body_origin_local=(*hinge, 0.0), axis=_Z)
                # however far it opens, no point of it is farther from E than this
                reach_e = float(np.hypot(*hinge)) + reach_h
            return (mechanism.speed_bound("E") + spin * reach_e + rate * reach_h,
                    mechanism.acceleration_bound("E") + turn * reach_e
                    + (rate_rate + rate**2 + 2 * spin * rate) * reach_h)

        for name in blades:
            rules[name] = lambda part, name=name: blade(part, name)
    if cam is not None:   # the duckbill's lever, push rod and links, each by its own motion
        def linkage(part, host):
            speed, acceleration, reach_e = _linkage_motion(cam, part, host)
            return (mechanism.speed_bound("E") + spin * reach_e + speed,
                    mechanism.acceleration_bound("E") + turn * reach_e + acceleration
                    + 2 * spin * speed)

        for name, host in parts.items():
            if host.kind in _LINKAGE_KINDS:
                rules[name] = lambda part, host=host: linkage(part, host)
    return rules


def _linkage_motion(cam, part, host=None, samples: int = 20_000):
    """A duckbill linkage part's motion in the planter: the largest speed and acceleration (per
    carrier radian, sampled, +25 %) of any of its points there, and its largest reach from E.
    ``part``: the solid (the linkage part, or a solid fixed in it and placed with it); ``host``:
    the linkage part it moves as (default ``part``)."""
    from cadgen.sweep.scene import part_reach

    phi = np.linspace(0.0, 2 * np.pi, samples + 1)
    step = phi[1] - phi[0]
    linkage = cam.linkage
    lam = cam.profile.program(cam.cam_angle(phi))[0]

    def rates(values):
        rate = np.gradient(values, step, axis=0)
        return rate, np.gradient(rate, step, axis=0)

    host = part if host is None else host
    if host.kind == "lever":   # turns about H
        pivot = linkage.lever_pivot
        reach = part_reach(part, body_origin_local=(*pivot, 0.0), axis=_Z)
        rate, rate_rate = rates(lam)
        speed = np.abs(rate) * reach
        acceleration = (np.abs(rate_rate) + rate**2) * reach
        reach_e = float(np.hypot(*pivot)) + reach
    elif host.kind == "push-rod":   # slides along the duckbill axis
        travel = linkage.rod_arm * np.sin(lam)
        rate, rate_rate = rates(travel)
        speed, acceleration = np.abs(rate), np.abs(rate_rate)
        reach_e = part_reach(part, axis=_Z) + float(np.max(np.abs(travel)))
    else:   # a link, from its blade's crank pin J to the rod's end P2 (its frame's origin at J)
        beta = linkage.opening_of_lever(lam)
        pin = linkage.crank_pin(beta)
        if host.name.endswith("left"):
            pin = np.stack([-2.0 * linkage.L1 - pin[:, 0], pin[:, 1]], axis=-1)
        end_y = linkage.push_rod_end(beta)
        angle = np.unwrap(np.arctan2(end_y - pin[:, 1], -linkage.L1 - pin[:, 0]))
        reach = float(np.max(np.linalg.norm(part.mesh.vertices[:, :2], axis=1)))
        pin_rate, pin_rate_rate = rates(pin)
        rate, rate_rate = rates(angle)
        speed = np.linalg.norm(pin_rate, axis=1) + np.abs(rate) * reach
        acceleration = (np.linalg.norm(pin_rate_rate, axis=1)
                        + (np.abs(rate_rate) + rate**2) * reach)
        reach_e = float(np.max(np.linalg.norm(pin, axis=1))) + reach
    return (SAMPLED_MARGIN * float(np.max(speed)), SAMPLED_MARGIN * float(np.max(acceleration)),
            reach_e)


def _hinge(linkage, blade: str) -> np.ndarray:
    """A blade's hinge in the planter frame: the right one, or its mirror in the duckbill axis."""
    if blade == "blade-right":
        return linkage.hinge
    return np.array([-2.0 * linkage.L1 - linkage.hinge[0], linkage.hinge[1]])


def _arm_bounds_of(instances, part_of, bounds) -> dict:
    """Each arm instance's part's (speed, acceleration) bounds; a part without any (a new part
    on the arm the bounds do not yet cover) is a SolidInputError naming it."""
    from cadgen.solids.errors import SolidInputError

    missing = sorted({part_of[name] for name in instances} - set(bounds))
    if missing:
        raise SolidInputError("arm_interference", f"no speed bound for the arm parts {missing}: "
                              "cadgen.pipeline.clearances does not know how they move")
    return {name: bounds[part_of[name]] for name in instances}


def _verdict(result, target) -> str:
    """``fail`` when certainly not above ``target``, ``pass`` when certainly (or within the
    certified atol) above it, else ``undecided`` (the gap [bound, minimum] straddles it)."""
    if result.interference_ranges or not result.minimum > target:
        return "fail"
    return "pass" if result.bound > target or result.certified else "undecided"


def _section(result, label, target, kinematic) -> dict:
    verdict = _verdict(result, target)
    return {
        "label": label, "method": "FCL mesh distance of the solids, certified minimum",
        "minimum_mm": float(result.minimum), "certified_bound_mm": float(result.bound),
        "certified": bool(result.certified),
        "carrier_angle_deg": float(np.degrees(result.argument)),
        "nearest": [str(result.pair[0]), str(result.pair[1])],
        "nearest_points_mm": [np.asarray(result.point_a, dtype=float).tolist(),
                              np.asarray(result.point_b, dtype=float).tolist()],
        "interference_ranges_deg": [[float(np.degrees(a)), float(np.degrees(b))]
                                    for a, b in result.interference_ranges],
        "kinematic_estimate_mm": None if kinematic is None else float(kinematic),
        "target_mm": float(target),
        "passed": verdict == "pass",
        "verdict": verdict,
        "evaluations": int(result.evaluations),
        "lipschitz_mm_per_rad": float(result.lipschitz),
        "atol_mm": float(result.atol),
        "samples": {"carrier_angle_deg": np.degrees(result.samples_phi).round(6).tolist(),
                    "distance_mm": np.asarray(result.samples_distance).round(6).tolist()},
    }


def _housing_reach(part, body: str, rc: float) -> float:
    """How fast (mm per rad of carrier angle) a point of a housing on ``body`` can move."""
    from cadgen.sweep.scene import part_reach

    if body == "frame":
        return 0.0
    if body == "carrier1":
        return part_reach(part, axis=_Z)
    if body == "gearbox2":
        return rc + part_reach(part, axis=_Z)
    from cadgen.solids.errors import SolidInputError

    raise SolidInputError("ground_clearance", f"no speed bound for the housing {part.name!r} "
                          f"on the body {body!r}")


def _fixed_ground(reach: dict) -> dict:
    """Instance bounds of housings turning at rate 1 (speed and acceleration both their reach),
    and of the fixed ground."""
    bounds = {name: (value, value) for name, value in reach.items()}
    bounds["ground"] = (0.0, 0.0)
    return bounds


def _kinematic(evaluation, key):
    return next(m.value for m in evaluation.metrics if m.key == key)


def arm_interference(params, mechanism, solids, cam, evaluation=None) -> dict:
    """Certified least distance between the two planting arms' solids over a revolution.

    ``evaluation`` (the metrics stage's) supplies the kinematic estimate beside it;
    without it the estimate is computed again.
    """
    from cadgen.sweep.fcl import FclScene
    from cadgen.sweep.search import certified_distance

    assembly = solids.assembly
    parts = {part.name: part for part in assembly.parts}
    bought = list(getattr(assembly, "bought", ()))
    arm1, arm2 = arm_groups(assembly, bought=True)
    scene = FclScene(assembly, arm1, arm2)
    bounds = _arm_part_bounds(mechanism, parts, cam, bought)
    part_of = {name: part.name for part in assembly.parts + bought
               for name, _, _ in part.instances}
    # arm 2 moves like arm 1, half a turn on: each instance has its part's bounds, and the
    # distance repeats every half turn
    speed = max(value for value, _ in bounds.values())
    acceleration = max(value for _, value in bounds.values())
    result = certified_distance(scene, lipschitz=2 * speed, acceleration=2 * acceleration,
                                upper=math.pi, atol=params.resolution.sweep_atol,
                                steps=SWEEP_STEPS,
                                instance_bounds=_arm_bounds_of(arm1 + arm2, part_of, bounds))
    kinematic = (_kinematic(evaluation, "arm_distance") if evaluation is not None
                 else _arm_distance_estimate(params, mechanism))
    return _section(result, "arm distance (solids, FCL)", params.targets.arm_distance_min,
                    kinematic)


def _arm_distance_estimate(params, mechanism):
    from kinematics.clearance import arm_distance

    return arm_distance(mechanism, steps=params.resolution.steps_per_revolution).value


def _with_riding(assembly, kinds) -> list:
    """The parts of ``kinds`` and the bought solids riding on them (a housing's flange bolts,
    nuts and washers, its dowels, its bearings; the screws under the pricking sprocket)."""
    parts = [part for part in assembly.parts if part.kind in kinds]
    hosts = {part.name for part in parts}
    return parts + [part for part in getattr(assembly, "bought", ()) if part.host in hosts]


def ground_clearance(params, design, solids, field) -> dict:
    """Certified least gap between every housing and the ground mesh over a revolution."""
    from cadgen.sweep.fcl import FclScene
    from cadgen.sweep.scene import part_reach
    from cadgen.sweep.search import certified_distance

    assembly = solids.assembly
    if params.mechanism == "pricking":
        link = design.linkage
        # every housing the assembly model places (the gear case's halves, the frame bracket)
        # and the sprocket under the case's floor: the case turns about O at rate 1 (a point
        # of it moves at most its reach from O), the bracket is fixed
        centre = (*np.asarray(link.centre, dtype=float), 0.0)
        reach = {name: (0.0 if body == "frame" else
                        part_reach(part, body_origin_local=centre, axis=_Z))
                 for part in _with_riding(assembly, ("housing", "sprocket"))
                 for name, body, _ in part.instances}
        housings = list(reach)
        speed = max(reach.values())
        result = certified_distance(FclScene(assembly, housings, ["ground"]), lipschitz=speed,
                                    acceleration=speed, atol=params.resolution.sweep_atol,
                                    steps=SWEEP_STEPS, instance_bounds=_fixed_ground(reach))
        # the case must stay out of the soil (no kinematic estimate for this mechanism)
        return _section(result, "gear case ground clearance (solids, FCL)", 0.0, None)
    rc = design.carrier_radii["C"]
    # every housing instance the assembly model places, bounded by the body it rides on:
    # gearbox 1 turns about O at rate 1; gearbox 2 about C, which circles at rc (a point moves
    # at most its reach, and accelerates at most the same, per radian); the frame is fixed
    reach, frame = {}, []
    for part in _with_riding(assembly, ("housing",)):
        for name, body, _ in part.instances:
            reach[name] = _housing_reach(part, body.split(":")[0], rc)
            if body == "frame":
                frame.append(name)
    housings = list(reach)
    speed = max(reach.values())
    scene = FclScene(assembly, housings, ["ground"])
    result = certified_distance(scene, lipschitz=speed, acceleration=speed,
                                atol=params.resolution.sweep_atol, steps=SWEEP_STEPS,
                                instance_bounds=_fixed_ground(reach))
    section = _section(result, "gearbox ground clearance (solids, FCL)",
                       params.targets.ground_clearance_min, _kinematic(field, "ground_clearance"))
    if frame:   # what the frame changes: its own gap (fixed: one pose says it all)
        gap = float(FclScene(assembly, list(frame), ["ground"]).distance(0.0).distance)
        section["frame_gap_mm"] = gap
        section["frame_note"] = (
            f"the frame (fixed, about O) stands {gap:.1f} mm above the soil; "
            + ("it is the nearest part: the frame sets the ground clearance"
               if gap <= result.minimum + 1e-9 else
               f"the rotating housings come to {result.minimum:.1f} mm of it: the frame changes "
               "nothing"))
    return section
