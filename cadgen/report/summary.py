"""Plain-text summaries of a build's report (what the command line prints).

A report holds only the sections of the stages that ran, and some of its values
may be None (the pricking mechanism has no kinematic clearance estimate, a
non-finite number is written as null in report.json): every formatter here takes
a section as it may come, from a live build or re-read from report.json, and says
what is missing instead of failing.
"""

from __future__ import annotations

import math

__all__ = ["summary_text", "format_metrics_table", "format_gear_table", "format_cam", "format_dynamics",
           "format_duckbill",
           "format_solids", "format_machine", "format_clearances", "format_stages", "format_verdict"]

#: Printed for a number the report does not have.
MISSING = "n/a"


def _number(value, spec: str, missing: str = MISSING) -> str:
    """``value`` formatted with ``spec``, or ``missing`` when it is None or not a finite number
    (infinities print as they are: a bound that does not exist is still a value)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return missing
    return format(value, spec)


def summary_text(report: dict) -> str:
    """Everything a person reads after a build: metrics, gears, cam, solids, sweeps, stages."""
    sections = []
    if report["mechanism"] == "pricking" and "linkage" in report:
        from cadgen.report.pricking import pricking_summary

        sections.append(pricking_summary(report))
    elif "metrics" in report:
        sections.append(format_metrics_table(report))
    else:
        sections.append(f"design {report['design']} ({report['mechanism']} mechanism)")
    if "sweep" in report:
        sections.append(format_clearances(report["sweep"]))
    if "gear_train" in report:
        sections.append(format_gear_table(report["gear_train"], report))
    if "cam" in report:
        sections.append(format_cam(report["cam"]) + (
            "\n" + format_duckbill(report["duckbill"]) if "duckbill" in report else ""))
    if "solids" in report:
        sections.append(format_solids(report["solids"]))
    if "machine" in report:
        sections.append(format_machine(report["machine"], report.get("bom"),
                                       (report.get("assembly") or {}).get("axial")))
    if "dynamics" in report:
        sections.append(format_dynamics(report["dynamics"]))
    sections.append(format_stages(report))
    return "\n\n".join(sections)


def format_dynamics(dynamics: dict) -> str:
    """One line: the input torque over a carrier turn, or why there is none."""
    if not dynamics.get("modelled"):
        return f"dynamics: not modelled ({dynamics['reason']})"
    torque = dynamics["summary"]["input_torque_nm"]
    motor = dynamics["motor"]
    return (f"dynamics ({dynamics['mass_properties_source']} masses, load case "
            f"{dynamics['load_case']}, {dynamics['carrier_speed_rpm']:g} r/min): input torque "
            f"peak {torque['peak']:.3g} N m, RMS {torque['rms']:.3g}, mean {torque['mean']:.3g} "
            f"at {dynamics['input_speed_rpm']:g} r/min; motor {motor['rated_torque_nm']:.3g} N m "
            f"{motor['rated_power_w']:.3g} W; energy balance "
            f"{dynamics['energy_balance_max_rel']:.1e}")


def format_stages(report: dict) -> str:
    """The stages that ran, their times and any failure; the verdict."""
    lines = []
    for record in report.get("stages", []):
        seconds = _number(record["seconds"], "8.3f")
        line = f"  {record['stage']:<18} {record['status']:<8} {seconds:>8} s"
        if record["message"]:
            line += f"  {record['message']}"
        lines.append(line)
    for effect, reason in report.get("scene", {}).get("set_aside", {}).items():
        lines.append(f"  (effect {effect} not run: {reason})")
    return "stages:\n" + "\n".join(lines) + "\n" + format_verdict(report)


#: Failure reasons printed under NOT PASSED; the rest are counted and left to the report.
FAILURES_SHOWN = 5


def format_verdict(report: dict, shown: int = FAILURES_SHOWN) -> str:
    """``PASSED``, or ``NOT PASSED:`` and one indented line per reason, the first ``shown``
    of them, then ``and N more (see report.html)`` (report.json when no page was written)."""
    if report.get("passed"):
        return "PASSED"
    failures = [" ".join(str(f).split()) for f in report.get("failures", [])]
    lines = ["NOT PASSED:" if failures else "NOT PASSED"]
    lines += [f"  - {reason}" for reason in failures[:shown]]
    rest = len(failures) - shown
    if rest > 0:
        files = report.get("files") or ()
        where = ("report.html" if "report.html" in files
                 else "report.json" if "report.json" in files else "the report")
        lines.append(f"  and {rest} more (see {where})")
    return "\n".join(lines)


def format_clearances(sweep: dict) -> str:
    """The FCL clearances beside their kinematic estimates (when the mechanism has one)."""
    lines = []
    for key, row in sweep.items():
        ranges = row.get("interference_ranges_deg") or []
        bound = _number(row.get("certified_bound_mm"), ".3f")
        bound = (f"certified >= {bound}" if row.get("certified", True)
                 else f"NOT certified, bound {bound}")
        nearest = row.get("nearest") or ()
        where = (f" at carrier angle {_number(row.get('carrier_angle_deg'), '.2f')} deg"
                 + (f", {nearest[0]} / {nearest[1]}" if len(nearest) == 2 else ""))
        estimate = row.get("kinematic_estimate_mm")
        estimate = ("no kinematic estimate for this mechanism" if estimate is None
                    else f"kinematic estimate {_number(estimate, '.3f')} mm")
        lines.append(
            f"{row.get('label', key)}: {_number(row.get('minimum_mm'), '.3f')} mm ({bound})"
            f"{where}; {estimate}; target > {_number(row.get('target_mm'), 'g')} mm: "
            f"{'pass' if row.get('passed') else 'FAIL'}"
            + (f"; IN INTERFERENCE over {', '.join(f'{a:.1f}..{b:.1f}' for a, b in ranges)} deg"
               if ranges else ""))
    return "\n".join(lines)


def format_metrics_table(report: dict) -> str:
    """Plain-text table of the metrics against their targets."""
    rows = [("metric", "spacing", "value", "target", "")]
    for m in report["metrics"]:
        spacing = f"{_number(m['spacing_mm'], 'g')} mm" if m.get("spacing_mm") is not None else ""
        value = f"{_number(m.get('value'), '.3f')} {m['unit']}".strip()
        target = f"{m['target']} {m['unit']}".strip() if m.get("target") is not None else ""
        status = ("UNDECIDED" if m.get("verdict") == "undecided"   # a search's gap straddles it
                  else "pass" if m["passed"] else "FAIL")
        rows.append((m["label"], spacing, value, target, status))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    from cadgen.report.content import verdict_text

    met = all(m["passed"] for m in report["metrics"])
    lines = [f"design {report['design']} ({report['mechanism']} mechanism): "
             f"{verdict_text(report)}; {'all targets met' if met else 'TARGETS MISSED'}"]
    for k, row in enumerate(rows):
        lines.append("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        if k == 0:
            lines.append("  ".join("-" * w for w in widths))
    lines.append("")
    ev = report.get("events")
    if ev is None:   # a bench run: no soil, so no entry, exit or absolute motion
        lines.append("bench run: no soil, so "
                     "no attitude at entry and exit, no holes and no absolute tip speeds")
    else:
        att = {key: _number(value, ".3f") for key, value in ev["attitude_deg"].items()}
        lines.append("attitude Psi (deg): catching {catching}, entry {entry}, lowest {lowest}, "
                     "exit {exit}".format(**att))
        vl = ev["tip_velocity_relative_lowest_mm_s"]
        lines.append(f"tip velocity at the lowest point, relative: ({_number(vl[0], '.2f')}, "
                     f"{_number(vl[1], '.2f')}) mm/s at {_number(ev['carrier_speed_rpm'], 'g')} "
                     "r/min")
        for row in report.get("per_spacing", []):
            v = row["tip_velocity_absolute_lowest_mm_s"]
            lines.append(f"  absolute at S = {_number(row['spacing_mm'], 'g')} mm: "
                         f"({_number(v[0], '.2f')}, {_number(v[1], '.2f')}) mm/s")
        lines.append("catching-to-planting height: "
                     f"{_number(ev['catch_to_plant_height_mm'], '.3f')} mm")
    d = report["derived"]
    lines.append(f"centre distance a = {_number(d['centre_distance_a_mm'], '.4f')} mm, "
                 f"module {_number(d['module_mm'], '.4f')} mm, ratio "
                 f"{_number(d['ratio_min'], '.4f')}..{_number(d['ratio_max'], '.4f')}")
    return "\n".join(lines)


def format_cam(cam: dict) -> str:
    """Plain-text summary of the duckbill cam and its checks."""
    events = cam["carrier_angle_deg"]

    def deg(value):
        return _number(value, ".1f")

    lines = [f"cam: opening {_number(cam['opening_angle_deg'], '.2f')} deg (mouth "
             f"{_number(cam['mouth_mm'], '.1f')} mm for {_number(cam['required_mouth_mm'], '.1f')}"
             f" mm), push-rod stroke {_number(cam['push_rod_stroke_mm'], '.2f')} mm, roller lift "
             f"{_number(cam['roller_lift_mm'], '.2f')} mm",
             f"     opens {deg(events['opening'][0])}..{deg(events['opening'][1])} deg, closes "
             f"{deg(events['closing'][0])}..{deg(events['closing'][1])} deg (lowest point "
             f"{deg(events.get('lowest'))}, exit {deg(events.get('exit'))}, seedling cleared "
             f"{deg(events.get('seedling_cleared'))})",
             f"     pressure angle max {_number(cam['pressure_angle_max_deg'], '.2f')} deg, "
             f"smallest convex pitch radius "
             f"{_number(cam['pitch_radius_convex_min_mm'], '.2f', 'none (no convex stretch)')} mm "
             f"for a {_number(cam['roller_radius_mm'], 'g')}-mm roller"]
    for problem in cam["problems"]:
        lines.append(f"     FAIL [{problem['code']}] {problem['message']}")
    if cam.get("not_written"):
        lines.append(f"     {cam['not_written']}")
    return "\n".join(lines)


def format_duckbill(duckbill: dict) -> str:
    """Plain-text lines of the duckbill linkage: its return spring and the roller's force."""
    spring, roller, follower = duckbill.get("spring"), duckbill["roller"], duckbill["follower"]
    lines = []
    if spring:
        lines.append(
            f"     return spring: wire {_number(spring['wire'], 'g')} mm (EN 10270-1 DH), D "
            f"{_number(spring['mean_diameter'], '.1f')} mm, n {_number(spring['active_coils'], 'g')}"
            f", L0 {_number(spring['free_length'], '.1f')} mm, {_number(spring['rate'], '.2f')} N/mm;"
            f" {_number(spring['preload'], '.1f')} N closed (contact needs "
            f"{_number(follower['needed_spring_force_max_n'], '.1f')} N x "
            f"{_number(follower['safety_factor'], 'g')}), {_number(spring['force_max'], '.1f')} N "
            f"open; stress {_number(spring['stress_max'], '.0f')} of "
            f"{_number(spring['stress_allowed'], '.0f')} MPa")
    lines.append(f"     roller {roller['bearing']}: contact force "
                 f"{_number(roller['contact_force_min_n'], '.1f')}.."
                 f"{_number(roller['contact_force_max_n'], '.1f')} N at "
                 f"{_number(follower['carrier_speed_rpm'], 'g')} r/min")
    return "\n".join(lines)


def format_machine(machine: dict, bom=None, axial=None) -> str:
    """Plain-text summary of the shafts, bearings, keys, rims, what holds the parts along their
    shafts (``axial``: report.json ``assembly.axial``) and the bill of materials."""
    shafts = machine.get("shafts", [])
    lines = [f"machine ({machine.get('process', MISSING)}): "
             + ", ".join(f"{s['name']} {_number(s['diameter_mm'], 'g')} mm"
                         for s in shafts if s.get("side", 1) == 1)]
    sources = machine.get("load_sources")
    if sources:
        lines.append(f"     loads: sized from the {' and the '.join(sources['sized_from'])}, "
                     f"checked with the {' and the '.join(sources['checked_with'])}"
                     + ("" if sources.get("recheck_passed", True) else ": RE-CHECK FAILED"))
    bearings = machine.get("bearings", [])
    if bearings:
        shortest = min(bearings, key=lambda b: b["l10_h"])
        lines.append(f"     bearings: {', '.join(sorted({b['designation'] for b in bearings}))}; "
                     f"shortest L10 {_number(shortest['l10_h'], '.0f')} h ({shortest['shaft']} "
                     f"{shortest['wall']}), target {_number(shortest['target_h'], 'g')} h")
    rims = [r for r in machine.get("hubs", []) if r.get("rim_mm") is not None]
    if rims:
        thin = min(rims, key=lambda r: r["rim_mm"] / r["module_mm"])
        lines.append(f"     thinnest rim under a bore: {_number(thin['rim_mm'], '.2f')} mm "
                     f"({thin['gear']}; fails below {_number(thin['limit_mm'], '.2f')} mm)")
    if axial:
        free = axial.get("free") or []
        lines.append(f"     along the shafts: {axial['parts']} parts, held by shoulders, "
                     "spacers, DIN 471 rings and set screws: "
                     + ("every part held both ways" if not free else "FREE TO SLIDE: " + ", ".join(
                         f"{f['what']} ({' and '.join(f['ways'])})" for f in free)))
    for problem in machine.get("problems", []):
        lines.append(f"     FAIL [{problem['code']}] {problem['message']}")
    if bom:
        made = sum(r["quantity"] for r in bom if r["source"] == "make")
        bought = sum(r["quantity"] for r in bom if r["source"] == "buy")
        lines.append(f"     bill of materials: {made} made and {bought} bought parts (bom.csv)")
    return "\n".join(lines)


def format_solids(solids: dict) -> str:
    """Plain-text summary of the solids: parts, mass, enclosure."""
    parts = solids["parts"]
    instances = sum(p["instances"] for p in parts)
    density = (f"{_number(solids['density_kg_m3'], 'g')} kg/m3"
               if solids.get("density_kg_m3") is not None else
               f"each part's material ({solids.get('process', 'machined')})")
    bought = (solids.get("bought") or {}).get("placed")
    placed = f"{instances} placed" + (f", and {bought} bought solids" if bought else "")
    lines = [f"solids: {len(parts)} parts ({placed}), total mass "
             f"{_number(solids['total_mass_kg'], '.2f')} kg at {density}, assembly at carrier "
             f"angle {_number(solids['assembly']['carrier_angle_deg'], 'g')} deg"]
    for row in solids["enclosure"]:
        margin = row.get("smallest_margin_mm")
        if margin is None:
            lines.append(f"     {row['housing']}: no gears were cut, so its size is a coarse "
                         "estimate (each gear within the centre distance)")
            continue
        state = ("encloses its gears" if row["gears_enclosed"] else "DOES NOT enclose its gears")
        axial = ("" if row.get("axial_fit", True)
                 else "; the gears' faces do not fit between its floor and roof")
        lines.append(f"     {row['housing']} {state} (smallest margin {_number(margin, '.2f')} mm, "
                     f"{row.get('nearest_gear') or MISSING}{axial})")
    overlaps = solids.get("overlaps")
    if overlaps:
        if overlaps["failures"]:
            lines += [f"     OVERLAP: {failure}" for failure in overlaps["failures"]]
        else:
            lines.append(f"     no parts overlap ({overlaps['pairs_examined']} touching pairs "
                         "checked; only their fits' chord-error shells and screw threads)")
    printed = [p for p in parts if p.get("overhang_mm2") is not None]
    if printed:
        needing = [p for p in printed if p.get("supports_needed")]
        worst = max(printed, key=lambda p: p["overhang_mm2"])
        lines.append(f"     printing: {len(needing)} of {len(printed)} printed parts need supports"
                     + (f" (overhang up to {_number(worst['overhang_mm2'], '.0f')} mm2, "
                        f"{worst['part']})" if needing else "")
                     + "; each on the face that leaves the least overhang")
    alignment = solids.get("alignment") or []
    if alignment:
        worst = max(alignment, key=lambda row: row["misalignment_arcmin"])
        lines.append(f"     bearing seats' alignment: worst {worst['misalignment_arcmin']:.1f}' "
                     f"(shaft {worst['shaft']} in {worst['housing']}; dowelled cover, "
                     f"{_number(worst['position_tolerance_mm'], 'g')} mm bore positions), "
                     f"bearings accept {_number(worst['allowance_arcmin'], 'g')}'")
    volume = solids.get("build_volume_mm")
    for part in solids.get("too_big_for_build_volume") or []:
        size = " x ".join(_number(v, ".1f") for v in part["print_extents_mm"])
        bed = " x ".join(_number(v, "g") for v in volume) if volume else MISSING
        lines.append(f"     warning: {part['part']} ({part['kind']}) is {size} mm in its printing "
                     f"pose, larger than the build volume {bed} mm (manufacturing.build_volume)")
    return "\n".join(lines)


def format_gear_table(gear_train: dict, report: dict | None = None) -> str:
    """The gear verdict in one line (as the report page words it), then a table of the gears
    cut (none when none was), their meshes, and why any gear was not cut.

    ``report``, the whole report, lets the verdict name the pairs' other gears (a pricking
    report's pitch curves); without it the train's own entries are used.
    """
    from cadgen.report.gear_verdict import gear_verdict

    verdict = gear_verdict(report if report is not None else {"gear_train": gear_train})
    lines = [f"gears: {verdict.statement()}"]
    rows = [("gear", "teeth", "module", "cutter", "undercut teeth", "pointed", "problems")]
    for g in gear_train["gears"]:
        rows.append((g["gear"], str(g["teeth"]), _number(g["module_mm"], ".4f"), g["cutter"] +
                     (f" (z={g['shaper_teeth']})" if g.get("shaper_teeth") else ""),
                     str(len(g["undercut_teeth"])), str(len(g["pointed_teeth"])),
                     ", ".join(p["code"] for p in g["problems"]) or "-"))
    if len(rows) > 1:   # a header over no rows says nothing the line above does not
        widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
        table = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
        table.insert(1, "  ".join("-" * w for w in widths))
        lines += [""] + table
    meshes = []
    for m in gear_train["meshes"]:
        relief = m.get("tip_relief")
        backlash = m.get("backlash_deg") or (None, None)
        meshes.append(
            f"mesh {m['stage']}: {m['interference_poses']} interfering poses of {m['poses']} "
            f"(largest overlap {_number(m.get('overlap_area_max_mm2'), '.1e')} mm2), backlash "
            f"{_number(backlash[0], '.1e')}..{_number(backlash[1], '.1e')} deg, transmission "
            f"error {_number(m.get('transmission_error_pp_deg'), '.1e')} deg p-p"
            + (f"; tip relief on the {relief['gear']} gear: "
               f"{_number(relief['removed_area_mm2'], '.3f')} mm2, up to "
               f"{_number(relief['depth_mm'], '.3f')} mm deep" if relief else ""))
    for f in gear_train["failures"]:
        meshes.append(f"NOT CUT [{f['code']}] {f['message']}")
    if meshes:
        lines += [""] + meshes
    strength = gear_train.get("strength")
    if strength:
        lines += ["", _strength_line(gear_train["gears"], strength)]
    return "\n".join(lines)


def _strength_line(gears: list, strength: dict) -> str:
    """One line: the least bending and contact safeties of the train, whose, against the
    limits, and the load they are for."""
    rated = [g for g in gears if "bending_safety_min" in g]
    if not rated:
        return "tooth strength: no gear rated"
    limits = strength["limits"]
    bending = min(rated, key=lambda g: g["bending_safety_min"])
    contacts = [g for g in rated if g.get("contact_safety_min") is not None]
    text = (f"tooth strength ({strength['load'].split(':')[0]}): least bending safety "
            f"{bending['bending_safety_min']:.2f} ({bending['gear']}; limit "
            f"{limits['bending_safety_min']:g})")
    if contacts:
        contact = min(contacts, key=lambda g: g["contact_safety_min"])
        text += (f", least contact safety {contact['contact_safety_min']:.2f} "
                 f"({contact['gear']}; limit {limits['contact_safety_min']:g})")
    low = len(strength.get("problems", []))
    return text + (f"; {low} checks below their limits" if low else "")
