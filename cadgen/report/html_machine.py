"""The report page's machine sections: shafts, bearings, keys and rims, fits; the bill of materials.

Each function takes the report (``report.json``'s content) and returns one
``<section>`` (or ``""`` when the build has no such section), like
:mod:`cadgen.report.html_sections`.
"""

from __future__ import annotations

from cadgen.report.html_tables import (_badge, _e, _number, _pass_badge, _problem_list, _section,
                                       _table)

__all__ = ["machine_section_html", "bom_section_html", "machine_checks"]


def machine_checks(report: dict) -> list:
    """``(name, passed, detail)`` rows of the page's verdict for the machine design."""
    machine = report.get("machine")
    if machine is None:
        return []
    bearings = machine.get("bearings", [])
    short = [b for b in bearings if not b.get("passed", True)]
    shafts = machine.get("shafts", [])
    problems = machine.get("problems", [])
    keyed = [p for p in problems if p["code"] == "key_overloaded"]
    other = [p for p in problems if p["code"] not in ("key_overloaded", "bearing_life_short")]
    rows = [("bearing life", not short,
             f"{len(bearings) - len(short)} of {len(bearings)} bearings reach "
             f"{_number(bearings[0]['target_h'], trim=True) if bearings else '—'} h"),
            ("keys", not keyed, f"{len(keyed)} overloaded" if keyed else "every key within "
             "its flank pressure"),
            ("shafts", not other, f"{len(shafts)} shafts sized" if not other
             else "; ".join(p["message"] for p in other))]
    assembly = report.get("assembly")
    if assembly:
        rule = assembly["mobility_rule"]
        rows.append(("joint graph", bool(assembly.get("passed")),
                     f"mobility {assembly['mobility']} ({rule['bodies']} bodies, "
                     f"{rule['lower_pairs']} revolute, {rule['higher_pairs']} gear and cam "
                     "pairs)" + ("; loose: " + ", ".join(assembly["unconnected"])
                                 if assembly["unconnected"] else "")))
    rims = machine.get("hubs", [])
    if rims:
        thin = [r for r in rims if not r["passed"]]
        measured = [r for r in rims if r.get("rim_mm") is not None]
        thinnest = min(measured, key=lambda r: r["rim_mm"] / r["module_mm"], default=None)
        detail = (f"thinnest {_number(thinnest['rim_mm'])} mm ({thinnest['gear']}, "
                  f"{_number(thinnest['rim_mm'] / thinnest['module_mm'])} modules)"
                  if thinnest else "no gear bored")
        rows.append(("gear rims under the bores", not thin, detail))
    return rows


def _sides(records, key) -> list:
    """``(record, label)``: a record of side 2 identical to side 1's but for the side is left
    out and side 1's is labelled "both sides" (gearbox 1's axes A, B, C)."""
    def payload(record):
        return {k: v for k, v in record.items() if k not in ("side", "xy_mm")}

    first = {key(r): r for r in records if r.get("side", 1) == 1}
    twins = {key(r) for r in records if r.get("side", 1) == 2
             and key(r) in first and payload(r) == payload(first[key(r)])}
    out = []
    for r in records:
        if r.get("side", 1) == 2 and key(r) in twins:
            continue
        label = (" (both sides)" if key(r) in twins else
                 f" (side {r['side']})" if r.get("side", 1) != 1 else "")
        out.append((r, label))
    return out


def machine_section_html(report: dict) -> str:
    machine = report.get("machine")
    if machine is None:
        return ""
    fits = machine.get("fits", {})
    body = [f"<p>process <b>{_e(machine.get('process', '—'))}</b>: bearing seats "
            f"{_e(fits.get('seat_fit', '—'))}, journals {_e(fits.get('shaft_fit', '—'))}, "
            f"shaft holes +{_e(_number(fits.get('running_clearance_mm'), trim=True))} mm, "
            f"keyways +{_e(_number(fits.get('key_slot_allowance_mm'), trim=True))} mm, gear "
            f"backlash allowance {_e(_number(fits.get('backlash_mm'), trim=True))} mm per gear, "
            f"bolt holes ISO 273 {_e(fits.get('bolt_hole_series', '—'))}</p>"]
    sources = machine.get("load_sources")
    if sources:   # which load the sizes came from, and which the figures below
        body.append(f"<p>loads: sizes chosen from the <b>{_e(', '.join(sources['sized_from']))}"
                    f"</b>; the torques, key pressures, bearing loads and lives below are the "
                    f"<b>{_e(', '.join(sources['checked_with']))}</b>'s (bearing load: ISO 281's "
                    f"cycle-equivalent load where the dynamics ran)</p>")
    rows = []
    for s, side in _sides(machine.get("shafts", []), lambda r: r["name"]):
        hubs = "; ".join(
            f"{h['gear']}: " + (h["key"]["designation"].removeprefix("parallel key ")
                                + f" ({_number(h['key'].get('pressure_mpa'), 0)} MPa)"
                                if h.get("key") else
                                f"runs free on 2 x {h['runs_free_on']['designation']}"
                                if h.get("runs_free_on") else
                                f"D-flat {_number(h.get('flat_depth_mm'))} mm"
                                if h.get("flat_depth_mm") else "plain bore")
            for h in s.get("hubs", []))
        rows.append([_e(s["name"] + side),
                     _e(s["housing"]), _e(_number(s["diameter_mm"], trim=True)),
                     _e(_number(s["required_mm"], 1)), _e(_number(s["torque_nm"], 1)),
                     _e(_number(s.get("length_mm"), 1)), _e(hubs or "—"),
                     _e(s.get("load_source", "—")), _pass_badge(s.get("strength_passed", True))])
    body.append("<h3>Shafts</h3>" + _table(
        ["shaft", "housing", "diameter (mm)", "required (mm)", "torque (N·m)", "length (mm)",
         "hubs (key, flank pressure)", "load from", "strength"], rows, numeric=(2, 3, 4, 5),
        empty="no shafts sized"))
    rows, classes = [], []
    for b, side in _sides(machine.get("bearings", []), lambda r: (r["shaft"], r["wall"])):
        rows.append([_e(f"{b['shaft']} {b['housing']} {b['wall']}{side}"),
                     _e(b["designation"] + (f" x {b['count']} (pair)"
                                            if b.get("count", 1) > 1 else "")),
                     _e(f"{_number(b['d_mm'], trim=True)} x {_number(b['D_mm'], trim=True)} x "
                        f"{_number(b['B_mm'], trim=True)}"),
                     _e(_number(b["C_kn"], trim=True)), _e(_number(b["seat_diameter_mm"], 4)),
                     _e(_number(b["load_n"], 0)), _e(_number(b["speed_rpm"], 1)),
                     _e(_number(b["l10_h"], significant=3)), _e(b.get("load_source", "—")),
                     _pass_badge(b.get("passed", True))])
        classes.append("" if b.get("passed", True) else "fail")
    body.append("<h3>Bearings (ISO 281 basic rating life L10)</h3>" + _table(
        ["shaft, wall", "bearing", "d x D x B (mm)", "C (kN)", "seat (mm)", "load (N)",
         "speed (r/min)", "L10 (h)", "load from", "life"], rows, numeric=(3, 4, 5, 6, 7),
        row_classes=classes,
        empty="no bearings chosen"))
    rims = machine.get("hubs", [])
    if rims:
        rows = [[_e(r["gear"]), _e(_number(r["rim_mm"])), _e(_number(r["limit_mm"])),
                 _e(_number(r["warning_limit_mm"])),
                 _badge("fail") if not r["passed"] else
                 _badge("warn") if r["problems"] else _badge("pass")] for r in rims]
        body.append("<h3>Rim left under each gear's bore and keyway</h3>" + _table(
            ["gear", "thinnest rim (mm)", "fails below (mm)", "warns below (mm)", "check"],
            rows, numeric=(1, 2, 3)))
    body.append(_transmission_html(report))
    body.append(_fixings_html(machine.get("fixings") or {}))
    body.append(_retention_html(machine.get("retention") or [],
                                (report.get("assembly") or {}).get("axial")))
    body.append(_alignment_html((report.get("solids") or {}).get("alignment") or []))
    body.append(_joint_graph_html(report.get("assembly")))
    problems = machine.get("problems", [])
    if problems:
        body.append(_problem_list(problems))
    rules = (machine.get("rules") or {}).get("text") or {}
    if rules:
        body.append("<details><summary>how the sizes were chosen</summary><ul>"
                    + "".join(f"<li><b>{_e(k.replace('_', ' '))}</b>: {_e(v)}</li>"
                              for k, v in rules.items()) + "</ul></details>")
    return _section("machine", "Transmission: shafts, bearings, hubs, joints", "".join(body))


def _transmission_html(report: dict) -> str:
    """Train 1's two sets mesh by mesh (working against axis distance), the frame's drive, the
    pricking case's hold and drive."""
    train = report.get("gear_train") or {}
    out = []
    rows = []
    for record in train.get("sets", []):
        for mesh in record["meshes"]:
            rows.append([_e(record["name"]), _e(f"{mesh['driver']} → {mesh['driven']}"),
                         _e(f"{mesh['driver_teeth']} / {mesh['driven_teeth']}"),
                         _e(_number(mesh["module_mm"], trim=True)),
                         _e(" / ".join(_number(x, 3) for x in mesh.get("profile_shifts", []))),
                         _e(_number(mesh["centre_distance_mm"], 3)),
                         _e(_number(mesh["axis_distance_mm"], 3))])
    if rows:
        ratios = "; ".join(f"{r['name']}: converted ratio {_number(r['converted_ratio'], 4)} "
                           f"({'exact' if r['ratio_exact'] else 'not exact'} from the teeth)"
                           for r in train["sets"])
        out.append("<h3>Train 1: both sets on the axes O, A, B, C</h3><p>" + _e(ratios) + "</p>"
                   + _table(["set", "mesh", "teeth", "module (mm)", "profile shifts",
                             "working centre distance (mm)", "axis distance (mm)"], rows,
                            numeric=(3, 5, 6)))
    drive = train.get("drive")
    if drive:
        teeth = drive["teeth"]
        out.append("<h3>The frame's drive</h3><p>" + _e(
            f"input gear 1 ({teeth['z1']} teeth) → central shaft gear ({teeth['z2']}), input "
            f"gear 2 ({teeth['z3']}) → transmission driven gear ({teeth['z4']}) on gearbox 1, "
            f"module {_number(drive['module_1'], trim=True)} mm, axis distance "
            f"{_number(drive['centre_distance'], trim=True)} mm: n = {drive['ratio_fraction']} "
            f"({'exact' if drive['exact'] else 'error ' + _number(drive['ratio_error'], 6)}); "
            f"the input turns at {_number(drive['input_speed_rpm'], 1)} r/min for "
            f"{_number(drive['carrier_speed_rpm'], 1)} r/min of carrier 1") + "</p>")
    held = ((report.get("machine") or {}).get("rules") or {}).get("case_drive")
    if held:
        sprocket, bracket = held["sprocket"], held["bracket"]
        out.append("<h3>The gear case's hold and drive</h3><p>" + _e(
            f"the sun's shaft is keyed into a frame bracket ({_number(bracket['plate'], 1)} mm "
            f"plate, 4 x {bracket['mount_bolt']} mounting holes); the case is driven by an ISO "
            f"606 {held['chain']['designation']} sprocket of {sprocket['teeth']} teeth "
            f"(pitch diameter {_number(sprocket['pitch_diameter'], 2)} mm) bolted to its floor: "
            f"{_number(sprocket['torque_nm'], 1)} N·m at {_number(sprocket['speed_rpm'], 1)} "
            f"r/min, a chain pull of {_number(sprocket['chain_pull_n'], 0)} N") + "</p>")
    return "".join(out)


def _fixings_html(fixings: dict) -> str:
    """How the arm's parts are fixed: the keyed hubs (key, hub, flank pressure), the cam's
    screws (circle, counterbores, shear), the needle's clamp."""
    rows = []
    for name, fix in fixings.items():
        if "shaft" in fix:   # a keyed hub
            key = fix.get("key")
            what = (f"{key['designation']} in a {_number(fix['length'], trim=True)} mm hub "
                    f"(boss {_number(fix['outside'], trim=True)} mm) on shaft {fix['shaft']}"
                    if key else f"a D-flat {_number(fix['flat_depth'])} mm deep on shaft "
                                f"{fix['shaft']}")
            check = ("not checked (a D-flat)" if fix.get("pressure_mpa") is None else
                     f"{_number(fix['pressure_mpa'], 0)} MPa of {_number(fix['allowed_mpa'], 0)}"
                     f" under {_number(fix['torque_nm'])} N m")
            passed = fix.get("pressure_mpa") is None or fix["pressure_mpa"] <= fix["allowed_mpa"]
        elif "bolt" in fix:   # a screwed plate
            what = (f"{fix['bolts']} x {fix['screw']} on a "
                    f"{_number(2 * fix['bolt_circle_radius'], 1)} mm circle, heads sunk in "
                    f"{_number(fix['counterbore_diameter'], trim=True)} x "
                    f"{_number(fix['counterbore_depth'], trim=True)} mm counterbores, into "
                    f"{fix['carries']}'s cover")
            check = (f"screws' shear {_number(fix['bolt_shear_mpa'], 0)} MPa of "
                     f"{_number(fix['bolt_shear_allow_mpa'], 0)} under "
                     f"{_number(fix['torque_nm'])} N m")
            passed = fix["bolt_shear_mpa"] <= fix["bolt_shear_allow_mpa"]
        else:   # the needle's clamp
            what = (f"a {_number(fix['outside'])} mm holder, bore {_number(fix['bore'], 3)} mm, "
                    f"{fix['set_screw']}")
            check, passed = "slides to set its reach, then clamped", True
        rows.append([_e(name), _e(what), _e(check), _badge("pass" if passed else "fail")])
    if not rows:
        return ""
    return ("<h3>How the arm's parts are fixed</h3>"
            + _table(["part", "fixing", "check", ""], rows))


def _stack_words(part: dict) -> str:
    """One part of a shaft's axial stack, as the fitter slides it on."""
    length = part["z"][1] - part["z"][0]
    if part["kind"] == "bearing":
        return f"bearing {part['designation']} ({part['housing']}'s shoulder {part['stop']})"
    if part["kind"] == "spacer":
        return f"spacer {_number(length, 2)} mm"
    if part["kind"] == "ring":
        return "ring " + part["designation"]
    return part["part"]


def _retention_html(stacks: list, axial) -> str:
    """What holds each part along its shaft (bottom up), and the check that nothing slides."""
    if not stacks:
        return ""
    def words(stack):   # a gap (a wall, another housing) between two runs of parts: "…"
        out = []
        for k, part in enumerate(stack):
            if k and part["z"][0] - stack[k - 1]["z"][1] > 1.0:
                out.append("…")
            out.append(_stack_words(part))
        return " | ".join(out)

    rows = [[_e(f"{r['shaft']}" + (f" (side {r['side']})" if r["side"] != 1 else "")),
             _e(words(r["stack"])),
             _e("; ".join(f"{s['designation']} on {s['part']}" for s in r["set_screws"])
                or "—")] for r in stacks]
    verdict = ""
    if axial:
        free = axial.get("free") or []
        verdict = ("<p>" + _pass_badge(axial.get("passed")) + " "
                   + _e(f"{axial['parts']} parts along the axes, {axial['contacts']} contacts: "
                        + ("every part is held both ways" if not free else
                           "free to slide: " + ", ".join(
                               f"{f['what']} ({' and '.join(f['ways'])})" for f in free)))
                   + "</p>")
    return ("<h3>What holds each part along its shaft</h3>"
            "<p class=\"note\">Each shaft's parts from the bottom up: bearings against their "
            "seats' shoulders, turned spacers between the parts, DIN 471 retaining rings in "
            "grooves, a set screw onto the key where the shaft ends at a hub; … where the "
            "shaft passes a wall or another housing.</p>" + verdict
            + _table(["shaft", "from the bottom up", "set screws"], rows))


def _alignment_html(rows: list) -> str:
    """Each shaft's two seats, bored in a dowelled base and cover: the tilt they can have."""
    if not rows:
        return ""
    table = [[_e(f"{r['shaft']}" + (f" (side {r['side']})" if r["side"] != 1 else "")),
              _e(r["housing"]), _e(_number(r["span_mm"], 1)),
              _e(_number(r["dowel_clearance_mm"], 3)), _e(_number(r["position_tolerance_mm"], 3)),
              _e(_number(r["misalignment_arcmin"], 2)), _e(_number(r["allowance_arcmin"], 0)),
              _badge("pass" if r["passed"] else "warn")] for r in rows]
    return ("<h3>Bearing seats' alignment (two ISO 8734 dowels per cover)</h3>"
            "<p class=\"note\">The tilt two coaxial seats can have, one in the base and one in "
            "the cover: the dowels' largest H7/m6 clearance plus each bore's position tolerance, "
            "over the seats' span, against what a deep-groove ball bearing accepts.</p>"
            + _table(["shaft", "housing", "span (mm)", "dowel clearance (mm)",
                      "bore position (mm)", "tilt (')", "accepted (')", ""], table,
                     numeric=(2, 3, 4, 5, 6)))


def _joint_graph_html(assembly) -> str:
    """The joint graph's verdict: bodies, pairs, mobility, loose parts, joints not yet made."""
    if not assembly:
        return ""
    rule = assembly["mobility_rule"]
    text = (f"{len(assembly['parts'])} parts, {len(assembly['joints'])} joints: "
            f"{rule['bodies']} rigid bodies, {rule['lower_pairs']} revolute joints, "
            f"{rule['higher_pairs']} gear and cam pairs; {rule['formula']} = "
            f"{assembly['mobility']}")
    loose = assembly.get("unconnected") or []
    body = ("<h3>Joint graph</h3><p>" + _pass_badge(assembly.get("passed")) + " " + _e(text)
            + (_e("; held by nothing: " + ", ".join(loose)) if loose else "") + "</p>")
    joints = assembly.get("joints") or []
    if joints:
        def bought(joint):   # the same item twice on one joint (two seats) is said once
            counts = {}
            for item in joint.get("items", []):
                counts[item["description"]] = counts.get(item["description"], 0) + item["count"]
            return "; ".join(f"{n} x {what}" for what, n in counts.items()) or "—"

        rows = [[_e(j["kind"]), _e(j["a"]), _e(j["b"]), _e(j.get("detail", "")), _e(bought(j))]
                for j in joints]
        body += (f"<details><summary>every joint and what it is bought with ({len(joints)})"
                 "</summary>" + _table(["kind", "part", "held by", "what makes it",
                                        "bought items"], rows) + "</details>")
    sequence = assembly.get("sequence") or []
    if sequence:
        items = "".join(
            f"<li>{_e(step['part'])} onto {_e(step['onto'])}: {_e(step['how'])}"
            + (f" <span class=\"note\">({_e('; '.join(step['bought']))})</span>"
               if step["bought"] else "") + "</li>" for step in sequence)
        body += (f"<details><summary>assembly order ({len(sequence)} steps: each shaft's gears, "
                 "the housings outward from the frame, each closed after its shafts, then the "
                 "parts outside)</summary><ol>" + items + "</ol><p class=\"note\">Tightening "
                 "torques: ISO 4762 screws of class 8.8, friction 0.14 in the thread and under "
                 "the head (VDI 2230's table, 90 % of the yield point); into a tapped aluminium "
                 "housing no more than 80 % of it. The 3D view's Explode slider shows "
                 "the parts apart in this order.</p></details>")
    not_made = assembly.get("not_made") or []
    if not_made:
        body += ("<details><summary>joints in the graph not yet made as parts "
                 f"({len(not_made)})</summary><ul>"
                 + "".join(f"<li>{_e(item)}</li>" for item in not_made) + "</ul></details>")
    return body


def bom_section_html(report: dict) -> str:
    rows = report.get("bom")
    if not rows:
        return ""
    table = [[_e(str(r["item"])), _e(r["source"]), _e(r["part"]), _e(r["description"]),
              _e(r["material"]), _e(r["process"]), _e(str(r["quantity"])),
              _e(_number(r["mass_each_kg"], 3) if r.get("mass_each_kg") is not None else "—"),
              _e(r["file"] or "—")] for r in rows]
    made = sum(r["quantity"] for r in rows if r["source"] == "make")
    bought = sum(r["quantity"] for r in rows if r["source"] == "buy")
    body = (f"<p>{made} made parts and {bought} bought parts; the same rows are in "
            f"<code>bom.csv</code></p>"
            + _table(["item", "make/buy", "part", "description", "material", "process",
                      "quantity", "mass each (kg)", "file"], table, numeric=(0, 6, 7)))
    return _section("bom", "Bill of materials", body, folded=True,
                    gist=f"{made} made and {bought} bought parts")


def _strength_html(train: dict) -> str:
    """The teeth's strength over the cycle: each gear's least bending and contact safety,
    where, against the ``[machine]`` limits; the load it was computed for and the method."""
    strength = train.get("strength")
    if not strength:
        return ""
    limits = strength["limits"]
    rows, classes = [], []
    for g in train.get("gears", []):
        if "bending_safety_min" not in g:
            continue
        contact = g.get("contact_safety_min")
        low = (g["bending_safety_min"] < limits["bending_safety_min"]
               or (contact is not None and contact < limits["contact_safety_min"]))
        rows.append([_e(g["gear"]), _e(g["material"]),
                     _e(_number(g["equivalent_teeth_min"], 2)),
                     _e(_number(g["root_stress_max_mpa"], 0)),
                     _e(_number(g["bending_safety_min"], 2)),
                     _e(f"{g['bending_safety_mesh']}, {_number(g['bending_safety_at_deg'], 1)}°"),
                     _e(_number(g["contact_stress_max_mpa"], 0)),
                     _e("not rated" if contact is None else _number(contact, 2)),
                     _e("—" if contact is None else
                        f"{g['contact_safety_mesh']}, {_number(g['contact_safety_at_deg'], 1)}°"),
                     _e(str(g["strength_invalid_poses"]))])
        classes.append("fail" if low else "")
    factors = ", ".join(f"{k} {_number(v, trim=True)}" for k, v in strength["factors"].items())
    text = (f"Least safeties over each gear's meshes and poses against machine.bending_safety_min "
            f"= {_number(limits['bending_safety_min'], trim=True)} and "
            f"machine.contact_safety_min = {_number(limits['contact_safety_min'], trim=True)}. "
            f"Load: {strength['load']}. Method: {strength['method']}; load factors {factors}.")
    return ("<h3>Tooth strength over the cycle</h3><p>" + _e(text) + "</p>"
            + _table(["gear", "material", "least z_v", "root stress max (MPa)", "S_F min",
                      "where (mesh, cycle angle)", "Hertz stress max (MPa)", "S_H min",
                      "where (mesh, cycle angle)", "poses outside validity"], rows,
                     numeric=(2, 3, 4, 6, 7, 9), row_classes=classes)
            + _problem_list(strength.get("problems", []))
            + _problem_list(strength.get("warnings", []), "warn"))

