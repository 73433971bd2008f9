"""The HTML report's sections, one function per part of the report.

Each takes the report (a dict, the content of ``report.json``) and returns one
``<section>`` or "" when the report lacks that part, so reports of either
mechanism kind, with or without gears, cam, solids, sweep or stage statuses,
render. :func:`cadgen.report.html.render_html` puts them in page order.
"""

from __future__ import annotations

from cadgen.report.html_tables import (MAX_SIGNIFICANT, _badge, _degrees_ranges, _e,
                                       _key_values, _number, _pass_badge, _plural, _point,
                                       _problem_list, _prose, _quantity, _row, _scientific,
                                       _section, _split_unit, _table, _to_accuracy, _value_html)

__all__ = ["_metrics_section", "_planting_motion_section", "_pricking_section", "_sweep_section",
           "_gears_section", "_cam_section", "_solids_section", "_stages_section",
           "_accuracy_section", "_parameters_section", "_sweep_name"]


def _sweep_name(key: str, sweep: dict) -> str:
    """A clearance sweep's name on the page: its label, or its report key in words."""
    return str(sweep.get("label") or _split_unit(key)[0])


# ----------------------------------------------------------------------------------------------
# mechanism sections


def _metrics_section(report: dict) -> str:
    metrics = report.get("metrics", [])
    if not metrics:
        return ""
    # A clearance the solids' sweep measured keeps the kinematic estimate beside it.
    estimates = any("kinematic_estimate" in m for m in metrics)
    rows, classes = [], []
    for m in metrics:
        spacing = m.get("spacing_mm")
        spacing = "" if spacing is None else _quantity(spacing, "mm", trim=True)
        unit = m.get("unit", "")
        row = [_e(m["label"]), _e(spacing), _e(_quantity(m["value"], unit)),
               _e(f"{m['target']} {unit}".strip()),
               # a search whose gap [bound, value] straddles the target decides nothing
               _badge("warn").replace("WARN", "UNDECIDED") if m.get("verdict") == "undecided"
               else _pass_badge(m["passed"])]
        if estimates:
            estimate = m.get("kinematic_estimate")
            row.append(_e("" if estimate is None else _quantity(estimate, unit)))
        rows.append(row)
        classes.append("" if m["passed"] else "fail")
    headers = ["metric", "plant spacing", "value", "target", "result"]
    body = _table(headers + ["kinematic estimate"] * estimates, rows, numeric=(1, 2, 5),
                  row_classes=classes)
    met = sum(1 for m in metrics if m["passed"])
    return _section("metrics", "Design metrics against targets", body,
                    gist=f"{met} of {len(metrics)} met")


def _planting_motion_section(report: dict) -> str:
    parts = []
    events = report.get("events")
    if events:
        angles, attitude = events.get("carrier_angle_deg", {}), events.get("attitude_deg", {})
        rows = [[_e(name), _e(_quantity(angles.get(name), "deg", 2)),
                 _e(_quantity(attitude.get(name), "deg", 2))]
                for name in dict.fromkeys([*angles, *attitude])]
        rest = {k: v for k, v in events.items() if k not in ("carrier_angle_deg", "attitude_deg")}
        parts.append("<h3>Events over one carrier turn</h3>" + _row(
            _table(["event", "carrier angle", "attitude Ψ"], rows, numeric=(1, 2)),
            _key_values(rest)))
    spacings = report.get("per_spacing")
    if spacings:
        rows = [[_e(_quantity(s["spacing_mm"], "mm", trim=True)),
                 _e(_quantity(s["hole_width_mm"], "mm")),
                 _e(_quantity(s["hole_verticality_mm"], "mm")),
                 _e(_quantity(s["hole_span_mm"], "mm")),
                 _e(_number(s["x_entry_mm"], 2)), _e(_number(s["x_exit_mm"], 2)),
                 _e(_number(s["x_lowest_mm"], 2)),
                 _e(_point(s["tip_velocity_absolute_lowest_mm_s"], 2) + " mm/s")]
                for s in spacings]
        parts.append("<h3>Per plant spacing</h3>" + _table(
            ["spacing", "hole width", "verticality", "span", "x entry (mm)", "x exit (mm)",
             "x lowest (mm)", "tip velocity at lowest point"], rows, numeric=tuple(range(8))))
    if "derived" in report:
        derived = {k: v for k, v in report["derived"].items() if k not in _CLEARANCE_KEYS}
        if "housing_circles_mm" in derived:   # an input of the kinematic clearance model
            derived["housing_circles_kinematic_model_mm"] = derived.pop("housing_circles_mm")
        parts.append("<h3>Derived geometry</h3>" + _key_values(derived))
        parts.append(_clearance_methods(report))
    if not parts:
        return ""
    return _section("motion", "Planting motion and derived geometry", "".join(parts))


#: Derived-geometry keys of the kinematic clearance estimates, shown by method instead.
_CLEARANCE_KEYS = ("arm_distance_at_deg", "ground_clearance_at_deg", "ground_clearance_nearest",
                   "clearance_method")


def _clearance_methods(report: dict) -> str:
    """The clearances by method: the kinematic estimate (centre lines and housing circles,
    from the metrics stage) beside the FCL minimum on the solids, each with where it occurs."""
    derived, sweeps = report.get("derived", {}), report.get("sweep", {})
    metrics = {m.get("key"): m for m in report.get("metrics", [])}
    rows = []
    for key, sweep_key, where_key, nearest in (
            ("arm_distance", "arm_interference", "arm_distance_at_deg", None),
            ("ground_clearance", "ground_clearance", "ground_clearance_at_deg",
             derived.get("ground_clearance_nearest"))):
        if where_key not in derived and sweep_key not in sweeps:
            continue
        metric = metrics.get(key, {})
        sweep = sweeps.get(sweep_key)
        # with a sweep the metric's value is the solids' and the estimate stands beside it
        estimate = metric.get("kinematic_estimate", None if sweep else metric.get("value"))
        kinematic = (f"{_quantity(estimate, 'mm')} at " if estimate is not None else "") + \
            _quantity(derived.get(where_key), "deg", 2) + (f" ({nearest})" if nearest else "")
        solids = ("not run in this build" if sweep is None else
                  f"{_quantity(sweep.get('minimum_mm'), 'mm')} at "
                  f"{_quantity(sweep.get('carrier_angle_deg'), 'deg', 2)} "
                  f"({' ↔ '.join(map(str, sweep.get('nearest') or []))})")
        rows.append([_e(key.replace("_", " ")), _e(kinematic), _e(solids)])
    if not rows:
        return ""
    method = str(derived.get("clearance_method", "centre lines and housing circles"))
    method = method.removeprefix("kinematic: ")
    return ("<h3>Clearances by method</h3>"
            + _table(["clearance", f"kinematic estimate ({method}), carrier angle of arm 1",
                      "FCL on the solids (certified minimum), carrier angle"], rows)
            + '<p class="note">The kinematic estimates come from the metrics stage, the FCL '
              "minima from the solids' sweep (the values the checks use). The two arms take "
              "each other's poses every half turn, so a carrier angle and that angle plus "
              "180 deg give the same clearance with the arms swapped.</p>")


def _signed_windows(ranges) -> str:
    """Carrier-progress windows around the outer dead centre: ``-77.9 to 51.9 deg``."""
    if not ranges:
        return "none"
    return ", ".join(f"{_number(a, 1)} to {_number(b, 1)} deg" for a, b in ranges)


def _pricking_section(report: dict) -> str:
    field = report.get("field", {})
    rows, classes = [], []
    for r in field.get("per_inclination", []):
        root = r.get("needle_root_in_soil")
        rows.append([_e(_quantity(r["inclination_deg"], "deg", 1)),
                     _e(_quantity(r["needle_entry_angle_deg"], "deg", 2)),
                     _e(_quantity(r["needle_exit_angle_deg"], "deg", 2)),
                     _e(_quantity(r["hole_mouth_mm"], "mm", 2)),
                     _e(_quantity(r["time_in_soil_deg"], "deg", 1)),
                     _e(_signed_windows(r.get("slow_windows_deg"))),
                     _e(_quantity(r["slow_window_total_deg"], "deg", 1)),
                     _e(_quantity(r["projected_height_mm"], "mm", 1)),
                     _e(_quantity(r["width_mm"], "mm", 1)),
                     _badge("fail") + " yes" if root else "no"])
        classes.append("fail" if root else "")
    note = (f"carrier at {_number(field.get('carrier_speed_rpm'), trim=True)} r/min, forward "
            f"speed {_number(field.get('forward_speed_mm_s'), trim=True)} mm/s, depth "
            f"{_number(field.get('depth_mm'), trim=True)} mm; {field.get('angles', '')}; slow "
            "windows are carrier progress around the outer (R max) dead centre, negative "
            "before it, so a window across it reads -77.9 to 51.9 deg, not 282.1 to 411.9")
    note = f'<p class="note">{_e(note)}</p>'
    body = [note, _table(["inclination", "needle entry", "needle exit", "hole mouth", "in soil",
                          "slow windows (from R max)", "slow total", "height", "width", "needle root in soil"],
                         rows, numeric=(0, 1, 2, 3, 4, 6, 7, 8), row_classes=classes)]
    from cadgen.report.content import PREDICTED_FINDINGS

    findings = report.get("findings", [])
    # Newer reports count findings among their failures, but a prediction for rack cutting
    # (undercut) only warns: the cut teeth decide. Older reports only warn.
    state = "fail" if "failures" in report else "warn"
    failing = [f for f in findings if f.get("code") not in PREDICTED_FINDINGS]
    predicted = [f for f in findings if f.get("code") in PREDICTED_FINDINGS]
    body.append(f"<h3>Findings ({len(findings)})</h3>"
                + ((_problem_list(failing, state) + _problem_list(predicted, "warn"))
                   or '<p class="note">none</p>'))
    gears = report.get("gears", {})
    if gears.get("pitch_curves"):
        rows = [[_e(g["name"]), _e(str(g["stage"])), _e(g["role"]),
                 _e(_number(g["perimeter_mm"])),
                 _e(f"{_number(g['radius_min_mm'], 2)}–{_number(g['radius_max_mm'], 2)}"),
                 _e(_number(g["curvature_min_per_mm"], 4)),
                 "yes" if g["convex"] else _badge("warn") + " no",
                 _e(_number(g["pressure_angle_deviation_max_deg"], 1)),
                 _e(_number(g["convex_radius_of_curvature_min_mm"], 2)),
                 _badge("warn") + " yes" if g["undercut"] else "no"]
                for g in gears["pitch_curves"]]
        body.append("<h3>Pitch curves</h3>" + _table(
            ["gear", "stage", "role", "perimeter (mm)", "radius (mm)", "min curvature (1/mm)",
             "convex", "pressure-angle deviation (deg)", "min convex ρ (mm)", "undercut"],
            rows, numeric=(3, 4, 5, 7, 8)))
    rest = {k: v for k, v in gears.items() if k != "pitch_curves"}
    body.append(_row(*(f"<h3>{title}</h3>" + _key_values(data) for title, data in (
        ("Linkage", report.get("linkage")), ("Gear ratio split", rest),
        ("Forward check", report.get("verification"))) if data)))
    return _section("field", "Field behaviour per inclination", "".join(body))


def _sweep_section(report: dict) -> str:
    sweeps = report.get("sweep")
    if not sweeps:
        return ""
    names = list(sweeps)
    fields = (
        ("result", lambda s: _pass_badge(s.get("passed"))),
        ("minimum", lambda s: _e(_quantity(s.get("minimum_mm"), "mm"))),
        ("certified lower bound", lambda s: _e(_quantity(s.get("certified_bound_mm"), "mm"))),
        ("target", lambda s: _e("> " + _quantity(s.get("target_mm"), "mm", trim=True))),
        ("where (carrier angle)",
         lambda s: _e(_quantity(s.get("carrier_angle_deg"), "deg", 2))),
        ("nearest parts", lambda s: _e(" ↔ ".join(map(str, s.get("nearest") or [])) or "—")),
        ("nearest points (mm)",
         lambda s: _e(" ↔ ".join(_point(p) for p in s.get("nearest_points_mm") or []) or "—")),
        ("interference ranges",
         lambda s: _e(_degrees_ranges(s.get("interference_ranges_deg")))),
        ("kinematic estimate", lambda s: _e(_quantity(s.get("kinematic_estimate_mm"), "mm"))),
        ("evaluations", lambda s: _e(_number(s.get("evaluations")))),
        ("method", lambda s: _e(s.get("method", "—"))),
    )
    rows = [[_e(label)] + [cell(sweeps[n]) for n in names] for label, cell in fields]
    headers = ["", *(_sweep_name(n, sweeps[n]) for n in names)]
    body = _table(headers, rows)
    notes = [sweeps[n]["frame_note"] for n in names if sweeps[n].get("frame_note")]
    body += "".join(f"<p>{_e(note[:1].upper() + note[1:])}.</p>" for note in notes)
    return _section("sweep", "Interference and clearance sweep", body)


def _gears_section(report: dict) -> str:
    train = report.get("gear_train")
    if train is None:
        return ""
    from cadgen.report.gear_verdict import gear_verdict

    verdict = gear_verdict(report)
    rows, problems = [], []
    for g in train.get("gears", []):
        cutter = g["cutter"] + (f" (z = {g['shaper_teeth']})" if g.get("shaper_teeth") else "")
        codes = ", ".join(p["code"] for p in g.get("problems", []))
        rows.append([_e(g["gear"]), _e(g["stage"]), _e(str(g["teeth"])),
                     _e(_number(g["module_mm"], 4)), _e(cutter), "yes" if g["convex"] else "no",
                     _e(str(len(g["undercut_teeth"]))), _e(str(len(g["pointed_teeth"]))),
                     _e(_number(g["root_thickness_min_mm"])),
                     _e(_number(g["tip_thickness_min_mm"])),
                     _badge("warn") + " " + _e(codes) if codes else "—"])
        problems += g.get("problems", [])
    # the one statement of the checks row and the terminal, then the gears cut (if any)
    body = [f"<p>{_pass_badge(verdict.passed)} {_e(verdict.statement())}</p>"]
    if rows:
        body.append(_table(["gear", "stage", "teeth", "module (mm)", "cutter", "convex",
                            "undercut teeth", "pointed teeth", "min root thickness (mm)",
                            "min tip thickness (mm)", "problems"], rows,
                           numeric=(2, 3, 6, 7, 8, 9)))
    body.append(_problem_list(problems, "warn"))
    not_cut = ([[_e(gear), _e(pair), _badge("fail") + " " + _e(f"cannot be cut: {reason}")]
                for gear, pair, reason in verdict.not_cuttable]
               + [[_e(gear), _e(pair), _e(f"not cut: its mate {mate} cannot be cut")]
                  for gear, pair, mate in verdict.not_cut_with])
    if not_cut:
        body.append(f"<h3>Gears not cut ({len(not_cut)} of {verdict.total})</h3>"
                    + _table(["gear", "pair", "why"], not_cut)
                    + _problem_list(train.get("failures", [])))
    mesh_rows, classes = [], []
    for m in train.get("meshes", []):
        relief = m.get("tip_relief")
        relief_text = (f"{relief['gear']}: {_number(relief['removed_area_mm2'])} mm², "
                       f"{_number(relief['depth_mm'])} mm deep" if relief else "—")
        low, high = m["backlash_deg"]
        mesh_rows.append([_e(m["stage"]), _e(" / ".join(m["gears"])),
                          _e(_number(m["centre_distance_mm"])),
                          _e(f"{m['interference_poses']} of {m['poses']}"),
                          _e(_scientific(m["overlap_area_max_mm2"])),
                          _e(f"{_scientific(low)}–{_scientific(high)}"),
                          _e(_scientific(m["transmission_error_pp_deg"])), _e(relief_text)])
        classes.append("fail" if m["interference_poses"] else "")
    if mesh_rows:
        body.append("<h3>Meshes</h3>" + _table(
            ["stage", "gears", "centre distance (mm)", "interfering poses",
             "largest overlap (mm²)", "backlash (deg)", "transmission error p-p (deg)",
             "tip relief"],
            mesh_rows, numeric=(2, 3, 4, 5, 6), row_classes=classes))
    from cadgen.report.html_machine import _strength_html

    body.append(_strength_html(train))
    return _section("gears", "Gears", "".join(body), gist=verdict.statement())


def _cam_section(report: dict) -> str:
    cam = report.get("cam")
    if cam is None:
        return ""
    state = "pass" if cam.get("cuttable", True) and not cam.get("problems") else "fail"
    shown = {k: v for k, v in cam.items() if k != "problems"}
    verdict = "the roller can follow the contour" if state == "pass" else "cam problems below"
    body = (f"<p>{_badge(state)} {verdict}</p>"
            + _key_values(shown) + _problem_list(cam.get("problems", [])))
    duckbill = report.get("duckbill")
    if duckbill:   # the linkage's return spring, roller and pins (cadgen.machine.duckbill)
        body += "<h3>Duckbill linkage</h3>" + _key_values(_duckbill_rows(duckbill))
    return _section("cam", "Duckbill cam", body)


#: The return spring's numbers the page shows: (report key, label with its unit).
_SPRING_ROWS = (("designation", "designation"), ("wire", "wire (mm)"),
                ("mean_diameter", "mean diameter (mm)"), ("active_coils", "active coils"),
                ("free_length", "free length (mm)"), ("installed_length", "closed (mm)"),
                ("working_length", "open (mm)"), ("least_working_length", "least (mm)"),
                ("rate", "rate (N/mm)"), ("preload", "force closed (N)"),
                ("force_max", "force open (N)"), ("stress_max", "corrected stress (MPa)"),
                ("stress_allowed", "allowed, 0.5 Rm (MPa)"), ("utilisation", "utilisation"))


def _duckbill_rows(duckbill: dict) -> dict:
    spring, roller, loads = duckbill.get("spring") or {}, duckbill["roller"], duckbill["follower"]
    return {
        "return spring (EN 13906-1)": {label: spring[key] for key, label in _SPRING_ROWS
                                       if key in spring},
        "roller": {"bearing": roller["bearing"], "pin": roller["pin"], "ring": roller["ring"],
                   "contact force (N)": f"{roller['contact_force_min_n']:.1f} to "
                                        f"{roller['contact_force_max_n']:.1f}"},
        "loads": {"largest need (N)": loads["needed_spring_force_max_n"],
                  "at carrier angle (deg)": loads["needed_at_carrier_deg"],
                  "safety factor": loads["safety_factor"],
                  "carrier speed (r/min)": loads["carrier_speed_rpm"]},
        "pins": {joint: pin["designation"] for joint, pin in duckbill["pins"].items()},
    }


def _solids_section(report: dict) -> str:
    solids = report.get("solids")
    if solids is None:
        return ""
    # volume and mass no finer than the polygonal round parts allow (accuracy_achieved)
    error = _volume_error(report)
    rows = [[_e(p["part"]), _e(p["kind"]), _e(p.get("material", "—")), _e(str(p["instances"])),
             _e(_to_accuracy(p["volume_mm3"], _times(error, p["volume_mm3"]), "mm³")),
             _e(_to_accuracy(p["mass_kg"], _times(error, p["mass_kg"]), "kg")),
             _e(_point(p["centre_of_mass_mm"], 2)), _e(str(p.get("triangles", "—"))),
             _pass_badge(p.get("watertight", True))]
            for p in solids.get("parts", [])]
    assembly = solids.get("assembly", {})
    density = (f'density {_number(solids.get("density_kg_m3"), trim=True)} kg/m³'
               if solids.get("density_kg_m3") is not None else
               f'each part\'s material ({solids.get("process", "machined")})')
    body = [f'<p>total mass {_e(_quantity(solids.get("total_mass_kg"), "kg"))} at '
            f'{_e(density)}; assembly '
            f'<code>{_e(assembly.get("file", "—"))}</code> at carrier angle '
            f'{_e(_number(assembly.get("carrier_angle_deg"), trim=True))} deg</p>',
            _table(["part", "kind", "material", "instances", "volume (mm³)", "mass each (kg)",
                    "centre of mass (mm)", "triangles", "watertight"], rows,
                   numeric=(3, 4, 5, 7), empty="no parts")]
    printed = [p for p in solids.get("parts", []) if p.get("overhang_mm2") is not None]
    if printed:   # each printed part on the face that leaves the least unsupported overhang
        body.append("<h3>Printing: overhang steeper than 45° in each part's printing pose</h3>"
                    + _table(["part", "overhang (mm²)", "supports"],
                             [[_e(p["part"]), _e(_number(p["overhang_mm2"], 0)),
                               _badge("warn") + " needed" if p["supports_needed"]
                               else _badge("pass") + " none"] for p in printed],
                             numeric=(1,)))
    enclosure, classes = [], []
    for r in solids.get("enclosure", []):
        ok = r.get("gears_enclosed", True) and r.get("axial_fit", True)
        margin = r.get("smallest_margin_mm")
        enclosure.append([_e(r["housing"]), _pass_badge(r.get("gears_enclosed")),
                          _e(_quantity(margin, "mm") if margin is not None else
                             "coarse estimate (no gears cut)"),
                          _e(r.get("nearest_gear") or "—"), _pass_badge(r.get("axial_fit"))])
        classes.append("" if ok else "fail")
    if enclosure:
        body.append("<h3>Enclosure</h3>" + _table(
            ["housing", "encloses its gears", "smallest margin", "nearest gear", "axial fit"],
            enclosure, numeric=(2,), row_classes=classes))
    too_big = solids.get("too_big_for_build_volume") or []
    if too_big:
        volume = " x ".join(_number(v, trim=True) for v in solids.get("build_volume_mm") or [])
        body.append(f"<h3>Parts larger than the build volume ({_e(volume)} mm)</h3>" + _table(
            ["part", "kind", "printing-pose extents (mm)", "fits"],
            [[_e(p["part"]), _e(p["kind"]),
              _e(" x ".join(_number(v, 1) for v in p["print_extents_mm"])),
              _badge("warn").replace("WARN", "TOO BIG")]
             for p in too_big], numeric=(2,)))
    if solids.get("frames"):
        body.append(f'<p class="note">{_e(solids["frames"])}</p>')
    parts = solids.get("parts", [])
    return _section("solids", "Solids", "".join(body),
                    gist=f"{_plural(len(parts), 'part')}, total mass "
                         f"{_quantity(solids.get('total_mass_kg'), 'kg')}")


def _volume_error(report: dict) -> float | None:
    """The relative volume error the report states for its round parts (the polygon of
    ``solids.segments_per_circle`` sides, ``accuracy_achieved``), or None."""
    from cadgen.report.content import round_part_volume_error

    for row in report.get("accuracy_achieved") or []:
        if row.get("knob") == "solids.segments_per_circle" and isinstance(row.get("value"), int):
            return round_part_volume_error(row["value"])
    return None


def _times(error, value):
    return None if error is None or not isinstance(value, (int, float)) else error * abs(value)


def _stages_section(report: dict) -> str:
    if "stages" in report:
        stages = report["stages"]
    else:
        stages = [{"stage": k, "seconds": v} for k, v in report.get("stages_s", {}).items()]
    if not stages:
        return ""
    with_status = any("status" in s for s in stages)
    rows, classes = [], []
    for s in stages:
        row = [_e(s["stage"]), _e(_number(s.get("seconds"), 3))]
        if with_status:
            status = s.get("status", "ok")
            badge = {"ok": "pass", "failed": "fail"}.get(status, "warn")
            row += [f'<span class="badge {badge}">{_e(status)}</span>', _e(s.get("message", ""))]
        rows.append(row)
        classes.append("fail" if s.get("status") == "failed" else "")
    total = sum(float(s.get("seconds") or 0.0) for s in stages)
    rows.append(["<b>total</b>", f"<b>{_e(_number(total))}</b>"] + ["", ""][: 2 * with_status])
    classes.append("")
    headers = ["stage", "seconds"] + (["status", "message"] if with_status else [])
    failed = sum(1 for s in stages if s.get("status", "ok") != "ok")
    return _section("stages", "Stages", _table(headers, rows, numeric=(1,), row_classes=classes),
                    folded=not failed,
                    gist=f"{_plural(len(stages), 'stage')}"
                    + (f", {failed} not ok" if failed else "") + f", {_number(total, 1)} s")


def _searches_table(searches: dict) -> str:
    """The certified searches; a maximum (the highest point) carries an upper bound."""
    rows = []
    for name, search in searches.items():
        value, bound = search.get("value"), search.get("certified_bound")
        label = name.replace("_", " ")
        if search.get("maximum"):
            label += " (a maximum: its bound is an upper one)"
        elif name == "arm_distance":   # named by method, as the metrics' tables name it
            label += " (centre lines)"
        elif name == "ground_clearance":
            label = "gearbox ground clearance (envelope circles)"
        rows.append([_e(label), _e(_number(value)), _e(_number(bound)),
                     "yes" if search.get("certified") else _badge("warn") + " no",
                     _e(_scientific(search.get("gap"))), _e(_scientific(search.get("atol"))),
                     "yes" if search.get("budget_spent") else "no",
                     _e(_number(search.get("refined_intervals"))),
                     _e(_number(search.get("evaluations")))])
    # value and bound to the page's 0.001 mm: how far apart they are is the gap's column
    return _table(["search", "value (mm)", "certified bound (mm)", "certified", "gap", "atol",
                   "budget spent", "refined intervals", "evaluations"], rows,
                  numeric=(1, 2, 4, 5, 7, 8))


def _accuracy_section(report: dict) -> str:
    """What the build's resolution achieved: per knob (``accuracy_achieved``), then the
    metrics' own accuracy figures (``accuracy``, planting) or the forward check (pricking)."""
    achieved = report.get("accuracy_achieved") or []
    accuracy = dict(report.get("accuracy") or {})
    verification = report.get("verification") if report.get("mechanism") == "pricking" else None
    if not (achieved or accuracy or verification):
        return ""
    body = []
    if achieved:
        rows = [[f"<code>{_e(r.get('knob', ''))}</code>", _value_html(r.get("value", "")),
                 _e(_prose(r.get("achieved", ""))), _e(_prose(r.get("basis", "")))]
                for r in achieved]
        body.append("<h3>What each resolution knob buys</h3>"
                    + _table(["knob", "value", "achieved", "basis"], rows, numeric=(1,)))
    if verification:
        body.append("<h3>Forward check of the inverse design</h3>"
                    + _key_values(verification))
    if accuracy:
        searches = accuracy.pop("minimum_searches", None)
        body.append("<h3>Metrics: closure and searches</h3>" + _key_values(accuracy))
        if searches:
            body.append("<h3>Certified minimum searches of the metrics (kinematic model)</h3>"
                        + _searches_table(searches))
    return _section("accuracy", "Accuracy achieved", "".join(body), folded=True,
                    gist=f"what {_plural(len(achieved), 'resolution knob')} bought"
                    if achieved else "")


def _parameters_section(report: dict) -> str:
    if not report.get("parameters"):
        return ""
    # the values as written (to 6 significant digits): inputs, not results
    return _section("parameters", "Input parameters",
                    '<p class="note">The validated parameters, as the build read them.</p>'
                    + _key_values(report["parameters"], significant=MAX_SIGNIFICANT),
                    folded=True, gist="the validated parameter file")
