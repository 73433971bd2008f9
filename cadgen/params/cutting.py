"""Gear cutting settings shared by every mechanism kind (the ``[gears]`` table)."""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field

from cadgen.params._tables import _Table

__all__ = ["CuttingParameters"]


class CuttingParameters(_Table):
    """How the gears' teeth are cut, checked and drawn (standard defaults)."""

    cutter: Literal["auto", "shaper"] = Field(
        "auto", description='"auto": rack on convex stretches, pinion cutter on concave ones; '
                            '"shaper": a pinion cutter everywhere')
    pressure_angle_deg: float = Field(20.0, ge=5, lt=45, description="pressure angle, deg")
    addendum: float = Field(1.0, ge=0.1, le=2,
                            description="addendum coefficient ha*, dimensionless")
    dedendum: float = Field(1.25, gt=0, le=2.5, description="dedendum coefficient hf*, dimensionless")
    tip_radius: float = Field(0.38, ge=0, le=0.6,
                              description="cutter tip radius (root fillet), coefficient of the module")
    backlash: float | None = Field(
        None, ge=0, le=2, description="circumferential backlash taken off each gear's teeth, mm "
                                      "(default: the [manufacturing] process's allowance)")
    flank_points: int = Field(96, ge=8, le=4000, description="points per generated flank")
    chord_tolerance: float = Field(0.005, gt=0, le=1,
                                   description="largest deviation of the DXF polyline from the profile, mm")
    bore_diameter: float = Field(0.0, ge=0, description="shaft bore of every gear, mm (0: none)")
    meshing_poses: int | None = Field(
        None, ge=16, le=20000,
        description="poses of the meshing check over one cycle (default 8 per tooth, at least 96)")
    circular_module: float | None = Field(
        None, gt=0, description="module of the trains' circular gears, mm (default: the largest "
                                "0.05-mm step that gives every one a whole tooth count)")

    face_width: float | None = Field(
        None, gt=0, description="face width of every gear, mm (default: 6 modules of each gear, "
                                "to 0.5 mm)")

    def face_width_for(self, module: float) -> float:
        """The face width given, or 6 modules rounded to 0.5 mm (mm)."""
        return self.face_width if self.face_width is not None else max(0.5, round(12.0 * module) / 2)

    @property
    def pressure_angle_rad(self) -> float:
        return math.radians(self.pressure_angle_deg)
