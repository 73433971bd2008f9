"""The duckbill linkage's small bought parts: clevis pins, retaining rings, rollers, spring wire.

Tables in ``cadgen/machine/data`` (sources in its ``README.md``), read once like the other
catalogues (:mod:`cadgen.machine.catalogue`); a size outside a table is a
:class:`~cadgen.machine.catalogue.CatalogueError` naming the value and what the table holds.

* ISO 2341 form B clevis pins (head, split-pin hole) with their ISO 8738 washers and ISO 1234
  split pins (their legs' and eye's sizes): the linkage's hinge pins;
* DIN 471 retaining rings (only the small shafts the linkage uses; kept apart from the
  machine's own ring tables so the two can grow separately);
* deep-groove ball bearings of the 60, 62, 63 and 69 series small enough to run as a cam roller
  on a pin (ISO 15 boundary dimensions);
* EN 10270-1 grade DH spring wire: its minimum tensile strength by diameter.
"""

from __future__ import annotations

import math

from cadgen.machine.catalogue import CatalogueError, _rows

__all__ = ["clevis_pin", "clevis_pin_length", "split_pin", "retaining_ring", "roller_bearing",
           "roller_bearings", "spring_wires", "PIN_LENGTHS", "SPLIT_PIN_LENGTHS"]

#: The nominal lengths of ISO 2338 parallel pins and ISO 2341 clevis pins (mm), one series.
PIN_LENGTHS = (6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0, 22.0, 24.0, 26.0, 28.0, 30.0,
               32.0, 35.0, 40.0, 45.0, 50.0, 55.0, 60.0, 65.0, 70.0, 75.0, 80.0)
#: ISO 1234 split pin lengths (mm).
SPLIT_PIN_LENGTHS = (4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0, 22.0, 25.0)


def _float_row(row: dict) -> dict:
    return {key: (value if key in ("designation", "lengths") else float(value))
            for key, value in row.items()}


def clevis_pin(d: float) -> dict:
    """ISO 2341 B clevis pin of diameter ``d`` with its washer and split pin (mm).

    ``{d, head_diameter, head_height, split_pin, hole_end, washer_outside,
    washer_thickness, lengths}``: ``hole_end`` is the split-pin hole's least distance from
    the pin's end (ISO 2341's ``l_e``), ``split_pin`` the ISO 1234 size that fits the hole.
    """
    for row in _rows("clevis_pins"):
        if abs(float(row["d"]) - float(d)) < 1e-9:
            out = _float_row(row)
            out["lengths"] = tuple(float(v) for v in row["lengths"].split())
            return out
    sizes = ", ".join(row["d"] for row in _rows("clevis_pins"))
    raise CatalogueError(f"no ISO 2341 clevis pin of {d:g} mm in the table (it holds {sizes})")


def clevis_pin_length(d: float, grip: float) -> dict:
    """The shortest ISO 2341 B pin through ``grip`` mm with its washer and split pin beyond.

    The split-pin hole lies ``hole_end`` from the pin's end and must clear the washer by half
    the split pin, so ``l >= grip + washer + split_pin / 2 + hole_end``. Returns the pin's row
    with ``length``, ``needed_length`` and the three designations.
    """
    pin = clevis_pin(d)
    needed = float(grip) + pin["washer_thickness"] + pin["split_pin"] / 2 + pin["hole_end"]
    length = next((value for value in pin["lengths"] if value >= needed - 1e-9), None)
    if length is None:
        raise CatalogueError(f"no ISO 2341 B {d:g} mm clevis pin reaches {needed:.1f} mm (the "
                             f"longest is {pin['lengths'][-1]:g} mm)")
    # a split pin about twice the pin's diameter long bends round it
    split = next(v for v in SPLIT_PIN_LENGTHS if v >= 2 * d - 1e-9)
    return {**pin, "length": length, "needed_length": needed, "split_length": split,
            "pin": f"ISO 2341 B {d:g} x {length:g} - St",
            "washer": f"ISO 8738 {d:g} - 160 HV",
            "split": f"ISO 1234 {pin['split_pin']:g} x {split:g} - St"}


def split_pin(nominal: float) -> dict:
    """ISO 1234 split pin of ``nominal`` size (the hole it goes through, mm): ``{nominal, d_max
    (its two legs together), c_max (its eye), b, a_max}``."""
    for row in _rows("split_pins"):
        if abs(float(row["nominal"]) - float(nominal)) < 1e-9:
            return _float_row(row)
    sizes = ", ".join(row["nominal"] for row in _rows("split_pins"))
    raise CatalogueError(f"no ISO 1234 split pin of {float(nominal):g} mm in the table (it holds "
                         f"{sizes})")


def retaining_ring(shaft: float) -> dict:
    """DIN 471 retaining ring for a ``shaft`` mm pin (the machine's table,
    :func:`cadgen.machine.catalogue.shaft_ring`): ``{shaft, groove, thickness, groove_width,
    ring_outside, designation}`` (mm)."""
    from cadgen.machine.catalogue import shaft_ring

    ring = shaft_ring(shaft)
    return {"shaft": ring["d1"], "groove": ring["d2"], "thickness": ring["s"],
            "groove_width": ring["m"], "ring_outside": ring["d4"],
            "designation": f"DIN 471 {float(shaft):g} x {ring['s']:g}"}


def roller_bearings() -> tuple:
    """Every small bearing that may run as a cam roller: dicts ``{designation, d, D, B}`` (mm)."""
    return tuple(_float_row(row) for row in _rows("roller_bearings"))


def roller_bearing(outside: float) -> dict:
    """The bearing whose outside diameter is ``outside`` mm (the cam's roller): the narrowest,
    then the one with the largest bore (the stiffest pin), of those that match."""
    matches = [row for row in roller_bearings() if abs(row["D"] - float(outside)) < 1e-6]
    if not matches:
        sizes = ", ".join(f"{row['D']:g}" for row in sorted(roller_bearings(),
                                                             key=lambda r: r["D"]))
        raise CatalogueError(f"no catalogue bearing is {outside:g} mm across to run as the cam's "
                             f"roller (outside diameters: {sizes} mm)")
    return min(matches, key=lambda row: (row["B"], -row["d"]))


def spring_wires() -> tuple:
    """EN 10270-1 DH wire diameters with their tensile strength: ``((d, Rm_min, Rm_max), ...)``
    in mm and MPa, thinnest first."""
    rows = [(float(r["d"]), float(r["Rm_min"]), float(r["Rm_max"])) for r in _rows("spring_wire")]
    if any(not math.isfinite(value) for row in rows for value in row):
        raise CatalogueError("the spring wire table holds a number that is not finite")
    return tuple(sorted(rows))
