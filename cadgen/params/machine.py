"""Machine design and manufacturing settings shared by every mechanism kind.

``[machine]`` gives the design load and the strength and life rules the shafts,
keys and bearings are sized by (:mod:`cadgen.machine`). The load is a force at
the tool's tip (the duckbill's or the needle's), the soil's resistance when the
tool enters it: through the gears it sets every shaft's torque and every
bearing's load. ``[manufacturing]`` names the process the made parts are made by,
which sets the clearances of holes, seats and bores, the gear backlash allowance
and the materials, and the printer's build volume the printed parts are checked
against.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BeforeValidator, Field

from cadgen.params._tables import _list_to_tuple, _Table

__all__ = ["DEFAULT_BUILD_VOLUME", "PROCESSES", "MachineParameters", "ManufacturingParameters",
           "ShaftDiameters", "PrickingMachineParameters", "PrickingShaftDiameters"]

#: A common printer bed (x, y, z in mm): 256 mm cube printers are widespread.
DEFAULT_BUILD_VOLUME = (256.0, 256.0, 256.0)

#: The manufacturing processes of the made parts (see :mod:`cadgen.machine.fits`).
PROCESSES = ("printed", "machined", "laser", "edm")


class _ShaftDiameters(_Table):
    """Shaft diameters given in the file (mm), by axis; an axis left out is sized from its torque."""

    def given(self) -> dict:
        """``{axis: diameter}`` of the diameters the file gives."""
        return {k: v for k, v in self.model_dump().items() if v is not None}


class ShaftDiameters(_ShaftDiameters):
    """Planting: ``O``, ``A``, ``B``, ``C`` (gearbox 1), ``C2`` (the central gear's shaft in
    gearbox 2), ``D``, ``E``."""

    O: float | None = Field(None, gt=0)
    A: float | None = Field(None, gt=0)
    B: float | None = Field(None, gt=0)
    C: float | None = Field(None, gt=0)
    C2: float | None = Field(None, gt=0)
    D: float | None = Field(None, gt=0)
    E: float | None = Field(None, gt=0)


class PrickingShaftDiameters(_ShaftDiameters):
    """Pricking: ``sun``, ``intermediate``, ``planet``."""

    sun: float | None = Field(None, gt=0)
    intermediate: float | None = Field(None, gt=0)
    planet: float | None = Field(None, gt=0)


class MachineParameters(_Table):
    """The design load and the rules the shafts, keys and bearings are sized by."""

    tip_load_n: float = Field(
        50.0, gt=0, le=1e5,
        description="design force at the tool tip (soil resistance on the duckbill or the "
                    "needle), N")
    service_factor: float = Field(
        1.5, ge=1, le=5, description="multiplies the design load for shocks (stones, clods), "
                                     "dimensionless")
    shaft_safety_factor: float = Field(
        2.0, ge=1, le=10, description="on the shaft material's shear yield, dimensionless")
    shaft_yield_mpa: float = Field(
        355.0, gt=0, le=3000, description="yield strength of the shaft steel, MPa "
                                          "(355: C45 / S355)")
    key_pressure_mpa: float = Field(
        150.0, gt=0, le=1000, description="allowed bearing pressure on a key's flank, MPa")
    bearing_life_min_h: float = Field(
        5000.0, gt=0, le=1e7, description="basic rating life L10 every bearing must reach, h")
    gear_material: Literal["steel C45", "steel S355", "steel 42CrMo4+QT", "aluminium EN AW-7075",
                           "aluminium EN AW-6082", "PETG", "PA12"] | None = Field(
        None, description="the gears' material, when not the process's (machined and edm: "
                          "steel C45, normalised; laser: S355 plate; printed: PETG): "
                          "its allowables set the teeth's bending and contact strength, its "
                          "density the masses, and the bill names it")
    bending_safety_min: float = Field(
        1.4, ge=1, le=10,
        description="least tooth-root bending safety S_F every gear must keep over the cycle "
                    "(ISO 6336-3; 1.4 is the usual minimum for industrial gears, as in ISO/TR "
                    "6336-30's examples), dimensionless")
    contact_safety_min: float = Field(
        1.0, ge=0.5, le=10,
        description="least flank contact (pitting) safety S_H every gear must keep over the "
                    "cycle (ISO 6336-2; 1.0: some pitting tolerated, the usual minimum for "
                    "slow, non-critical drives), dimensionless")
    shafts: ShaftDiameters = ShaftDiameters()


class PrickingMachineParameters(MachineParameters):
    """``[machine]`` of the pricking mechanism: its shafts are the sun's, the intermediate
    gears' and the planet's."""

    shafts: PrickingShaftDiameters = PrickingShaftDiameters()


class ManufacturingParameters(_Table):
    """How the made parts are made: the process, its fits and the printer's build volume."""

    process: Literal["printed", "machined", "laser", "edm"] = Field(
        "machined",
        description='"printed" (FDM: every made part printed), "machined" (turned and milled; '
                    'ISO fits H7/k6), "laser" or "edm" (gears, cam and arm plate cut from plate, '
                    'housings machined)')
    build_volume: Annotated[
        tuple[Annotated[float, Field(gt=0)], Annotated[float, Field(gt=0)],
              Annotated[float, Field(gt=0)]],
        BeforeValidator(_list_to_tuple)] = Field(
        DEFAULT_BUILD_VOLUME,
        description="printer build volume [x, y, z], mm: every printed part's printing pose "
                    "(the resting face that leaves the least overhang among those that fit, "
                    "turned 90 deg about z if that fits) is checked against it")
