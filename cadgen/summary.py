"""Plain-text summaries of a build's report (what the command line prints)."""

from __future__ import annotations

__all__ = ["summary_text", "format_metrics_table", "format_gear_table", "format_cam",
           "format_solids", "format_clearances", "format_stages"]


def summary_text(report: dict) -> str:
    """Everything a person reads after a build: metrics, gears, cam, solids, sweeps, stages."""
    sections = []
    if report["mechanism"] == "pricking" and "linkage" in report:
        from .pricking_report import pricking_summary

        sections.append(pricking_summary(report))
    elif "metrics" in report:
        sections.append(format_metrics_table(report))
    else:
        sections.append(f"design {report['design']} ({report['mechanism']} mechanism)")
    if "sweep" in report:
        sections.append(format_clearances(report["sweep"]))
    if "gear_train" in report:
        sections.append(format_gear_table(report["gear_train"]))
    if "cam" in report:
        sections.append(format_cam(report["cam"]))
    if "solids" in report:
        sections.append(format_solids(report["solids"]))
    sections.append(format_stages(report))
    return "\n\n".join(sections)


def format_stages(report: dict) -> str:
    """The stages that ran, their times and any failure; the verdict."""
    lines = []
    for record in report.get("stages", []):
        line = f"  {record['stage']:<18} {record['status']:<8} {record['seconds']:8.3f} s"
        if record["message"]:
            line += f"  {record['message']}"
        lines.append(line)
    for effect, reason in report.get("scene", {}).get("set_aside", {}).items():
        lines.append(f"  (effect {effect} not run: {reason})")
    verdict = "PASSED" if report.get("passed") else "NOT PASSED: " + "; ".join(
        report.get("failures", [])[:6])
    return "stages:\n" + "\n".join(lines) + f"\n{verdict}"


def format_clearances(sweep: dict) -> str:
    """The FCL clearances beside their kinematic estimates."""
    lines = []
    for key, row in sweep.items():
        ranges = row.get("interference_ranges_deg") or []
        lines.append(
            f"{row['label']}: {row['minimum_mm']:.3f} mm (certified >= "
            f"{row['certified_bound_mm']:.3f}) at carrier angle {row['carrier_angle_deg']:.2f} deg, "
            f"{row['nearest'][0]} / {row['nearest'][1]}; kinematic estimate "
            f"{row['kinematic_estimate_mm']:.3f} mm; target > {row['target_mm']:g} mm: "
            f"{'pass' if row['passed'] else 'FAIL'}"
            + (f"; IN INTERFERENCE over {', '.join(f'{a:.1f}..{b:.1f}' for a, b in ranges)} deg"
               if ranges else ""))
    return "\n".join(lines)


def format_metrics_table(report: dict) -> str:
    """Plain-text table of the metrics against their targets."""
    rows = [("metric", "spacing", "value", "target", "")]
    for m in report["metrics"]:
        spacing = f"{m['spacing_mm']:g} mm" if m["spacing_mm"] is not None else ""
        value = f"{m['value']:.3f} {m['unit']}".strip()
        rows.append((m["label"], spacing, value, f"{m['target']} {m['unit']}".strip(),
                     "pass" if m["passed"] else "FAIL"))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    lines = [f"design {report['design']} ({report['mechanism']} mechanism): "
             f"{'all targets met' if report['passed'] else 'TARGETS MISSED'}"]
    for k, row in enumerate(rows):
        lines.append("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        if k == 0:
            lines.append("  ".join("-" * w for w in widths))
    ev = report["events"]
    att = ev["attitude_deg"]
    lines.append("")
    lines.append("attitude Psi (deg): catching {catching:.3f}, entry {entry:.3f}, lowest {lowest:.3f}, "
                 "exit {exit:.3f}".format(**att))
    vl = ev["tip_velocity_relative_lowest_mm_s"]
    lines.append(f"tip velocity at the lowest point, relative: ({vl[0]:.2f}, {vl[1]:.2f}) mm/s "
                 f"at {ev['carrier_speed_rpm']:g} r/min")
    for row in report["per_spacing"]:
        v = row["tip_velocity_absolute_lowest_mm_s"]
        lines.append(f"  absolute at S = {row['spacing_mm']:g} mm: ({v[0]:.2f}, {v[1]:.2f}) mm/s")
    lines.append(f"catching-to-planting height: {ev['catch_to_plant_height_mm']:.3f} mm")
    d = report["derived"]
    lines.append(f"centre distance a = {d['centre_distance_a_mm']:.6f} mm, "
                 f"module {d['module_mm']:.4f} mm, ratio {d['ratio_min']:.4f}..{d['ratio_max']:.4f}")
    return "\n".join(lines)


def format_cam(cam: dict) -> str:
    """Plain-text summary of the duckbill cam and its checks."""
    events = cam["carrier_angle_deg"]
    lines = [f"cam: opening {cam['opening_angle_deg']:.2f} deg (mouth {cam['mouth_mm']:.1f} mm for "
             f"{cam['required_mouth_mm']:.1f} mm), push-rod stroke {cam['push_rod_stroke_mm']:.2f} "
             f"mm, roller lift {cam['roller_lift_mm']:.2f} mm",
             f"     opens {events['opening'][0]:.1f}..{events['opening'][1]:.1f} deg, closes "
             f"{events['closing'][0]:.1f}..{events['closing'][1]:.1f} deg (lowest point "
             f"{events['lowest']:.1f}, exit {events['exit']:.1f}, seedling cleared "
             f"{events['seedling_cleared']:.1f})",
             f"     pressure angle max {cam['pressure_angle_max_deg']:.2f} deg, smallest convex "
             f"pitch radius {cam['pitch_radius_convex_min_mm']:.2f} mm for a "
             f"{cam['roller_radius_mm']:g}-mm roller"]
    for problem in cam["problems"]:
        lines.append(f"     FAIL [{problem['code']}] {problem['message']}")
    return "\n".join(lines)


def format_solids(solids: dict) -> str:
    """Plain-text summary of the solids: parts, mass, enclosure."""
    parts = solids["parts"]
    instances = sum(p["instances"] for p in parts)
    lines = [f"solids: {len(parts)} parts ({instances} placed), total mass "
             f"{solids['total_mass_kg']:.2f} kg at {solids['density_kg_m3']:g} kg/m3, assembly at "
             f"carrier angle {solids['assembly']['carrier_angle_deg']:g} deg"]
    for row in solids["enclosure"]:
        margin = row["smallest_margin_mm"]
        if margin is None:
            lines.append(f"     {row['housing']}: no gears were cut, so its size is a coarse "
                         "estimate (each gear within the centre distance)")
            continue
        state = ("encloses its gears" if row["gears_enclosed"] else "DOES NOT enclose its gears")
        lines.append(f"     {row['housing']} {state} (smallest margin {margin:.2f} mm, "
                     f"{row['nearest_gear']})")
    return "\n".join(lines)


def format_gear_table(gear_train: dict) -> str:
    """Plain-text table of the generated gears and their meshes."""
    rows = [("gear", "teeth", "module", "cutter", "undercut teeth", "pointed", "problems")]
    for g in gear_train["gears"]:
        rows.append((g["gear"], str(g["teeth"]), f"{g['module_mm']:.4f}", g["cutter"] +
                     (f" (z={g['shaper_teeth']})" if g["shaper_teeth"] else ""),
                     str(len(g["undercut_teeth"])), str(len(g["pointed_teeth"])),
                     ", ".join(p["code"] for p in g["problems"]) or "-"))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    lines.append("")
    for m in gear_train["meshes"]:
        relief = m["tip_relief"]
        lines.append(
            f"mesh {m['stage']}: {m['interference_poses']} interfering poses of {m['poses']} "
            f"(largest overlap {m['overlap_area_max_mm2']:.1e} mm2), backlash "
            f"{m['backlash_deg'][0]:.1e}..{m['backlash_deg'][1]:.1e} deg, transmission error "
            f"{m['transmission_error_pp_deg']:.1e} deg p-p"
            + (f"; tip relief on the {relief['gear']} gear: {relief['removed_area_mm2']:.3f} mm2, "
               f"up to {relief['depth_mm']:.3f} mm deep" if relief else ""))
    for f in gear_train["failures"]:
        lines.append(f"NOT CUT [{f['code']}] {f['message']}")
    return "\n".join(lines)


