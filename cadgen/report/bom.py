"""The bill of materials: every part to make and every part to buy, with counts.

Made parts come from the solids a build wrote (one row per part file: its material
and process from ``[manufacturing]``, its mass at that material's density, the
number of copies the assembly places). Bought parts come from the machine design
(:mod:`cadgen.machine`): the bearings of every seat, the parallel keys of every
keyed gear, and per split housing its flange bolts (ISO 4762 socket head cap
screws), nuts (ISO 4032) and washers (ISO 7089, one under the head and one under the
nut). A housing both planting arms carry (gearbox 2) counts twice, as the
assembly places it twice.

``bom_rows`` gives the rows (dicts, JSON-ready); ``bom_csv`` the same rows as the
text of ``bom.csv``.
"""

from __future__ import annotations

import csv
import io
import math
import re
from collections import Counter

__all__ = ["BOM_COLUMNS", "bom_rows", "bom_csv", "bolt_set"]

#: The columns of bom.csv, in order.
BOM_COLUMNS = ("item", "source", "part", "description", "designation", "material", "process",
               "quantity", "mass_each_kg", "file")


def bolt_set(thread: str, grip: float) -> dict:
    """The screw, nut and washers that clamp ``grip`` mm of flange: designations and length.

    The screw is the shortest ISO 4762 standard length through the grip, two washers
    (ISO 7089), the nut (ISO 4032) and two thread pitches beyond it.
    """
    from cadgen.machine.catalogue import nut, screw_length, socket_screw, washer

    nut_row, washer_row = nut(thread), washer(thread)
    # the screw's end stands at least two thread pitches out of the nut
    needed = (grip + 2 * float(washer_row["h"]) + float(nut_row["m"])
              + 2 * socket_screw(thread)["pitch"])
    length = screw_length(thread, needed)
    size = thread.removeprefix("M")
    return {"screw": f"ISO 4762 {thread} x {length:g} - 8.8", "screw_length": length,
            "nut": f"ISO 4032 {thread} - 8", "washer": f"ISO 7089 {size} - 200 HV",
            "needed_length": needed}


def _copies(assembly) -> dict:
    """How many times the assembly places each housing (``gearbox2``: once per arm)."""
    out = {}
    for part in assembly.parts:
        # "<name>-base", or "<name>-base-1" for a housing cut into segments (each segment
        # is placed as often as the whole)
        if part.kind == "housing" and part.name.endswith(("-base", "-base-1")):
            stem = part.name.removesuffix("-1").removesuffix("-base")
            out[stem] = len(part.instances) or 1
    return out


def _description(part: dict) -> str:
    """What a made part is: its kind's words; a housing half says which half and which
    segment (a printed housing too long for the bed is cut into bolted segments)."""
    if part["part"] == "frame-bracket":
        return "frame bracket (holds the sun's shaft; the transplanter's mounting holes)"
    if part["kind"] == "housing":
        match = re.search(r"-(base|cover)(?:-(\d+))?$", part["part"])
        if match:
            half, segment = match.groups()
            what = ("frame (transmission box)" if part["part"].startswith("frame-")
                    else "gearbox housing")
            return f"{what} {half}" + (f", segment {segment}" if segment else "")
    return _DESCRIPTIONS.get(part["kind"], part["kind"])


def _made_rows(solids_report: dict, fits) -> list:
    rows = []
    for part in solids_report.get("parts", []):
        material = fits.material(part["kind"])
        rows.append({"source": "make", "part": part["part"],
                     "description": _description(part),
                     "designation": "", "material": material.name,
                     "process": material.process, "quantity": int(part["instances"]),
                     "mass_each_kg": part["mass_kg"], "file": part["file"]})
    return rows


_DESCRIPTIONS = {"gear": "gear", "housing": "gearbox housing half", "cam": "cam plate",
                 "planter": "planter (arm plate and duckbill tube)", "blade": "duckbill blade",
                 "rocker": "rocker", "needle": "needle", "shaft": "shaft"}


def _bought_rows(drivetrain, housings: dict, copies: dict, gears: set) -> list:
    """Bearings of every seat, keys of the gears that were made (``gears``: their part names),
    and each housing's flange bolts, nuts and washers (and those of the splices joining its
    segments, when it was cut to fit a printer), times the housing's copies."""
    bearings, keys, fasteners = Counter(), Counter(), Counter()
    describe = {}
    for shaft in drivetrain.shafts:
        n = copies.get(shaft.housing, 1)
        for seat in shaft.seats:
            bearing = seat.bearing
            name = (f"deep-groove ball bearing {bearing.designation}-2Z "
                    f"({bearing.bore:g} x {bearing.outside:g} x {bearing.width:g} mm)")
            # a seat in the shaft's own housing is placed as often as it; one in another
            # housing (C2's in gearbox 2's roof) belongs to this shaft's record once
            placed = copies.get(seat.housing, 1) if seat.housing == shaft.housing else 1
            bearings[name] += placed * getattr(seat, "count", 1)
            describe[name] = ("bearing", bearing.designation)
        for mount in shaft.mounts:
            if mount.key is not None and mount.gear.replace(" ", "-") in gears:
                keys[mount.key.designation] += n
                describe[mount.key.designation] = ("key", mount.key.designation)
            bearing = getattr(mount, "bearing", None)
            if bearing is not None:   # a gear running free on the shaft: two in its hub
                name = (f"deep-groove ball bearing {bearing.designation}-2Z "
                        f"({bearing.bore:g} x {bearing.outside:g} x {bearing.width:g} mm)")
                bearings[name] += 2 * n
                describe[name] = ("bearing", bearing.designation)
        coupling = getattr(shaft, "coupling_key", None)
        if coupling is not None and shaft.side == 1:   # the stub's key, for the input's hub
            keys[coupling.designation] += 1
            describe[coupling.designation] = ("key", coupling.designation)
        flange = getattr(shaft, "flange", None)
        if flange and shaft.side == 1:   # the carrying flange's screws, per copy of the shaft
            sides = sum(1 for s in drivetrain.shafts if s.name == shaft.name)
            from cadgen.machine.catalogue import screw_length

            thread = flange["bolt"]
            length = screw_length(thread, float(flange["thickness"])
                                  + 1.5 * float(thread.removeprefix("M")))
            item = f"ISO 4762 {thread} x {length:g} - 8.8"
            fasteners[item] += sides * int(flange["bolts"])
            describe[item] = ("socket head cap screw", item)
    held = drivetrain.rules.get("case_drive")
    if held:   # the pricking case's chain sprocket and its screws into the case's floor
        sprocket = held["sprocket"]
        item = (f"chain sprocket ISO 606 {held['chain']['designation']}, plate wheel, "
                f"z = {sprocket['teeth']}, bored {sprocket['bore']:.1f} mm, "
                f"{sprocket['bolts']} x {sprocket['bolt']} holes on a "
                f"{2 * sprocket['bolt_circle_radius']:.1f} mm circle")
        fasteners[item] += 1
        describe[item] = ("sprocket", f"ISO 606 {held['chain']['designation']} z{sprocket['teeth']}")
        from cadgen.machine.catalogue import screw_length

        size = float(sprocket["bolt"].removeprefix("M"))
        length = screw_length(sprocket["bolt"], sprocket["width"] + 1.5 * size)
        screw = f"ISO 4762 {sprocket['bolt']} x {length:g} - 8.8"
        fasteners[screw] += int(sprocket["bolts"])
        describe[screw] = ("socket head cap screw", screw)
    for name, housing in housings.items():
        count = len(getattr(housing, "bolt_positions", ()))
        if not count:
            continue
        # the flange's bolts, then each splice's (its own grip: both lugs)
        sets = [(count, housing.bolt_size, 2 * float(housing.flange_thickness))]
        sets += [(len(joint.bolts), joint.bolt_size, float(joint.grip))
                 for joint in getattr(housing, "joints", ())]
        for per_housing, thread, grip in sets:
            n = copies.get(name, 1) * per_housing
            bolts = bolt_set(thread, grip)
            for item, what in ((bolts["screw"], "socket head cap screw"),
                               (bolts["nut"], "hexagon nut"), (bolts["washer"], "plain washer")):
                fasteners[item] += n * (2 if what == "plain washer" else 1)
                describe[item] = (what, item)
    rows = []
    for counter, kind in ((bearings, "bearing"), (keys, "key"), (fasteners, None)):
        for name in sorted(counter):
            what, designation = describe[name]
            rows.append({"source": "buy", "part": what, "description": name,
                         "designation": designation, "material": "steel", "process": "bought",
                         "quantity": int(counter[name]), "mass_each_kg": None, "file": ""})
    return rows


def bom_rows(solids_outcome, solids_report: dict, drivetrain, params) -> list:
    """Every made and bought part, numbered: made parts first (assembly order), then bought.

    Parameters
    ----------
    solids_outcome : cadgen.solids.outcome.SolidsOutcome
    solids_report : dict
        :func:`cadgen.solids.outcome.solids_report` of it (masses, files, instances).
    drivetrain : cadgen.machine.model.Drivetrain or None
        None: no bought parts are listed (the machine design did not run).
    params : validated parameters (``manufacturing.process``).
    """
    from cadgen.machine.fits import process_fits

    fits = process_fits(params.manufacturing.process)
    rows = _made_rows(solids_report, fits)
    if drivetrain is not None:
        made = {part.name for part in solids_outcome.assembly.parts if part.kind == "gear"}
        rows += _bought_rows(drivetrain, solids_outcome.housings,
                             _copies(solids_outcome.assembly), made)
    for number, row in enumerate(rows, start=1):
        row["item"] = number
    return [{column: row.get(column) for column in BOM_COLUMNS} for row in rows]


def bom_csv(rows) -> str:
    """The rows as CSV text (masses to the gram's thousandth, blanks for bought parts)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(BOM_COLUMNS)
    for row in rows:
        mass = row.get("mass_each_kg")
        writer.writerow([row["item"], row["source"], row["part"], row["description"],
                         row["designation"], row["material"], row["process"], row["quantity"],
                         "" if mass is None or not math.isfinite(mass) else f"{mass:.6f}",
                         row["file"]])
    return buffer.getvalue()
