"""Solids settings shared by every mechanism kind: housings, ground, mesh resolution, assembly.

``[housing]`` sets the gearbox shells (clearance round the gears, wall, axial gap);
each may be left out and is then derived from the module of the gears the housing
encloses. ``[ground]`` is the soil surface as a mesh (flat or a ridge). ``[solids]``
holds the mesh resolution, the density for the mass properties and the pose of
the assembly file, and the printer's build volume the printed parts are checked against.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BeforeValidator, Field, field_validator
from pydantic_core import PydanticCustomError

from cadgen.params._tables import _list_to_tuple, _Table

__all__ = ["MIN_WALL", "DEFAULT_BUILD_VOLUME", "ShellParameters", "GroundParameters",
           "SolidsParameters"]

#: A common printer bed (x, y, z in mm): 256 mm cube printers are widespread.
DEFAULT_BUILD_VOLUME = (256.0, 256.0, 256.0)

#: The thinnest housing wall accepted (mm): thinner cast or welded walls do not hold a bearing.
MIN_WALL = 2.0


class ShellParameters(_Table):
    """A gearbox housing: a closed shell round the hull of its gears' envelopes."""

    clearance: float | None = Field(
        None, ge=0, description="gear tips to the housing inside, mm (default: 0.75 module, "
                                "at least 2 mm)")
    wall: float | None = Field(
        None, description=f"housing wall thickness, mm (default: 1.5 module, at least 3 mm; "
                          f"at least {MIN_WALL:g} mm)")
    axial_gap: float = Field(2.0, ge=0, description="between gear layers and the housing's inner "
                                                    "faces, mm")

    @field_validator("wall")
    @classmethod
    def _thick_enough(cls, wall: float | None) -> float | None:
        if wall is not None and wall < MIN_WALL:
            raise PydanticCustomError(
                "wall_too_thin",
                "wall = {wall} mm is thinner than allowed: a housing wall must be at least "
                "{minimum} mm", {"wall": wall, "minimum": MIN_WALL})
        return wall

    def clearance_for(self, module: float) -> float:
        """The clearance given, or the default for gears of ``module`` (mm)."""
        return self.clearance if self.clearance is not None else max(2.0, 0.75 * module)

    def wall_for(self, module: float) -> float:
        """The wall given, or the default for gears of ``module`` (mm)."""
        return self.wall if self.wall is not None else max(3.0, 1.5 * module)


class GroundParameters(_Table):
    """The soil surface as a mesh: flat, or a ridge (bed) between two furrows, across the travel."""

    profile: Literal["flat", "ridge"] = Field("flat", description='"flat" or "ridge"')
    ridge_top_width: float = Field(300.0, gt=0, description="width of the ridge top, mm")
    ridge_height: float = Field(150.0, gt=0, description="ridge top above the furrow bottom, mm")
    ridge_side_slope_deg: float = Field(60.0, gt=0, le=90,
                                        description="ridge side against the horizontal, deg")
    furrow_width: float = Field(200.0, gt=0, description="width of each furrow bottom, mm")
    thickness: float = Field(100.0, gt=0, description="soil slab below the lowest surface, mm")
    margin: float = Field(200.0, ge=0, description="ground beyond the mechanism's reach, mm")


class SolidsParameters(_Table):
    """Mesh resolution, material and assembly pose of the solids."""

    segments_per_circle: int = Field(96, ge=8, le=4096,
                                     description="facets of a full circle (bores, shells, tubes)")
    density_kg_m3: float = Field(7850.0, gt=0, description="density for the mass properties, kg/m^3")
    assembly_carrier_angle_deg: float = Field(0.0, description="carrier angle of the assembly file, "
                                                               "deg (0 = catching)")
    assembly_format: Literal["glb", "3mf"] = Field("glb", description='"glb" or "3mf"')
    build_volume: Annotated[
        tuple[Annotated[float, Field(gt=0)], Annotated[float, Field(gt=0)],
              Annotated[float, Field(gt=0)]],
        BeforeValidator(_list_to_tuple)] = Field(
        DEFAULT_BUILD_VOLUME,
        description="printer build volume [x, y, z], mm: every part's printing pose (largest "
                    "flat face down, turned 90 deg about z if that fits) is checked against it")

    @property
    def assembly_carrier_angle_rad(self) -> float:
        return math.radians(self.assembly_carrier_angle_deg)
