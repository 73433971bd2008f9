"""The machine-element catalogues: bearings, parallel keys, clearance holes, screws, nuts, washers.

The tables are package data (``cadgen/machine/data/*.csv``, sources in its
``README.md``), read once with :mod:`importlib.resources` and cached. Every lookup
returns plain numbers or the :mod:`cadgen.machine.model` records; a size outside a
table is a :class:`CatalogueError` (also a ``ValueError``) naming the value and the
table's range, never a silent nearest row.
"""

from __future__ import annotations

import csv
import importlib.resources
from functools import lru_cache

from cadgen.machine.model import Bearing, KeySize

__all__ = ["CatalogueError", "bearings", "bearings_with_bore", "key_for_shaft", "key_length",
           "key_lengths", "clearance_hole", "socket_screw", "screw_length", "nut", "washer",
           "preferred_diameters", "shaft_ring", "SERIES"]

#: ISO 273's clearance-hole series.
SERIES = ("fine", "medium", "coarse")


class CatalogueError(ValueError):
    """A size the catalogue does not hold."""


@lru_cache(maxsize=None)
def _rows(name: str) -> tuple:
    """The rows of ``data/<name>.csv`` as dicts of strings (read once)."""
    text = importlib.resources.files("cadgen.machine").joinpath("data", f"{name}.csv").read_text(
        encoding="utf-8")
    return tuple(csv.DictReader(text.splitlines()))


def _by_thread(name: str, thread: str) -> dict:
    for row in _rows(name):
        if row["thread"] == thread:
            return row
    threads = ", ".join(row["thread"] for row in _rows(name))
    raise CatalogueError(f"thread {thread!r} is not in the {name} table (it holds {threads})")


# ------------------------------------------------------------------ bearings
@lru_cache(maxsize=None)
def bearings() -> tuple:
    """Every catalogue bearing, as :class:`~cadgen.machine.model.Bearing`, by bore then OD."""
    rows = [Bearing(row["designation"], float(row["d"]), float(row["D"]), float(row["B"]),
                    float(row["C_kN"]), float(row["C0_kN"])) for row in _rows("bearings")]
    return tuple(sorted(rows, key=lambda b: (b.bore, b.outside, b.width)))


def bearings_with_bore(d: float) -> list:
    """The bearings of bore ``d`` (mm), smallest outside diameter first; empty if none."""
    return [b for b in bearings() if abs(b.bore - float(d)) < 1e-9]


def preferred_diameters() -> tuple:
    """The shaft diameters a bearing exists for (the catalogue's bores, mm), ascending."""
    return tuple(sorted({b.bore for b in bearings()}))


# ------------------------------------------------------------------ keys
@lru_cache(maxsize=None)
def key_lengths() -> tuple:
    """DIN 6885-1's standard key lengths (mm), ascending."""
    return tuple(sorted(float(row["length"]) for row in _rows("key_lengths")))


def key_length(max_length: float) -> float:
    """The longest standard key length no longer than ``max_length`` (mm), e.g. the hub's width."""
    fitting = [length for length in key_lengths() if length <= float(max_length) + 1e-9]
    if not fitting:
        raise CatalogueError(f"no standard key is as short as {max_length:g} mm (the shortest is "
                             f"{key_lengths()[0]:g} mm): widen the hub")
    return fitting[-1]


def key_for_shaft(d: float, length: float | None = None) -> KeySize:
    """The DIN 6885-1 form A key for a shaft of diameter ``d`` (mm).

    ``length`` is the key's length (mm; default: the shortest standard length).
    Ranges are "over ... up to and including ..." as in the standard.
    """
    d = float(d)
    for row in _rows("keys"):
        if float(row["shaft_over"]) < d <= float(row["shaft_to"]):
            return KeySize(float(row["b"]), float(row["h"]), float(row["t1"]), float(row["t2"]),
                           key_lengths()[0] if length is None else float(length))
    low, high = float(_rows("keys")[0]["shaft_over"]), float(_rows("keys")[-1]["shaft_to"])
    raise CatalogueError(f"no DIN 6885-1 key in the table for a {d:g} mm shaft (the table covers "
                         f"shafts over {low:g} up to {high:g} mm)")


# ------------------------------------------------------------------ fasteners
def clearance_hole(thread: str, series: str = "medium") -> float:
    """ISO 273 clearance hole diameter (mm) for ``thread`` ("M3" .. "M12") in ``series``."""
    if series not in SERIES:
        raise CatalogueError(f"clearance-hole series {series!r} is not one of {SERIES}")
    return float(_by_thread("clearance_holes", thread)[series])


def socket_screw(thread: str) -> dict:
    """ISO 4762 socket head cap screw: ``{thread, pitch, head_diameter, head_height, lengths}``."""
    row = _by_thread("socket_screws", thread)
    return {"thread": thread, "pitch": float(row["pitch"]),
            "head_diameter": float(row["head_diameter"]),
            "head_height": float(row["head_height"]),
            "lengths": tuple(float(v) for v in row["lengths"].split())}


def screw_length(thread: str, minimum: float) -> float:
    """The shortest standard ISO 4762 length (mm) of ``thread`` that is at least ``minimum``."""
    lengths = socket_screw(thread)["lengths"]
    for length in lengths:
        if length >= float(minimum) - 1e-9:
            return length
    raise CatalogueError(f"no standard {thread} socket screw is {minimum:g} mm long or longer "
                         f"(the longest is {lengths[-1]:g} mm)")


def nut(thread: str) -> dict:
    """ISO 4032 hexagon nut: ``{thread, m (height), s (across flats)}``, mm."""
    row = _by_thread("nuts", thread)
    return {"thread": thread, "m": float(row["m"]), "s": float(row["s"])}


def washer(thread: str) -> dict:
    """ISO 7089 plain washer: ``{thread, d1 (hole), d2 (outside), h (thickness)}``, mm."""
    row = _by_thread("washers", thread)
    return {"thread": thread, "d1": float(row["d1"]), "d2": float(row["d2"]),
            "h": float(row["h"])}


# ------------------------------------------------------------------ retaining rings
def shaft_ring(d: float) -> dict:
    """DIN 471 retaining ring for a shaft of diameter ``d`` (mm): ``{d1, s (thickness), d2
    (groove diameter), m (groove width), n (shaft beyond the groove), d4 (space the fitted
    ring needs), designation}``."""
    for row in _rows("retaining_rings"):
        if abs(float(row["d1"]) - float(d)) < 1e-9:
            ring = {name: float(value) for name, value in row.items()}
            ring["designation"] = f"DIN 471 {ring['d1']:g} x {ring['s']:g}"
            return ring
    sizes = ", ".join(row["d1"] for row in _rows("retaining_rings"))
    raise CatalogueError(f"no DIN 471 retaining ring in the table for a {float(d):g} mm shaft "
                         f"(it holds {sizes})")
