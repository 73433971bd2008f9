"""A mechanism's joint graph from its drivetrain records: every part and what holds it.

Built from the same records the solids are (:class:`cadgen.machine.model.Drivetrain`: shafts,
their seats and hubs; the gear train's meshes), duck-typed so this package stays free of
numpy. Part names are the assembly's instance names (``shaft-A-side1``, ``sun-side1``,
``gearbox2-base-arm1``, ...): the joints speak of the parts the GLB and the bill show.

Each shaft is one revolute joint to the housing its first bearing is in (its other bearing is
coaxial: in the plane it adds nothing, so it is named in the joint's detail, not counted
twice); a keyed gear is fixed to its shaft, a gear running free on its bearings is a revolute
joint to it; a hollow shaft's flange is fixed to the housing it carries. A joint the workshop
does not yet get as parts (the planter's fixing on shaft E, the cam's screws, the blades'
hinge pins and the duckbill linkage between cam and blades) is in the graph for its kinematics
and listed in :data:`NOT_MADE` so the report claims nothing it does not make.
"""

from __future__ import annotations

from cadgen.assembly.graph import AssemblyModel, Joint

__all__ = ["planting_model", "pricking_model", "NOT_MADE", "model_report"]

#: Details of joints the graph holds for their kinematics but the build does not make as parts.
NOT_MADE = ("not yet made",)


def _slug(name: str) -> str:
    return name.replace(" ", "-")


class _Builder:
    def __init__(self, frame: str):
        self.parts, self.joints = [frame], []
        self.frame = frame

    def joint(self, kind, a, b, detail=""):
        for part in (a, b):
            if part not in self.parts:
                self.parts.append(part)
        self.joints.append(Joint(kind, a, b, detail))

    def model(self) -> AssemblyModel:
        return AssemblyModel(tuple(self.parts), tuple(self.joints), self.frame)


def _bearings(shaft) -> str:
    return "; ".join(f"{seat.count} x {seat.bearing.designation} in {seat.housing}'s {seat.wall}"
                     for seat in shaft.seats)


def planting_model(drivetrain, meshes=()) -> AssemblyModel:
    """The planting machine's joint graph: frame, drive, gearbox 1 and both arms.

    ``meshes``: the gear train's ``(drive, driven)`` gear names of every pair (the stages'
    ``pair.names``); each becomes a gear joint between the gears' instances.
    """
    b = _Builder("frame-base")
    b.joint("fixed", "frame-cover", "frame-base", "flange bolts")
    b.joint("fixed", "gearbox1-cover", "gearbox1-base", "flange bolts")
    for arm in (1, 2):
        b.joint("fixed", f"gearbox2-cover-arm{arm}", f"gearbox2-base-arm{arm}", "flange bolts")

    def housing_part(housing, side):
        return {"frame": "frame-base", "gearbox1": "gearbox1-base"}.get(
            housing, f"gearbox2-base-arm{side}")

    def shaft_part(shaft, side):
        if shaft.housing == "frame":
            return f"shaft-{shaft.name}"
        if shaft.housing == "gearbox2":
            return f"shaft-{shaft.name}-arm{side}"
        return f"shaft-{shaft.name}-side{side}"

    gear_instances = {}   # gear name -> {side: instance}
    for shaft in drivetrain.shafts:
        sides = (shaft.side,) if shaft.housing != "gearbox2" else (1, 2)
        for side in sides:
            me = shaft_part(shaft, side)
            first = shaft.seats[0]
            if shaft.flange:   # a hollow shaft: in its bearing pair, bolted to what it carries
                b.joint("revolute", me, housing_part(first.housing, side), _bearings(shaft))
                b.joint("fixed", me, housing_part(shaft.flange["carries"], side),
                        f"flange: {shaft.flange['bolts']} x {shaft.flange['bolt']} screws")
            else:
                b.joint("revolute", me, housing_part(first.housing, side), _bearings(shaft))
            for mount in shaft.mounts:
                stem = _slug(mount.gear)   # the gear's file stem, as its STL and GLB node
                if shaft.housing == "frame" and shaft.name == "input":
                    gear = stem
                elif shaft.housing == "gearbox2":
                    gear = f"{stem}-arm{side}"
                else:
                    gear = f"{stem}-side{side}"
                gear_instances.setdefault(mount.gear, {})[side] = gear
                if mount.bearing is not None:
                    b.joint("revolute", gear, me, f"runs free on 2 x {mount.bearing.designation}")
                elif mount.key is not None:
                    b.joint("fixed", gear, me, mount.key.designation)
                else:
                    b.joint("fixed", gear, me, f"D-flat {mount.flat_depth:g} mm")
    for drive, driven in meshes:
        one, two = gear_instances.get(drive, {}), gear_instances.get(driven, {})
        for side in (1, 2):
            a = one.get(side, one.get(1)) if len(one) == 1 else one.get(side)
            c = two.get(side, two.get(1)) if len(two) == 1 else two.get(side)
            if a and c and not any(j.kind == "gear" and {j.a, j.b} == {a, c} for j in b.joints):
                b.joint("gear", a, c, f"mesh {drive} - {driven}")
    # on the arms: the cam on gearbox 2, the planter on shaft E, the blades on the planter
    for arm in (1, 2):
        box = f"gearbox2-base-arm{arm}"
        b.joint("fixed", f"cam-arm{arm}", box, "on gearbox 2's roof over E: " + NOT_MADE[0]
                + " (screws)")
        b.joint("fixed", f"planter-shell-arm{arm}", f"shaft-E-arm{arm}",
                "on shaft E: " + NOT_MADE[0] + " (bore and key)")
        for blade in ("blade-right", "blade-left"):
            b.joint("revolute", f"{blade}-arm{arm}", f"planter-shell-arm{arm}",
                    "hinge: " + NOT_MADE[0] + " (pin)")
            b.joint("cam", f"{blade}-arm{arm}", f"cam-arm{arm}",
                    "opened by the cam through the duckbill linkage: " + NOT_MADE[0])
    return b.model()


def pricking_model(drivetrain, meshes=()) -> AssemblyModel:
    """The pricking machine's joint graph: the frame bracket holding the sun's shaft by its
    stub's key, the gear case turning on that shaft and driven by the sprocket bolted to it,
    the intermediate and planet shafts in the case, the rocker and needle on the planet."""
    held = drivetrain.rules.get("case_drive")
    b = _Builder("frame-bracket")
    b.joint("fixed", "gear-case-cover", "gear-case-base", "flange bolts")
    gears = {}
    for shaft in drivetrain.shafts:
        me = f"shaft-{shaft.name}"
        if shaft.name == "sun":   # the sun does not turn: its shaft's stub keyed in the bracket
            b.joint("fixed", me, "frame-bracket",
                    shaft.coupling_key.designation if shaft.coupling_key is not None
                    else "stub in the bracket: " + NOT_MADE[0] + " (key)")
        b.joint("revolute", me, "gear-case-base", _bearings(shaft))
        for mount in shaft.mounts:
            gear = _slug(mount.gear)
            gears[mount.gear] = gear
            b.joint("fixed", gear, me, mount.key.designation if mount.key is not None
                    else f"D-flat {mount.flat_depth:g} mm")
    if held:
        sprocket = held["sprocket"]
        b.joint("fixed", "case-sprocket", "gear-case-base",
                f"{sprocket['bolts']} x {sprocket['bolt']} screws (the chain drives it)")
    for drive, driven in meshes:
        if drive in gears and driven in gears:
            b.joint("gear", gears[drive], gears[driven], f"mesh {drive} - {driven}")
    b.joint("fixed", "rocker", "shaft-planet", "on the planet shaft: " + NOT_MADE[0])
    b.joint("fixed", "needle", "rocker", "on the rocker: " + NOT_MADE[0])
    return b.model()


def model_report(model: AssemblyModel, expected: int = 1) -> dict:
    """report.json's ``assembly``: parts, joints, mobility, unconnected parts, the joints not
    yet made as parts, and the check (mobility ``expected`` from the input, nothing loose)."""
    report = model.as_report()
    report["not_made"] = [f"{j.kind} {j.a} - {j.b}: {j.detail}" for j in model.joints
                          if NOT_MADE[0] in j.detail]
    problems = model.degrees_of_freedom_check(expected=expected)
    report["problems"] = problems
    report["passed"] = not problems
    return report
