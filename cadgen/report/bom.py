"""The bill of materials: every part to make and every part to buy, with counts.

Made parts come from the solids a build wrote (one row per part file: its material
and process from ``[manufacturing]``, its mass at that material's density, the
number of copies the assembly model places). Bought parts are the items the assembly
model's joints are made with (:mod:`cadgen.assembly.items`): the bearings of every
seat, the parallel keys of every keyed gear, and per split housing its flange bolts
(ISO 4762 socket head cap screws), nuts (ISO 4032) and washers (ISO 7089, one under the
head and one under the nut), summed over the joints: a housing both planting arms carry
(gearbox 2) counts twice, as the model has its joints once per arm.

``bom_rows`` gives the rows (dicts, JSON-ready); ``bom_csv`` the same rows as the
text of ``bom.csv``.
"""

from __future__ import annotations

import csv
import io
import math
import re

__all__ = ["BOM_COLUMNS", "bom_rows", "bom_csv"]

#: The columns of bom.csv, in order.
BOM_COLUMNS = ("item", "source", "part", "description", "designation", "material", "process",
               "quantity", "mass_each_kg", "file")


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
                 "rocker": "rocker", "needle": "needle", "shaft": "shaft",
                 "spacer": "spacer (turned sleeve between the parts on a shaft)",
                 "lever": "duckbill cam lever (bell crank H-I-G, the roller's pin pressed in)",
                 "push-rod": "duckbill push rod (collar with the G slot, eye at P2)",
                 "link": "duckbill blade link (J to P2)"}


#: The bought rows' order: bearings, then keys, then the rest (screws, nuts, washers, the
#: sprocket), each group by its description.
_BOUGHT_GROUPS = {"bearing": 0, "key": 1}


def _bought_rows(model, present) -> list:
    """Every bought item the assembly model's joints need, summed over the joints whose parts
    were made (``present``: the placed instances; a gear not cut needs no key)."""
    items = sorted(model.bought(present),
                   key=lambda entry: (_BOUGHT_GROUPS.get(entry[0].kind, 2), entry[0].description))
    return [{"source": "buy", "part": item.kind, "description": item.description,
             "designation": item.designation, "material": "steel", "process": "bought",
             "quantity": int(total), "mass_each_kg": None, "file": ""}
            for item, total in items]


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
    from cadgen.machine.fits import design_fits

    fits = design_fits(params)
    rows = _made_rows(solids_report, fits)
    model = getattr(solids_outcome.assembly, "model", None)
    if drivetrain is not None and model is not None:
        present = {name for part in solids_outcome.assembly.parts
                   for name, _, _ in part.instances}
        rows += _bought_rows(model, present)
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
