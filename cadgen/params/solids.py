"""Solids settings shared by every mechanism kind: housings, ground, mesh resolution, assembly.

``[housing]`` sets the gearbox shells (clearance round the gears, wall, axial gap);
each may be left out and is then derived from the module of the gears the housing
encloses. ``[ground]`` is the soil surface as a mesh (flat or a ridge). ``[solids]``
holds the mesh resolution, the density for the mass properties and the pose of
the assembly file (the printer's build volume is ``[manufacturing]``'s).
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field, field_validator
from pydantic_core import PydanticCustomError

from cadgen.params._tables import _Table

__all__ = ["MIN_WALL", "ShellParameters", "GroundParameters", "SolidsParameters"]

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
    bolt_size: Literal["M3", "M4", "M5", "M6", "M8", "M10"] | None = Field(
        None, description="ISO metric bolts joining each housing's base and cover (default: from "
                          "the wall: M3 below 4 mm, M4 below 6 mm, M5 below 8 mm, else M6)")

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

    # at most 1024: the FCL sweeps grow faster than the facets (the paper design's
    # full build, one process: 96 facets 7.5 s, 384 15 s, 768 22 s, 1536 67 s: nine times
    # the usual; benchmarks/knob_costs.py), and 1024 facets keep a 300 mm circle within 0.0015 mm
    segments_per_circle: int = Field(96, ge=8, le=1024,
                                     description="facets of a full circle (bores, shells, tubes)")
    density_kg_m3: float | None = Field(
        None, gt=0, description="density of every made part for the mass properties, kg/m^3 "
                                "(default: each part's material, from [manufacturing] process)")
    assembly_carrier_angle_deg: float = Field(0.0, description="carrier angle of the assembly file, "
                                                               "deg (0 = catching)")
    assembly_format: Literal["glb", "3mf"] = Field("glb", description='"glb" or "3mf"')

    @property
    def assembly_carrier_angle_rad(self) -> float:
        return math.radians(self.assembly_carrier_angle_deg)
