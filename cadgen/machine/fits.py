"""ISO fits and the clearances each manufacturing process is made with.

Two parts. First, a subset of ISO 286-1 (2010): the standard tolerance grades IT6 to
IT9 and the fundamental deviations of H, h, k, g and js for nominal sizes up to
120 mm, enough for bearing seats (H7), shafts (k6) and keyways (JS9):
:func:`deviation` gives a tolerance class's limit deviations. Second,
:class:`ProcessFits`: per manufacturing process (``printed``, ``machined``,
``laser``, ``edm``) the diametral allowances of bearing seats, gear bores, shaft
holes and keyways, the gear backlash, the bolt-hole series, and the materials of
the made parts. Machined features sit at the middle of their ISO tolerance zone
(what a shop aims for); printed ones get the offsets FDM needs to assemble.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from typing import NamedTuple

__all__ = ["FitError", "SIZE_STEPS", "tolerance_grade", "deviation", "mean_deviation",
           "Material", "ProcessFits", "process_fits", "design_fits", "GEAR_MATERIAL_DENSITY",
           "PART_KINDS"]


class FitError(ValueError):
    """A tolerance class or a nominal size outside the subset held here."""


#: Upper bounds of ISO 286-1's nominal size steps up to 120 mm ("over the previous, up to and
#: including this"), mm.
SIZE_STEPS = (3, 6, 10, 18, 30, 50, 80, 120)

#: Standard tolerance grades (ISO 286-1 table 1), micrometres, per size step above.
_IT = {
    6: (6, 8, 9, 11, 13, 16, 19, 22),
    7: (10, 12, 15, 18, 21, 25, 30, 35),
    8: (14, 18, 22, 27, 33, 39, 46, 54),
    9: (25, 30, 36, 43, 52, 62, 74, 87),
}

#: Fundamental deviation of g shafts, the upper deviation es (ISO 286-1 table 2), um.
_G_UPPER = (-2, -4, -5, -6, -7, -9, -10, -12)
#: Fundamental deviation of k shafts, the lower deviation ei for grades IT4 to IT7
#: (ISO 286-1 table 3; other grades and sizes up to 3 mm have ei = 0), um.
_K_LOWER = (0, 1, 1, 1, 2, 2, 2, 3)
#: ISO 286-2 fundamental deviation ei of "m" shafts (um), by the same size steps.
_M_LOWER = (2, 4, 6, 7, 8, 9, 11, 13)


def _step(nominal: float) -> int:
    nominal = float(nominal)
    if not 0.0 < nominal <= SIZE_STEPS[-1]:
        raise FitError(f"nominal size {nominal:g} mm is outside the ISO 286 subset held here "
                       f"(over 0 up to {SIZE_STEPS[-1]} mm)")
    return next(i for i, bound in enumerate(SIZE_STEPS) if nominal <= bound)


def tolerance_grade(grade: int, nominal: float) -> float:
    """The standard tolerance IT``grade`` at ``nominal`` (mm), in mm."""
    if grade not in _IT:
        raise FitError(f"IT{grade} is not held here (grades {sorted(_IT)})")
    return _IT[grade][_step(nominal)] / 1000.0


def deviation(designation: str, nominal: float) -> tuple:
    """``(lower, upper)`` limit deviations (mm) of a tolerance class at a nominal size.

    Parameters
    ----------
    designation : str
        Letter and grade: ``"H7"``, ``"k6"``, ``"g6"``, ``"js6"``, ``"JS9"``, ``"h9"``.
        Upper case is a hole, lower case a shaft.
    nominal : float
        Nominal size, mm (over 0 up to 120).

    Examples
    --------
    >>> deviation("H7", 35)
    (0.0, 0.025)
    >>> deviation("k6", 20)
    (0.002, 0.015)
    """
    match = re.fullmatch(r"(H|h|k|m|g|js|JS)(\d+)", designation.strip())
    if not match:
        raise FitError(f"tolerance class {designation!r} is not one of H, h, k, m, g, js, JS "
                       "with a grade (e.g. 'H7', 'k6')")
    letter, grade = match.group(1), int(match.group(2))
    step = _step(nominal)
    if grade not in _IT:
        raise FitError(f"IT{grade} is not held here (grades {sorted(_IT)})")
    it = _IT[grade][step]
    if letter in ("H", "h"):
        lower, upper = (0, it) if letter == "H" else (-it, 0)
    elif letter in ("js", "JS"):
        # symmetric zone; for js7 and coarser ISO 286-1 replaces an odd IT by the even value
        # below, so the limits stay whole micrometres
        half = (it - it % 2) / 2 if grade >= 7 else it / 2
        lower, upper = -half, half
    elif letter == "g":
        upper = _G_UPPER[step]
        lower = upper - it
    elif letter == "m":
        lower = _M_LOWER[step]
        upper = lower + it
    else:   # k
        lower = _K_LOWER[step] if 4 <= grade <= 7 else 0
        upper = lower + it
    return (lower / 1000.0 + 0.0, upper / 1000.0 + 0.0)


def mean_deviation(designation: str, nominal: float) -> float:
    """The middle of the tolerance zone (mm): where a shop aims a machined feature."""
    lower, upper = deviation(designation, nominal)
    return (lower + upper) / 2


# ------------------------------------------------------------------ processes
class Material(NamedTuple):
    """A made part's material: name, density (kg/m^3) and the process word for the bill."""

    name: str
    density: float
    process: str


#: The part kinds a material is given for.
PART_KINDS = ("gear", "cam", "planter", "housing", "shaft", "blade", "rocker", "needle", "lever",
              "link", "push-rod", "spacer")

# Densities: steel 7850 kg/m^3 (EN 10025 / EN 10083 data sheets), aluminium EN AW-6082 2700,
# PETG 1270 (filament makers' data sheets).
_STEEL_C45 = ("steel C45", 7850.0)
_STEEL_S235 = ("steel S235", 7850.0)
_STEEL_S355 = ("steel S355", 7850.0)
_ALUMINIUM = ("aluminium EN AW-6082", 2700.0)
_PETG = ("PETG", 1270.0)


def _materials(gear, cam, planter, housing, blade, rocker, needle) -> dict:
    # shafts are turned steel whatever the process: a printed shaft would not carry a key's torque;
    # the duckbill's push rod likewise (it slides in its guide and carries the long pin G)
    return {"gear": Material(*gear), "cam": Material(*cam), "planter": Material(*planter),
            "housing": Material(*housing), "shaft": Material(*_STEEL_C45, "turned"),
            "blade": Material(*blade), "rocker": Material(*rocker), "needle": Material(*needle),
            # the spacers too: turned from tube or bar in any process, they carry the stack's
            # axial load and keep their length
            "spacer": Material(*_STEEL_S235, "turned"),
            # the duckbill's lever and links are plates cut as the rocker is
            "lever": Material(*rocker), "link": Material(*rocker),
            "push-rod": Material(*_STEEL_C45, "turned")}


@dataclass(frozen=True)
class ProcessFits:
    """The allowances and materials of one manufacturing process (diametral, mm).

    ``seat_offset`` / ``hub_offset`` of None mean "machined to the middle of H7" at the
    size in question (:meth:`seat_allowance`, :meth:`hub_allowance`).
    """

    process: str
    seat_fit: str             # bearing seats in the housings
    shaft_fit: str            # journals under the bearings' inner rings (nominal size)
    seat_offset: float | None
    hub_offset: float | None
    running_clearance: float  # a shaft's hole where it leaves a housing, diametral
    key_slot_allowance: float  # keyway width over the key's width
    backlash: float           # circumferential, taken off each gear's teeth
    bolt_hole_series: str     # ISO 273
    bolt_hole_extra: float    # added to the ISO 273 hole (printed holes shrink)
    materials: dict = field(default_factory=dict)
    position_tolerance: float = 0.01   # a bore's or dowel hole's position (mm, radius): CNC

    def seat_allowance(self, outside: float) -> float:
        """Bearing seat bore minus the bearing's outside diameter ``outside`` (mm)."""
        if self.seat_offset is not None:
            return self.seat_offset
        return mean_deviation("H7", outside)

    def hub_allowance(self, d: float) -> float:
        """Gear bore minus the shaft's nominal diameter ``d`` (mm)."""
        if self.hub_offset is not None:
            return self.hub_offset
        return mean_deviation("H7", d)

    def material(self, kind: str) -> Material:
        """The material of a part kind (one of :data:`PART_KINDS`)."""
        if kind not in self.materials:
            raise FitError(f"part kind {kind!r} has no material (kinds: {', '.join(PART_KINDS)})")
        return self.materials[kind]

    def as_dict(self) -> dict:
        """JSON-ready: the allowances and each part kind's material."""
        return {"process": self.process, "seat_fit": self.seat_fit, "shaft_fit": self.shaft_fit,
                "seat_offset_mm": self.seat_offset, "hub_offset_mm": self.hub_offset,
                "running_clearance_mm": self.running_clearance,
                "key_slot_allowance_mm": self.key_slot_allowance, "backlash_mm": self.backlash,
                "bolt_hole_series": self.bolt_hole_series,
                "bolt_hole_extra_mm": self.bolt_hole_extra,
                "position_tolerance_mm": self.position_tolerance,
                "materials": {k: m._asdict() for k, m in self.materials.items()}}


_PROCESSES = {
    "printed": ProcessFits(
        process="printed",
        seat_fit="printed +0.10 mm",
        shaft_fit="k6",               # the shafts are turned steel in every process
        seat_offset=0.10,             # FDM holes print undersize; 0.1 mm lets a bearing press in
        hub_offset=0.20,              # a printed bore slides onto a steel shaft with 0.2 mm
        running_clearance=1.2,        # printed holes are rough and shrink: more than machined
        key_slot_allowance=0.20,      # printed slot walls bulge; the key must still go in
        backlash=0.20,                # FDM tooth flanks deviate by about a layer width's part
        bolt_hole_series="medium",
        bolt_hole_extra=0.2,          # printed holes come out about 0.2 mm small
        position_tolerance=0.1,       # an FDM printer places a hole to about 0.1 mm
        materials=_materials(gear=(*_PETG, "printed"), cam=(*_PETG, "printed"),
                             planter=(*_PETG, "printed"), housing=(*_PETG, "printed"),
                             blade=(*_PETG, "printed"), rocker=(*_PETG, "printed"),
                             needle=(*_PETG, "printed"))),
    "machined": ProcessFits(
        process="machined",
        seat_fit="H7",                # ISO 492 normal-class bearings in a stationary-load housing
        shaft_fit="k6",               # rotating inner-ring load, light to normal: transition fit
        seat_offset=None,             # the middle of H7 at the bearing's OD
        hub_offset=None,              # the middle of H7 at the shaft: a keyed hub slides on
        running_clearance=1.0,        # 0.5 mm a side: no rubbing when the shaft deflects
        key_slot_allowance=0.0,       # JS9 hub keyway: its mean is the key's width
        backlash=0.05,                # hobbed/shaped gears, quality 8-9 (DIN 3967 cd25-ish)
        bolt_hole_series="medium",
        bolt_hole_extra=0.0,          # drilled holes are true to size
        materials=_materials(gear=(*_STEEL_C45, "machined"), cam=(*_STEEL_C45, "machined"),
                             planter=(*_STEEL_S235, "machined"),
                             housing=(*_ALUMINIUM, "machined"),
                             blade=(*_STEEL_S235, "machined"),
                             rocker=(*_STEEL_S235, "machined"),
                             needle=(*_STEEL_S235, "machined"))),
    "laser": ProcessFits(
        process="laser",
        seat_fit="H7",                # the housings are machined whatever cuts the gears
        shaft_fit="k6",
        seat_offset=None,
        hub_offset=0.05,              # a laser-cut bore has a kerf taper of a few hundredths
        running_clearance=1.0,        # the housing's holes are machined
        key_slot_allowance=0.05,      # the kerf's taper: the key must pass the narrow side
        backlash=0.10,                # laser kerf and taper on the flanks
        bolt_hole_series="medium",
        bolt_hole_extra=0.0,
        materials=_materials(gear=(*_STEEL_S355, "laser-cut plate"),
                             cam=(*_STEEL_S355, "laser-cut plate"),
                             planter=(*_STEEL_S355, "laser-cut plate"),
                             housing=(*_ALUMINIUM, "machined"),
                             blade=(*_STEEL_S355, "laser-cut plate"),
                             rocker=(*_STEEL_S355, "laser-cut plate"),
                             needle=(*_STEEL_S235, "machined"))),
    "edm": ProcessFits(
        process="edm",
        seat_fit="H7",                # the housings are machined
        shaft_fit="k6",
        seat_offset=None,
        hub_offset=None,              # wire EDM holds H7 on a bore
        running_clearance=1.0,
        key_slot_allowance=0.0,       # wire EDM cuts the keyway to JS9 with the profile
        backlash=0.03,                # wire EDM holds the flanks to a few micrometres
        bolt_hole_series="medium",
        bolt_hole_extra=0.0,
        materials=_materials(gear=(*_STEEL_C45, "wire-EDM plate"),
                             cam=(*_STEEL_C45, "wire-EDM plate"),
                             planter=(*_STEEL_C45, "wire-EDM plate"),
                             housing=(*_ALUMINIUM, "machined"),
                             blade=(*_STEEL_C45, "wire-EDM plate"),
                             rocker=(*_STEEL_C45, "wire-EDM plate"),
                             needle=(*_STEEL_S235, "machined"))),
}


#: The gears' materials a design may name (``[machine] gear_material``) and their densities
#: (kg/m^3; steels 7850, EN AW-7075 2810 and EN AW-6082 2700 from their data sheets, PETG 1270,
#: sintered PA12 1010).
GEAR_MATERIAL_DENSITY = {"steel C45": 7850.0, "steel S355": 7850.0, "steel 42CrMo4+QT": 7850.0,
                         "aluminium EN AW-7075": 2810.0, "aluminium EN AW-6082": 2700.0,
                         "PETG": 1270.0, "PA12": 1010.0}


def process_fits(process: str, gear_material: str | None = None) -> ProcessFits:
    """The :class:`ProcessFits` of ``process`` (``printed``, ``machined``, ``laser`` or ``edm``),
    its gears of ``gear_material`` (one of :data:`GEAR_MATERIAL_DENSITY`) when named, made by
    the process's own word."""
    try:
        fits = _PROCESSES[process]
    except KeyError:
        raise FitError(f"manufacturing process {process!r} is not one of "
                       f"{', '.join(_PROCESSES)}") from None
    if gear_material is None or gear_material == fits.materials["gear"].name:
        return fits
    if gear_material not in GEAR_MATERIAL_DENSITY:
        raise FitError(f"gear material {gear_material!r} is not one of "
                       f"{', '.join(GEAR_MATERIAL_DENSITY)}")
    gear = Material(gear_material, GEAR_MATERIAL_DENSITY[gear_material],
                    fits.materials["gear"].process)
    return dataclasses.replace(fits, materials={**fits.materials, "gear": gear})


def design_fits(params) -> ProcessFits:
    """The fits and materials of a design: its process's, its gears of ``[machine]
    gear_material`` when it names one."""
    return process_fits(params.manufacturing.process,
                        getattr(getattr(params, "machine", None), "gear_material", None))
