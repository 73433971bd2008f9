"""The duckbill and its cam (the planting mechanism's optional ``[cam]`` table).

The paper's linkage lengths are not published; the defaults are a consistent set
for the paper's planter (L1 = 130 mm, L2 = 190 mm) and a 30-mm pot. See
:mod:`kinematics.duckbill` for the geometry each length sets and
:mod:`kinematics.cam` for the timing and the checks.
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field

from cadgen.params._tables import _Table

__all__ = ["CamParameters", "DuckbillParameters", "LeverParameters", "CamTimingParameters"]

MotionLaw = Literal["cycloidal", "polynomial-345"]


class DuckbillParameters(_Table):
    """The blades and their drive (vector loop O1-J-P2)."""

    blade_length: float = Field(85.0, ge=1.0, description="blade hinge O1 to its tip, mm")
    closed_half_angle_deg: float = Field(18.0, gt=0, lt=60,
                                         description="half-angle of the closed duckbill, deg")
    blade_crank: float = Field(20.0, gt=0, description="blade crank O1-J, mm")
    blade_link: float = Field(35.0, gt=0, description="link J-P2 to the push rod, mm")


class LeverParameters(_Table):
    """The cam lever (bell crank H-I-G) and its roller."""

    roller_arm: float = Field(45.0, gt=0, description="lever pivot H to the roller centre I, mm")
    rod_arm: float | None = Field(None, gt=0, description="lever pivot H to the push-rod pin G, mm "
                                                          "(default: to the duckbill axis, L1 - base radius)")
    thickness: float = Field(5.0, gt=0, le=50, description="lever plate thickness, mm (the lever "
                                                          "turns in a layer of its own between the "
                                                          "cam and the planter's plate)")


class CamTimingParameters(_Table):
    """Where the cam's phases sit (carrier angles, deg)."""

    opening_offset_deg: float = Field(-5.0, ge=-90, le=90,
                                      description="start of opening after the lowest point, deg")
    opening_duration_deg: float = Field(30.0, gt=0, le=180, description="opening phase, deg")
    closing_delay_deg: float = Field(0.0, ge=0, le=180,
                                     description="wait after the tip has cleared the seedling, deg")
    closing_duration_deg: float = Field(40.0, gt=0, le=180, description="closing phase, deg")
    closed_before_catch_deg: float = Field(20.0, ge=0, le=180,
                                           description="closed at least this long before catching, deg")


class CamParameters(_Table):
    """The duckbill, its pot and the cam that opens it."""

    pot_diameter: float = Field(30.0, gt=0, description="pot (plug) diameter the mouth must clear, mm")
    mouth_clearance: float = Field(5.0, ge=0, description="mouth wider than the pot by this each side, mm")
    seedling_height: float = Field(100.0, ge=0,
                                   description="tip height above the soil before closing, mm")
    opening_angle_deg: float | None = Field(
        None, gt=0, lt=90, description="blade opening, deg (default: the smallest that clears the pot)")
    base_radius: float = Field(40.0, gt=0, description="roller centre's distance from E at rest, mm")
    roller_radius: float = Field(6.0, gt=0, description="roller radius, mm")
    rise_law: MotionLaw = Field("cycloidal", description='opening law: "cycloidal" or "polynomial-345"')
    return_law: MotionLaw = Field("cycloidal", description='closing law: "cycloidal" or "polynomial-345"')
    max_pressure_angle_deg: float = Field(30.0, gt=0, lt=90, description="pressure angle limit, deg")
    thickness: float = Field(8.0, gt=0, description="cam plate thickness, mm")
    bore_diameter: float | None = Field(
        None, gt=0, description="cam bore round the E shaft, mm (default: the E shaft's "
                                "diameter plus the process's running clearance; the cam is "
                                "fixed to gearbox 2 and the shaft turns inside it)")
    profile_points: int = Field(3600, ge=360, le=1_000_000,
                                description="cam-angle samples of the contour before DXF thinning")
    duckbill: DuckbillParameters = DuckbillParameters()
    lever: LeverParameters = LeverParameters()
    timing: CamTimingParameters = CamTimingParameters()

    @property
    def closed_half_angle_rad(self) -> float:
        return math.radians(self.duckbill.closed_half_angle_deg)

    def lever_layer(self, gap: float) -> float:
        """How much higher the planter's plate stands for the lever (mm): the lever turns
        ``gap`` above the cam, and the plate ``gap`` above the lever."""
        return self.lever.thickness + gap
