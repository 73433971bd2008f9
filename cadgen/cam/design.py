"""The planting mechanism's duckbill cam from its parameters: linkage, timing, contour, checks."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from kinematics.scalar import brentq

from kinematics.cam import CamCheck, CamProfile, CamTiming, cam_timing
from kinematics.duckbill import DuckbillLinkage
from kinematics.motion_laws import FollowerProgram

__all__ = ["CamDesign", "design_cam", "cam_report", "cam_section"]


@dataclass(frozen=True)
class CamDesign:
    linkage: DuckbillLinkage
    timing: CamTiming
    profile: CamProfile
    check: CamCheck
    cam_angle: object       # carrier angle -> cam angle (F)

    @property
    def cuttable(self) -> bool:
        """False when the roller would undercut the contour (no cam file is written then)."""
        return not any(p.code == "roller_undercut" for p in self.check.problems)


def linkage_of(params) -> DuckbillLinkage:
    cam, planter = params.cam, params.planter
    return DuckbillLinkage.design(
        L1=planter.L1, L2=planter.L2, pot_diameter=cam.pot_diameter,
        mouth_clearance=cam.mouth_clearance, blade_length=cam.duckbill.blade_length,
        closed_half_angle=cam.closed_half_angle_rad, blade_crank=cam.duckbill.blade_crank,
        blade_link=cam.duckbill.blade_link, base_radius=cam.base_radius,
        roller_arm=cam.lever.roller_arm, rod_arm=cam.lever.rod_arm,
        opening_angle=None if cam.opening_angle_deg is None else math.radians(cam.opening_angle_deg))


def timing_of(params, mechanism, events) -> CamTiming:
    timing = params.cam.timing
    return cam_timing(mechanism, events, seedling_height=params.cam.seedling_height,
                      opening_offset=math.radians(timing.opening_offset_deg),
                      opening_duration=math.radians(timing.opening_duration_deg),
                      closing_delay=math.radians(timing.closing_delay_deg),
                      closing_duration=math.radians(timing.closing_duration_deg),
                      closed_before_catch=math.radians(timing.closed_before_catch_deg))


def _carrier_of_cam(mechanism):
    """Inverse of the cam angle F over one revolution (F is monotone, F(2 pi) = 2 pi)."""
    F = mechanism.intermediate_rotation

    def carrier(theta):
        theta = float(np.mod(theta, 2 * np.pi))
        return brentq(lambda phi: float(F(phi)) - theta, 0.0, 2 * np.pi, xtol=1e-13)

    return carrier


def design_cam(params, mechanism, events) -> CamDesign:
    """Linkage, timing, contour and checks of the cam (raises DesignError for an impossible one)."""
    cam = params.cam
    linkage = linkage_of(params)
    timing = timing_of(params, mechanism, events)
    F = mechanism.intermediate_rotation
    program = FollowerProgram(
        linkage.lever_lift, rise=(float(F(timing.opening[0])), float(F(timing.opening[1]))),
        fall=(float(F(timing.closing[0])), float(F(timing.closing[1]))),
        rise_law=cam.rise_law, fall_law=cam.return_law)
    profile = CamProfile(linkage, program, cam.roller_radius, _carrier_of_cam(mechanism))
    check = profile.check(max_pressure_angle=math.radians(cam.max_pressure_angle_deg))
    return CamDesign(linkage, timing, profile, check, F)


def cam_report(design: CamDesign) -> dict:
    """The cam's section of report.json (angles in degrees, lengths in mm)."""
    linkage, timing, check, program = design.linkage, design.timing, design.check, design.profile.program
    deg = math.degrees
    return {
        "opening_angle_deg": deg(linkage.opening_angle),
        "mouth_mm": float(linkage.mouth_width(linkage.opening_angle)),
        "required_mouth_mm": linkage.required_mouth,
        "push_rod_stroke_mm": linkage.stroke,
        "lever_lift_deg": deg(linkage.lever_lift),
        "roller_lift_mm": float(np.linalg.norm(linkage.roller_centre(linkage.lever_lift)[0][0])
                                - linkage.base_radius),
        "rod_arm_mm": linkage.rod_arm,
        "carrier_angle_deg": {
            "opening": [deg(x) for x in timing.opening], "closing": [deg(x) for x in timing.closing],
            **{name: deg(value) for name, value in timing.events.items()}},
        "cam_angle_deg": {"opening": [deg(x) for x in program.rise],
                          "closing": [deg(x) for x in program.fall]},
        "laws": {"opening": program.rise_law, "closing": program.fall_law},
        "pressure_angle_max_deg": deg(check.pressure_angle_max),
        "pressure_angle_max_at_cam_deg": deg(check.pressure_angle_at),
        "pitch_radius_convex_min_mm": check.pitch_radius_convex_min,
        "pitch_radius_convex_min_at_cam_deg": deg(check.pitch_radius_at),
        "profile_radius_min_mm": check.profile_radius_min,
        "roller_radius_mm": design.profile.roller_radius,
        "cuttable": design.cuttable,
        "problems": [{"path": p.path, "code": p.code, "message": p.message}
                     for p in check.problems],
    }


def cam_section(design: CamDesign) -> dict:
    """The report's cam section, saying when no cam.dxf is written."""
    section = cam_report(design)
    if not design.cuttable:
        section["not_written"] = "cam.dxf is not written: the roller cannot follow this contour"
    return section
