"""The order a fitter puts the machine together in, read from the assembly model's joints.

Every holding joint (fixed, revolute, prismatic, or a pin in a slot) is one step: which part goes
onto which, what makes the joint and what it is bought with, with the tightening torque of its
screws. The steps come in the order a workshop works:

1. sub-assemblies: each gear keyed to, or run on its bearings on, its shaft;
2. the housings outward from the frame (a breadth-first walk of the holding joints from the
   frame): into each housing's base its shafts (their bearings pressed into the seats), the
   hollow shafts' flanges bolted to the housing they carry, then the cover closed on its dowels
   and bolts; the splices of a housing cut into segments before that;
3. what rides on the outside: the cam, the planter, the needle, the sprocket, in the same walk;
4. a frame that is no housing (the pricking machine's bracket) takes the machine last;
5. a contact that is bought with something (the duckbill lever's roller, which meets the cam)
   is a step just before its part goes in: the roller is fitted to the lever first.

Other meshes and cam contacts are no steps (they follow from the placing). Standard library
only.
"""

from __future__ import annotations

import re
from collections import deque

__all__ = ["assembly_sequence", "TIGHTENING_TORQUE_NM", "HOLDING"]

#: A housing's base (or one of its segments), on a side or an arm.
_BASE = re.compile(r"-base(-\d+)?(-(arm|side)\d)?$")

#: Tightening torque (N m) of ISO 4762 / ISO 4017 screws of class 8.8 with a friction
#: coefficient of 0.14 in thread and head (the usual table from VDI 2230, 90 % of the yield
#: point); into a tapped aluminium housing take no more than 80 % of it. The values as Röhm's
#: DURO-M operating manual tabulates them for ISO 4762 8.8 (1.27, 3.0, 5.9, 10.1, 24.6, 48,
#: 84 N m for M3 to M12); other makers' tables at 0.14 round them to 1.3, 2.9-3.0, 5.9-6, 10,
#: 25, 49, 85.
TIGHTENING_TORQUE_NM = {"M3": 1.3, "M4": 3.0, "M5": 5.9, "M6": 10.1, "M8": 24.6, "M10": 48.0,
                        "M12": 84.0}
#: Joint kinds that hold a part in place: one step each.
HOLDING = ("fixed", "revolute", "prismatic", "slot")


def _torque(item) -> str:
    match = re.search(r"\b(M\d+)\b", item.designation)
    if item.kind != "socket head cap screw" or not match or match.group(1) not in TIGHTENING_TORQUE_NM:
        return ""
    return f", tightened to {TIGHTENING_TORQUE_NM[match.group(1)]:g} N m"


def _items(joint) -> list:
    counts = {}
    for item in joint.items:
        key = (item.description, _torque(item))
        counts[key] = counts.get(key, 0) + item.count
    return [f"{n} x {description}{torque}" for (description, torque), n in counts.items()]


def _is_gear_on_shaft(joint, kinds: dict) -> bool:
    """A gear keyed to, or run on its bearings on, its shaft (the placements' kinds say which)."""
    return {kinds.get(joint.a), kinds.get(joint.b)} == {"gear", "shaft"}


def assembly_sequence(model) -> list[dict]:
    """The numbered steps (``step``, ``part``, ``onto``, ``joint``, ``how``, ``bought``) that put
    ``model``'s machine together (see the module notes); every holding joint once."""
    holding = [j for j in model.joints if j.kind in HOLDING]
    kinds = {p.instance: p.kind for p in model.placements}
    done, steps = set(), []

    def add(joint, part, onto):
        if id(joint) in done:
            return
        done.add(id(joint))
        steps.append({"step": len(steps) + 1, "part": part, "onto": onto, "joint": joint.kind,
                      "how": joint.detail, "bought": _items(joint)})

    for joint in holding:   # 1. each shaft's sub-assembly
        if _is_gear_on_shaft(joint, kinds):
            gear, shaft = ((joint.a, joint.b) if kinds.get(joint.a) == "gear"
                           else (joint.b, joint.a))
            add(joint, gear, shaft)
    # 2. the housings outward from the frame, each base's shafts before its cover. A frame that
    # is no housing (the pricking machine's bracket) takes the assembled machine last: the walk
    # starts at the first housing's base and the frame's joints are the final steps
    neighbours = {}
    for joint in holding:
        neighbours.setdefault(joint.a, []).append(joint)
        neighbours.setdefault(joint.b, []).append(joint)
    root = model.frame
    mounted_last = not _BASE.search(model.frame)
    if mounted_last:
        root = next((p for p in model.parts if _BASE.search(p)), model.frame)
        for joint in neighbours.get(model.frame, []):
            done.add(id(joint))   # held back until the end
    order, seen = [], {root}
    queue = deque([root])
    while queue:
        part = queue.popleft()
        order.append(part)
        for joint in neighbours.get(part, []):
            other = joint.b if joint.a == part else joint.a
            if other not in seen:
                seen.add(other)
                queue.append(other)
    bases = [p for p in order if _BASE.search(p) or p == model.frame]
    for base in bases:
        joints = neighbours.get(base, [])
        for joint in joints:   # splices, shafts in the base, flanges bolted to it
            other = joint.b if joint.a == base else joint.a
            if "-cover" in other or _is_gear_on_shaft(joint, kinds):
                continue
            if other.startswith("shaft-") or "splice" in joint.detail:
                add(joint, other, base)
        for joint in joints:   # then the cover, on its dowels and bolts
            other = joint.b if joint.a == base else joint.a
            if "-cover" in other:
                for splice in neighbours.get(other, []):   # a cut cover's segments first
                    if "splice" in splice.detail:
                        add(splice, splice.a, splice.b)
                add(joint, other, base)
    position = {part: k for k, part in enumerate(order)}
    for part in order:   # 3. the rest, in the walk's order: the later part onto the earlier
        for joint in neighbours.get(part, []):
            first, second = sorted((joint.a, joint.b), key=lambda p: position.get(p, len(order)))
            add(joint, second, first)
    if mounted_last:   # 4. the assembled machine onto its frame
        for joint in neighbours.get(model.frame, []):
            done.discard(id(joint))
            add(joint, joint.b if joint.a == model.frame else joint.a, model.frame)
    # 5. a contact bought with something (the duckbill lever's roller, on its pin pressed into
    # the lever): fitted to its part just before that part goes in (the planter's plate covers
    # the pin's end once the lever is on its pivot)
    for joint in model.joints:
        if joint.kind not in HOLDING and joint.items:
            add(joint, joint.a, joint.b)
            step = steps.pop()
            at = next((k for k, s in enumerate(steps) if s["part"] == joint.a), len(steps))
            steps.insert(at, step)
    for number, step in enumerate(steps, start=1):
        step["step"] = number
    return steps
