"""A mechanism's assembly model from its drivetrain records: every part, what holds it, where it is.

Built from the same records the solids are (:class:`cadgen.machine.model.Drivetrain`: shafts,
their seats and hubs; the gear train's meshes), duck-typed so this package stays free of
numpy. Part names are the assembly's instance names (``shaft-A-side1``, ``sun-side1``,
``gearbox2-base-arm1``, ...): the solids, the GLB's nodes, the bill and the sweeps use them.

This module is the one place that decides which copies of a made part exist: gearbox 1's
axes on both sides of carrier 1 (side 2 is side 1's part turned half a turn about O),
gearbox 2, the cam, the planter and its blades once per arm (arm 2 half a carrier turn on),
the frame and its shafts once. Given the made parts' bodies (``bodies``: each part's
kinematic body, where its solid is drawn) the model places every copy
(:class:`~cadgen.assembly.graph.Placement`); given the housing records (``housings``) its
flange and splice joints carry their bolts. Every joint carries the bought items it is
made with (:mod:`cadgen.assembly.items`): bearings, keys, screws, nuts and washers.

Each shaft is one revolute joint to the housing its first bearing is in (its other bearing is
coaxial: in the plane it adds nothing, so it is named in the joint's detail, not counted
twice, and its bearings are bought with that joint); a keyed gear is fixed to its shaft, a
gear running free on its bearings is a revolute joint to it; a hollow shaft's flange is fixed
to the housing it carries. A joint the workshop does not yet get as parts (the planter's
fixing on shaft E without a hub, the cam's screws without their fixing) is in the graph for its
kinematics and listed in :data:`NOT_MADE` so the report claims nothing it does not make. The
duckbill linkage (lever, roller, push rod, links, blades on their pins, the return spring) is
in the graph as parts when the drivetrain sized it (``fixings["duckbill"]``, with the cam) and
the solids made it; without it the blades hang on the planter and on the cam directly, marked
not made.
"""

from __future__ import annotations

import math
import re

from cadgen.assembly.axial import AxialGraph, axial_check, free_message
from cadgen.assembly.graph import AssemblyModel, Item, Joint, Placement
from cadgen.assembly.items import (bearing_item, bolted_flange_items, dowel_items, key_item,
                                   screw_items, sprocket_items)

__all__ = ["planting_model", "pricking_model", "NOT_MADE", "model_report", "ENVIRONMENT"]

#: Details of joints the graph holds for their kinematics but the build does not make as parts.
NOT_MADE = ("not yet made",)
#: Made solids that are not parts of the machine (the soil slab): the model places none.
ENVIRONMENT = frozenset({"ground"})
#: The copies of a part, by instance suffix: (body suffix, phase in rad). Side 2 of carrier 1
#: is side 1's part turned half a turn about O (``carrier1:mirrored``); arm 2 rides half a
#: carrier turn after arm 1.
COPIES = {None: ("", 0.0), "side1": ("", 0.0), "side2": (":mirrored", 0.0),
          "arm1": ("", 0.0), "arm2": ("", math.pi)}


def _slug(name: str) -> str:
    return name.replace(" ", "-")


class _Builder:
    """Parts, joints and placements as the machine's builder adds them.

    ``bodies``: ``{made part: kinematic body}``; None builds the graph alone (no placements).
    """

    def __init__(self, bodies=None, housings=None, kinds=None):
        self.parts, self.joints, self.placements, self.made = [], [], [], []
        self.bodies = bodies
        self.kinds = kinds or {}
        self.housings = housings or {}
        self._placed = set()
        self.axial = AxialGraph()

    def instance(self, stem: str, copy: str | None = None) -> str:
        """The instance name of ``stem``'s ``copy``, placed when ``stem`` is a made part."""
        name = stem if copy is None else f"{stem}-{copy}"
        if name not in self.parts:
            self.parts.append(name)
        if name not in self.made:
            self.made.append(name)
        if self.bodies is not None and stem in self.bodies and name not in self._placed:
            suffix, phase = COPIES[copy]
            self.placements.append(Placement(name, stem, self.bodies[stem] + suffix, phase,
                                             self.kinds.get(stem, "")))
            self._placed.add(name)
        return name

    def joint(self, kind, a, b, detail="", items=()):
        for part in (a, b):
            if part not in self.parts:
                self.parts.append(part)
        self.joints.append(Joint(kind, a, b, detail, tuple(items)))

    def housing(self, name: str, copy: str | None = None) -> str:
        """A split housing's halves (and the segments a printer needed), bolted together; the
        instance of its base (its first segment) that other parts join."""
        record = self.housings.get(name)
        halves = {}
        for half in ("base", "cover"):
            stem = f"{name}-{half}"
            cut = sorted((s for s in (self.bodies or {}) if re.fullmatch(rf"{stem}-\d+", s)),
                         key=lambda s: int(s.rsplit("-", 1)[1]))
            halves[half] = [self.instance(s, copy) for s in (cut or [stem])]
        bolts = ()
        if record is not None and getattr(record, "bolt_positions", None) is not None:
            bolts = bolted_flange_items(record.bolt_size, 2 * float(record.flange_thickness),
                                        len(record.bolt_positions))
        if record is not None and getattr(record, "dowels", ()):
            bolts += dowel_items(record)
        for k, (cover, base) in enumerate(zip(halves["cover"], halves["base"])):
            self.joint("fixed", cover, base, "flange bolts", bolts if k == 0 else ())
        splices = list(getattr(record, "joints", ()) or ())
        for k, splice in enumerate(splices):
            for half in ("base", "cover"):
                pieces = halves[half]
                if k + 1 < len(pieces):
                    items = (bolted_flange_items(splice.bolt_size, float(splice.grip),
                                                 len(splice.bolts)) if half == "base" else ())
                    self.joint("fixed", pieces[k + 1], pieces[k],
                               f"splice {k + 1}" + (" (its bolts join both halves)"
                                                    if half == "base" else ""), items)
        return halves["base"][0]

    def model(self, frame: str) -> AssemblyModel:
        if self.bodies is not None:
            missing = sorted(set(self.bodies) - ENVIRONMENT - {p.part for p in self.placements})
            if missing:
                raise ValueError(f"the assembly model places no copy of the made parts {missing}")
        parts = [frame] + [p for p in self.parts if p != frame]
        return AssemblyModel(tuple(parts), tuple(self.joints), frame, tuple(self.placements),
                             tuple(self.made), self.axial)


def _bearings(shaft) -> str:
    return "; ".join(f"{seat.count} x {seat.bearing.designation} in {seat.housing}'s {seat.wall}"
                     for seat in shaft.seats)


def _seat_items(shaft) -> tuple:
    return tuple(bearing_item(seat.bearing, getattr(seat, "count", 1)) for seat in shaft.seats)


def _mount_joint(b, gear, shaft_instance, mount, screw=None):
    """A gear on its shaft: free on two bearings (a revolute), keyed, or on a D-flat; ``screw``:
    the set screw that holds it along the shaft where no ring can (machine.retention)."""
    extra = ((f"; held along the shaft by {screw} onto the key",
              (Item("set screw", screw, screw, 1),)) if screw else ("", ()))
    if getattr(mount, "bearing", None) is not None:
        b.joint("revolute", gear, shaft_instance, f"runs free on 2 x {mount.bearing.designation}",
                (bearing_item(mount.bearing, 2),))
    elif mount.key is not None:
        b.joint("fixed", gear, shaft_instance, mount.key.designation + extra[0],
                (key_item(mount.key),) + extra[1])
    else:
        b.joint("fixed", gear, shaft_instance, f"D-flat {mount.flat_depth:g} mm" + extra[0],
                extra[1])


def _retention(drivetrain) -> dict:
    """``{(shaft, side): ShaftRetention}`` of the drivetrain (empty before it was designed)."""
    return {(r.shaft, r.side): r for r in getattr(drivetrain, "retention", ()) or ()}


def _axial_stack(b, retention, shaft, me, copy, housing_of, parts_of):
    """The shaft's spacers (made parts, clamped in its stack), its rings (bought with its
    bearings' joint: returned) and its axial contacts (:mod:`cadgen.assembly.axial`).
    ``housing_of(housing)`` is the housing's instance, ``parts_of``: ``{gear or hub name:
    instance}``."""
    if retention is None:
        return ()
    graph, nodes = b.axial, {}
    graph.part(me)
    for part in retention.parts:
        if part.kind == "bearing":
            seat = shaft.seats[part.ref]
            node = graph.part(f"{me}/bearing-{part.ref + 1}",
                              f"bearing {seat.bearing.designation} of {me} "
                              f"({seat.housing}'s {seat.wall})")
            housing = housing_of(seat.housing)
            graph.rest(node, housing) if part.stop == "down" else graph.rest(housing, node)
        elif part.kind == "ring":
            node = graph.part(f"{me}/ring-{part.ref}", f"retaining ring {part.designation} on {me}")
        elif part.kind == "spacer":
            node = b.instance(f"spacer-{shaft.name}-{part.ref}", copy)
            graph.part(node, f"spacer {node}")
            b.joint("fixed", node, me, f"spacer {part.z1 - part.z0:.2f} mm, clamped in the "
                    "shaft's stack")
        else:
            node = graph.part(parts_of[part.ref])
        if part.locked:
            graph.fix(node, me)
        nodes[id(part)] = node
    for lower, upper in retention.touching():
        graph.rest(nodes[id(upper)], nodes[id(lower)])
    count = len(retention.rings)
    ring = retention.rings[0].designation if count else ""
    return (Item("retaining ring", f"retaining ring {ring}", ring, count),) if count else ()


def _flange_items(flange) -> tuple:
    return screw_items(flange["bolt"], float(flange["thickness"]), int(flange["bolts"]),
                       length=flange.get("screw_length"))


def planting_model(drivetrain, meshes=(), *, bodies=None, housings=None,
                   kinds=None) -> AssemblyModel:
    """The planting machine's assembly model: frame, drive, gearbox 1 and both arms.

    ``meshes``: the gear train's ``(drive, driven)`` gear names of every pair (the stages'
    ``pair.names``); each becomes a gear joint between the gears' instances. ``bodies``: the
    made parts' kinematic bodies (``{part.name: part.body}`` of the solids), to place their
    copies; ``housings``: ``{"gearbox1": record, "gearbox2": ..., "frame": ...}`` split
    housing records, whose flange bolts (and splices) their joints then carry; ``kinds``: the
    made parts' kinds, which the placements keep.
    """
    b = _Builder(bodies, housings, kinds)
    frame = b.housing("frame")
    box1 = b.housing("gearbox1")
    box2 = {arm: b.housing("gearbox2", f"arm{arm}") for arm in (1, 2)}

    def housing_part(housing, side):
        return {"frame": frame, "gearbox1": box1}.get(housing) or box2[side]

    def copy_of(shaft, side):
        if shaft.housing == "frame":
            return None
        return f"arm{side}" if shaft.housing == "gearbox2" else f"side{side}"

    gear_instances = {}   # gear name -> {side: instance}
    retention = _retention(drivetrain)
    for shaft in drivetrain.shafts:
        sides = (shaft.side,) if shaft.housing != "gearbox2" else (1, 2)
        held = retention.get((shaft.name, shaft.side))
        screws = dict(held.set_screws) if held is not None else {}
        for side in sides:
            own = f"shaft-{shaft.name}-arm2"   # side 2's own part, its keyseats phased otherwise
            me = (b.instance(own) if side == 2 and own in (b.bodies or {}) else
                  b.instance(f"shaft-{shaft.name}", copy_of(shaft, side)))
            bearings = len(b.joints)
            b.joint("revolute", me, housing_part(shaft.seats[0].housing, side), _bearings(shaft),
                    _seat_items(shaft))
            if shaft.flange:   # a hollow shaft: in its bearing pair, bolted to what it carries
                b.joint("fixed", me, housing_part(shaft.flange["carries"], side),
                        f"flange: {shaft.flange['bolts']} x {shaft.flange['bolt']} screws",
                        _flange_items(shaft.flange))
                b.axial.fix(me, housing_part(shaft.flange["carries"], side))
            coupling = getattr(shaft, "coupling_key", None)
            if coupling is not None and side == 1:   # the user's sprocket or coupling hub
                b.joint("fixed", "input-coupling", me,
                        f"the user's sprocket or coupling hub on the stub: {coupling.designation}",
                        (key_item(coupling),))
            for mount in shaft.mounts:
                stem = _slug(mount.gear)   # the gear's file stem, as its STL and GLB node
                # a gear is copied as the housing it turns in is (C2's central gear, inside
                # gearbox 2, once per arm; planet I beside it in gearbox 1, once per side)
                housing = getattr(mount, "housing", "") or shaft.housing
                if shaft.housing == "frame" and shaft.name == "input":
                    gear = b.instance(stem)
                elif housing == "gearbox2":
                    gear = b.instance(stem, f"arm{side}")
                else:
                    gear = b.instance(stem, f"side{side}")
                gear_instances.setdefault(mount.gear, {})[side] = gear
                _mount_joint(b, gear, me, mount, screws.get(mount.gear))
            parts_of = {gear: instances[side] for gear, instances in gear_instances.items()
                        if side in instances}
            parts_of["planter"] = f"planter-shell-arm{side}"
            rings = _axial_stack(b, held, shaft, me, copy_of(shaft, side),
                                 lambda housing, side=side: housing_part(housing, side), parts_of)
            _add_items(b, bearings, rings + _hub_screw(screws, "planter"))
    for drive, driven in meshes:
        one, two = gear_instances.get(drive, {}), gear_instances.get(driven, {})
        for side in (1, 2):
            a = one.get(side, one.get(1)) if len(one) == 1 else one.get(side)
            c = two.get(side, two.get(1)) if len(two) == 1 else two.get(side)
            if a and c and not any(j.kind == "gear" and {j.a, j.b} == {a, c} for j in b.joints):
                b.joint("gear", a, c, f"mesh {drive} - {driven}")
    # on the arms: the cam on gearbox 2, the planter on shaft E, the blades on the planter
    fixings = getattr(drivetrain, "fixings", {}) or {}
    for arm in (1, 2):
        copy = f"arm{arm}"
        cam = b.instance("cam", copy)
        screwed = fixings.get("cam")
        if screwed:   # seated on the cover's roof, screwed into it
            cover = next(p for p in b.parts if p.startswith("gearbox2-cover") and p.endswith(copy))
            b.joint("fixed", cam, cover, f"{screwed['bolts']} x {screwed['screw']} in counterbores",
                    screw_items(screwed["bolt"], 0.0, int(screwed["bolts"]),
                                length=screwed["screw_length"]))
        else:
            b.joint("fixed", cam, box2[arm], "on gearbox 2's roof over E: " + NOT_MADE[0]
                    + " (screws)")
        planter = b.instance("planter-shell", copy)
        b.joint("fixed", planter, f"shaft-E-{copy}", *_hub_joint(fixings.get("planter"),
                                                                 "on shaft E"))
        linkage = fixings.get("duckbill")
        if linkage is not None and (bodies is None or "lever" in bodies):
            _duckbill_joints(b, linkage, copy, planter, cam)
            continue
        for blade in ("blade-right", "blade-left"):
            me = b.instance(blade, copy)
            b.joint("revolute", me, planter, "hinge: " + NOT_MADE[0] + " (pin)")
            b.joint("cam", me, f"cam-{copy}",
                    "opened by the cam through the duckbill linkage: " + NOT_MADE[0])
    return b.model(frame)


def _duckbill_joints(b, linkage: dict, copy: str, planter: str, cam: str) -> None:
    """One arm's duckbill linkage (:mod:`cadgen.machine.duckbill`): the lever on the planter at
    H, its roller on the cam, the pin G in the push rod's slot, the rod sliding in the tube's
    web against its spring, the links from the rod's end P2 to the blades' cranks J, the blades
    on their hinges O1.

    The roller is the bought bearing on the lever's pin, so the lever-cam contact carries it:
    as a shaft's bearings are items of its revolute, the roller's spin is the bearing's own
    and not a body of the graph (a roller body would add Norton's idle freedom to the count).
    Every body added is held by exactly the joints it needs: the mobility stays the drive's.
    """
    pins = linkage.get("pins", {})

    def items(entries) -> tuple:
        return tuple(Item(e["kind"], e["description"], e["designation"], int(e["count"]))
                     for e in entries)

    def pin(joint: str) -> tuple:
        entry = pins.get(joint)
        return ((entry["designation"], items(entry["items"])) if entry
                else (NOT_MADE[0] + " (pin)", ()))

    lever, rod = b.instance("lever", copy), b.instance("push-rod", copy)
    name, bought = pin("H")
    b.joint("revolute", lever, planter, f"lever on {name} at H, in the plate's lug", bought)
    roller = linkage.get("roller") or {}
    b.joint("cam", lever, cam, f"roller {roller.get('designation', '')} at I on the cam "
            f"(its pin {roller.get('pin', '')} pressed into the lever, {roller.get('ring', '')} "
            "under it)", items(roller.get("items", ())))
    name, bought = pin("G")
    b.joint("slot", lever, rod, f"{name} at G through the lever, in the push rod's slot", bought)
    spring = linkage.get("spring") or {}
    b.joint("prismatic", rod, planter,
            "guided in the tube's web; the return spring between the web and the rod's collar"
            + (f" ({spring['designation']})" if spring else ""),
            items(linkage.get("spring_items", ())))
    for side in ("right", "left"):
        link, blade = b.instance(f"blade-link-{side}", copy), b.instance(f"blade-{side}", copy)
        name, bought = pin("O1")
        b.joint("revolute", blade, planter, f"hinge O1: {name} through the tube's ears", bought)
        name, bought = pin("J")
        b.joint("revolute", link, blade, f"crank pin J: {name}", bought)
        name, bought = pin("P2")
        # one pin at P2 through both links and the rod's eye: bought with the right link's joint
        b.joint("revolute", link, rod, f"P2: {name} through both links and the rod's eye",
                bought if side == "right" else ())


def pricking_model(drivetrain, meshes=(), *, bodies=None, housings=None,
                   kinds=None) -> AssemblyModel:
    """The pricking machine's assembly model: the frame bracket holding the sun's shaft by its
    stub's key, the gear case turning on that shaft and driven by the sprocket bolted to it,
    the intermediate and planet shafts in the case, the rocker and needle on the planet.
    ``bodies``, ``housings`` (``{"gear-case": record}``) and ``kinds`` as for
    :func:`planting_model`."""
    held = drivetrain.rules.get("case_drive")
    b = _Builder(bodies, housings, kinds)
    frame = b.instance("frame-bracket")
    case = b.housing("gear-case")
    gears = {}
    retention = _retention(drivetrain)
    for shaft in drivetrain.shafts:
        me = b.instance(f"shaft-{shaft.name}")
        stack = retention.get((shaft.name, shaft.side))
        screws = dict(stack.set_screws) if stack is not None else {}
        if shaft.name == "sun":   # the sun does not turn: its shaft's stub keyed in the bracket
            key = shaft.coupling_key
            # and held along it by a set screw onto the key through the bracket's hub
            from cadgen.machine.retention import set_screw

            stub = set_screw(key)
            b.joint("fixed", me, frame,
                    f"{key.designation}, held by {stub} onto it" if key is not None
                    else "stub in the bracket: " + NOT_MADE[0] + " (key)",
                    (key_item(key), Item("set screw", stub, stub, 1)) if key is not None else ())
            if key is not None:
                b.axial.fix(me, frame)
        bearings = len(b.joints)
        b.joint("revolute", me, case, _bearings(shaft), _seat_items(shaft))
        for mount in shaft.mounts:
            gear = b.instance(_slug(mount.gear))
            gears[mount.gear] = gear
            _mount_joint(b, gear, me, mount, screws.get(mount.gear))
        rings = _axial_stack(b, stack, shaft, me, None, lambda housing: case,
                             {**gears, "rocker": "rocker"})
        _add_items(b, bearings, rings + _hub_screw(screws, "rocker"))
    if held:
        sprocket = held["sprocket"]
        b.joint("fixed", b.instance("case-sprocket"), case,
                f"{sprocket['bolts']} x {sprocket['bolt']} screws (the chain drives it)",
                sprocket_items(held))
    for drive, driven in meshes:
        if drive in gears and driven in gears:
            b.joint("gear", gears[drive], gears[driven], f"mesh {drive} - {driven}")
    fixings = getattr(drivetrain, "fixings", {}) or {}
    b.joint("fixed", b.instance("rocker"), "shaft-planet",
            *_hub_joint(fixings.get("rocker"), "on the planet shaft"))
    clamp = fixings.get("needle")
    if clamp:
        b.joint("fixed", b.instance("needle"), "rocker",
                f"in the holder at the rocker's end, clamped by {clamp['set_screw']}",
                (Item("set screw", clamp["set_screw"], clamp["set_screw"], 1),))
    else:
        b.joint("fixed", b.instance("needle"), "rocker", "on the rocker: " + NOT_MADE[0])
    return b.model(frame)


def _add_items(b, index: int, items: tuple) -> None:
    """Add ``items`` to the joint at ``index`` (a shaft's bearings: its rings are bought with
    them)."""
    if items:
        joint = b.joints[index]
        b.joints[index] = Joint(joint.kind, joint.a, joint.b, joint.detail,
                                joint.items + tuple(items))


def _hub_screw(screws: dict, hub: str) -> tuple:
    return (Item("set screw", screws[hub], screws[hub], 1),) if hub in screws else ()


def _hub_joint(hub, where: str) -> tuple:
    """``(detail, items)`` of a part keyed (or D-flatted) to its shaft by its hub
    (:func:`cadgen.machine.fixings.keyed_hub`), or not yet made."""
    if not hub:
        return (f"{where}: " + NOT_MADE[0] + " (bore and key)", ())
    if hub["key"] is None:
        return (f"{where}: a {hub['length']:g} mm hub on a D-flat "
                f"{hub['flat_depth']:g} mm deep", ())
    return (f"{where}: a {hub['length']:g} mm hub, {hub['key'].designation}",
            (key_item(hub["key"]),))


def model_report(model: AssemblyModel, expected: int = 1) -> dict:
    """report.json's ``assembly``: parts, joints, mobility, unconnected parts, the joints not
    yet made as parts, and the check (mobility ``expected`` from the input, nothing loose)."""
    report = model.as_report()
    report["not_made"] = [f"{j.kind} {j.a} - {j.b}: {j.detail}" for j in model.joints
                          if NOT_MADE[0] in j.detail]
    problems = model.degrees_of_freedom_check(expected=expected)
    if getattr(model, "axial", None) is not None and model.axial.parts:
        report["axial"] = axial_check(model.axial, model.frame)
        problems += [free_message(entry) for entry in report["axial"]["free"]]
    report["problems"] = problems
    report["passed"] = not problems
    if model.placements:   # the solids' model: the order a fitter puts it together in
        from cadgen.assembly.sequence import assembly_sequence

        report["sequence"] = assembly_sequence(model)
    return report
