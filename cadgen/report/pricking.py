"""Report of a pricking-mechanism design: the JSON dictionary and the terminal summary."""

from __future__ import annotations

from kinematics.pricking import FORWARD_TOLERANCE

__all__ = ["pricking_report", "pricking_summary"]


def _gear(gear) -> dict:
    return {
        "name": gear.name, "stage": gear.stage, "role": gear.role,
        "perimeter_mm": gear.perimeter, "radius_min_mm": gear.radius_min,
        "radius_max_mm": gear.radius_max, "curvature_min_per_mm": gear.curvature_min,
        "convex": gear.convex, "concave_stretches": gear.concave_stretches,
        "pressure_angle_deviation_max_deg": gear.pressure_angle_deviation_max_deg,
        "convex_radius_of_curvature_min_mm": gear.convex_radius_of_curvature_min,
        "undercut_limit_mm": gear.undercut_limit, "undercut": gear.undercut,
    }


def pricking_report(params, design, field) -> dict:
    """The pricking design's sections of the report (lengths mm, angles deg)."""
    linkage = design.linkage
    curve = design.curve
    findings = [{"path": f.path, "code": f.code, "message": f.message} for f in design.findings]
    return {
        "verified": bool(design.forward_deviation <= FORWARD_TOLERANCE),
        "findings": findings,
        "linkage": {
            "centre_distance_a_mm": linkage.a, "tip_reach_l_mm": linkage.l,
            "rocker_l1_mm": linkage.rocker, "needle_l2_mm": linkage.needle,
            "radius_max_mm": linkage.radius_max, "radius_min_mm": linkage.radius_min,
            "dead_centre_outer_near": curve.describe(linkage.u_max),
            "dead_centre_inner_near": curve.describe(linkage.u_min),
            "derived_from_curve": linkage.derived,
            "carrier_sense": design.carrier_sense,
            "assembly_modes": {("counter-clockwise" if k > 0 else "clockwise"): v
                               for k, v in design.modes.items()},
        },
        "gears": {
            "split_exponent_w": design.exponent,
            "scale": design.scale,
            "teeth": list(design.teeth),
            "modules_mm": list(design.modules),
            "total_ratio_min": design.ratio_min, "total_ratio_max": design.ratio_max,
            "stages": [{"index": s.index, "exponent": s.exponent, "constant_K": s.constant,
                        "ratio_min": s.ratio_min, "ratio_max": s.ratio_max,
                        "closure_error_rad": s.closure_error,
                        "pitch_perimeter_mm": s.perimeter} for s in design.stages],
            "pitch_curves": [_gear(g) for g in design.gears],
        },
        "verification": {
            "forward_deviation_mm": design.forward_deviation,
            "grid_closure_error_rad": design.grid_closure_error,
            "inverse_grid": params.resolution.inverse_grid,
        },
        "field": {
            "carrier_speed_rpm": params.field.carrier_speed_rpm,
            "forward_speed_mm_s": params.field.forward_speed,
            "depth_mm": params.field.depth,
            "angles": "carrier progress in deg from the outer dead centre",
            "per_inclination": [{
                "inclination_deg": r.inclination_deg,
                "needle_entry_angle_deg": r.entry_angle_deg,
                "needle_exit_angle_deg": r.exit_angle_deg,
                "hole_mouth_mm": r.hole_mouth, "mouth_x_range_mm": list(r.mouth_range),
                "time_in_soil_deg": r.time_in_soil_deg,
                "entry_progress_deg": r.entry_progress_deg,
                "exit_progress_deg": r.exit_progress_deg,
                "slow_windows_deg": r.slow_windows_deg,
                "slow_window_total_deg": r.slow_window_total_deg,
                "projected_height_mm": r.projected_height, "width_mm": r.width,
                "surface_level_in_mechanism_plane_mm": r.surface_level,
                "needle_root_in_soil": r.needle_root_in_soil,
            } for r in field],
        },
    }


def pricking_summary(report: dict) -> str:
    """Plain-text summary: linkage, gears, field table, findings (a missing number reads n/a)."""
    from cadgen.report.summary import _number as n

    link, gears, check = report["linkage"], report["gears"], report["verification"]
    teeth, modules = gears["teeth"], gears["modules_mm"]
    from cadgen.report.content import verdict_text

    lines = [f"design {report['design']} (pricking mechanism): {verdict_text(report)}; "
             f"{'verified' if report['verified'] else 'NOT VERIFIED'}, "
             f"{len(report['findings'])} finding{'s' if len(report['findings']) != 1 else ''}",
             f"linkage: a = {n(link['centre_distance_a_mm'], '.3f')} mm, l = "
             f"{n(link['tip_reach_l_mm'], '.3f')} mm, l1 = {n(link['rocker_l1_mm'], '.3f')} mm, "
             f"l2 = {n(link['needle_l2_mm'], '.3f')} mm; carrier turns {link['carrier_sense']}",
             f"gears: w = {n(gears['split_exponent_w'], '.4f')}, scale {n(gears['scale'], '.5f')}, "
             f"teeth {' / '.join(str(t) for t in teeth)}, modules "
             f"{' / '.join(n(m, '.4f') for m in modules)} mm, ratio i "
             f"{n(gears['total_ratio_min'], '.3f')}..{n(gears['total_ratio_max'], '.3f')}",
             f"forward check: tip loop reproduced to {n(check['forward_deviation_mm'], '.2e')} mm, "
             f"closure {n(check['grid_closure_error_rad'], '.1e')} rad ({check['inverse_grid']} "
             "steps)",
             ""]
    rows = [("gear", "perimeter", "radius", "min curvature", "convex", "pressure dev.",
             "min convex rho", "undercut")]
    for g in gears["pitch_curves"]:
        rows.append((g["name"], n(g["perimeter_mm"], ".3f"),
                     f"{n(g['radius_min_mm'], '.2f')}..{n(g['radius_max_mm'], '.2f')}",
                     n(g["curvature_min_per_mm"], ".4f"), "yes" if g["convex"] else "NO",
                     f"{n(g['pressure_angle_deviation_max_deg'], '.1f')} deg",
                     n(g["convex_radius_of_curvature_min_mm"], ".2f", "none convex"),
                     "YES" if g["undercut"] else "no"))
    lines += _table(rows) + [""]
    rows = [("theta", "entry", "exit", "mouth", "in soil", "slow window", "height", "width")]
    for r in report["field"]["per_inclination"]:
        rows.append((f"{n(r['inclination_deg'], 'g')} deg",
                     f"{n(r['needle_entry_angle_deg'], '.2f')} deg",
                     f"{n(r['needle_exit_angle_deg'], '.2f')} deg",
                     f"{n(r['hole_mouth_mm'], '.2f')} mm", f"{n(r['time_in_soil_deg'], '.1f')} deg",
                     f"{n(r['slow_window_total_deg'], '.1f')} deg",
                     f"{n(r['projected_height_mm'], '.1f')} mm", f"{n(r['width_mm'], '.1f')} mm"))
    lines += _table(rows)
    for f in report["findings"]:
        lines.append(f"finding [{f['code']}] {f['path']}: {f['message']}")
    return "\n".join(lines)


def _table(rows):
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    out = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    out.insert(1, "  ".join("-" * w for w in widths))
    return out
