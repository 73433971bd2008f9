"""A design's report as one self-contained HTML page: tables and plots for a person.

The page embeds every figure as a ``data:`` URI and carries its own CSS, so it
opens anywhere (an e-mail attachment, an offline laptop) and references nothing
outside itself: no scripts, fonts, style sheets or images to fetch. It is a pure
function of the report and the figures (no dates, no dictionary-order surprises
in the figure gallery), so the same design gives the same bytes.

Sections that a report lacks are left out, so reports of either mechanism kind,
and reports with or without gears, cam, solids, sweep or stage statuses, render.
"""

from __future__ import annotations

import base64
import html
import math
import os
import re
import struct
from pathlib import Path

__all__ = ["render_html", "write_html", "load_figures", "figure_caption", "overall_checks"]

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# Suffixes of report keys that name a unit, longest first so "_mm_s" wins over "_s".
_UNIT_SUFFIXES = (
    ("_kg_mm2", "kg·mm²"), ("_kg_m3", "kg/m³"), ("_mm_s", "mm/s"), ("_per_mm", "1/mm"),
    ("_mm2", "mm²"), ("_mm3", "mm³"), ("_mm", "mm"), ("_deg", "deg"), ("_rad", "rad"),
    ("_rpm", "r/min"), ("_kg", "kg"), ("_s", "s"),
)

# Figure gallery groups, in page order: (heading, words that put a file in the group).
_FIGURE_GROUPS = (
    ("Motion: paths, attitude, velocity", ("path", "attitude", "velocity", "loop", "field")),
    ("Gears", ("pitch", "ratio", "gear")),
    ("Cam", ("cam",)),
    ("Solids and assembly", ("assembly", "solid", "part", "housing")),
    ("Clearance and interference sweep", ("clearance", "sweep", "interference", "distance")),
)

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;
 margin:0;background:#f4f5f7;color:#1d2430;font-size:14px;line-height:1.45}
main{max-width:1320px;margin:0 auto;padding:20px 28px 48px;background:#fff}
h1{font-size:26px;margin:4px 0 6px}
h2{font-size:19px;margin:30px 0 10px;padding-bottom:4px;border-bottom:2px solid #d8dde6}
h3{font-size:15px;margin:18px 0 6px}
.sub{color:#556070;margin:0 0 10px}
nav{margin:10px 0 4px;font-size:13px}
nav a{margin-right:14px;color:#2457a6;text-decoration:none}
table{border-collapse:collapse;margin:6px 0 12px;font-size:13px}
th,td{border:1px solid #d8dde6;padding:4px 8px;text-align:left;vertical-align:top}
th{background:#eef1f5;font-weight:600}
tbody tr:nth-child(even){background:#fafbfc}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
table.kv td:first-child{color:#3b4656;white-space:nowrap}
table.kv table{margin:0}
tr.fail td{background:#fdf0ef}
.badge{display:inline-block;padding:1px 8px;border-radius:10px;font-weight:700;font-size:12px}
.pass{background:#dff3e5;color:#176b32}
.fail{background:#fbe2df;color:#a4231b}
.warn{background:#fff0d4;color:#825600}
.verdict{font-size:20px;padding:4px 16px;border-radius:14px;margin-right:10px}
.hash{font-family:ui-monospace,Menlo,Consolas,monospace;font-size:12px;word-break:break-all}
ul.issues{margin:4px 0 12px;padding-left:20px}
ul.issues li{margin:3px 0}
code{font-family:ui-monospace,Menlo,Consolas,monospace;font-size:12px}
.gallery{display:grid;grid-template-columns:repeat(auto-fill,minmax(560px,1fr));gap:18px;
 align-items:start}
.row{display:flex;flex-wrap:wrap;gap:8px 32px;align-items:flex-start}
.row>div{min-width:0}
figure{margin:0;border:1px solid #d8dde6;border-radius:6px;padding:8px;background:#fff}
figure img{display:block;max-width:100%;height:auto;margin:0 auto}
figcaption{margin-top:6px;font-size:13px}
figcaption code{color:#6a7482}
details{margin:8px 0}
summary{cursor:pointer;font-weight:600}
.note{color:#556070;font-size:13px}
.preset{margin:0 0 4px}
"""


# ----------------------------------------------------------------------------------------------
# formatting


def _e(value) -> str:
    """Escape any value as HTML text (quotes too, so it is also safe inside attributes)."""
    return html.escape(str(value), quote=True)


def _number(value, digits: int = 3, trim: bool = False) -> str:
    """A number as text: ``digits`` decimals, or 3 significant digits when that would show 0."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if not isinstance(value, float):
        return str(value)
    if not math.isfinite(value):
        return str(value)
    if value == 0:
        return "0"
    text = f"{value:.{digits}f}"
    if float(text) == 0 or abs(value) >= 1e9:
        return f"{value:.3g}"
    if trim and "." in text:
        text = text.rstrip("0").rstrip(".")
    return text


def _quantity(value, unit: str = "", digits: int = 3, trim: bool = False) -> str:
    text = _number(value, digits, trim)
    return f"{text} {unit}" if unit and value is not None and not isinstance(value, bool) else text


def _split_unit(key: str) -> tuple[str, str]:
    """``"hole_width_mm"`` -> ``("hole width", "mm")``."""
    for suffix, unit in _UNIT_SUFFIXES:
        if key.endswith(suffix) and len(key) > len(suffix):
            return key[: -len(suffix)].replace("_", " "), unit
    return key.replace("_", " "), ""


def _badge(state: str) -> str:
    """``state`` is "pass", "fail" or "warn"."""
    return f'<span class="badge {state}">{state.upper()}</span>'


def _pass_badge(passed) -> str:
    return _badge("pass" if passed else "fail")


def _scientific(value) -> str:
    """Small quantities (overlaps, backlash, errors) in 2 significant digits; 0 as "0"."""
    return "0" if value == 0 else f"{value:.1e}"


def _degrees_ranges(ranges) -> str:
    if not ranges:
        return "none"
    return ", ".join(f"{_number(a, 1)}–{_number(b, 1)} deg" for a, b in ranges)


def _point(point, digits: int = 1) -> str:
    """A position or vector with fixed decimals: round-off noise (1e-15) shows as 0."""
    return "(" + ", ".join(f"{c + 0.0:.{digits}f}".replace(f"-{0:.{digits}f}", f"{0:.{digits}f}")
                           for c in point) + ")"


def _plural(count: int, noun: str, plural: str = "") -> str:
    return f"{count} {noun if count == 1 else plural or noun + 's'}"


def _row(*blocks: str) -> str:
    """Blocks side by side, wrapping when the page is narrow."""
    return '<div class="row">' + "".join(f"<div>{b}</div>" for b in blocks if b) + "</div>"


# ----------------------------------------------------------------------------------------------
# generic blocks


def _table(headers, rows, numeric=(), row_classes=None) -> str:
    """An HTML table; cells are HTML already, ``numeric`` column indices are right-aligned."""
    head = "".join(f"<th>{_e(h)}</th>" for h in headers)
    body = []
    for k, row in enumerate(rows):
        css = f' class="{row_classes[k]}"' if row_classes and row_classes[k] else ""
        cells = "".join(f'<td class="num">{c}</td>' if i in numeric else f"<td>{c}</td>"
                        for i, c in enumerate(row))
        body.append(f"<tr{css}>{cells}</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _records_table(records: list, index: list | None = None, unit: str = "",
                   digits: int = 3) -> str:
    """Dicts as the rows of one table (columns: the union of their keys, in order)."""
    keys = list(dict.fromkeys(k for r in records for k in r))
    headers = [_split_unit(k)[0] for k in keys]
    rows = [[_value_html(r.get(k), _split_unit(k)[1] or unit, digits) for k in keys]
            for r in records]
    if index is not None:
        headers = ["", *headers]
        rows = [[_e(name), *row] for name, row in zip(index, rows)]
    return _table(headers, rows)


def _value_html(value, unit: str = "", digits: int = 3) -> str:
    """Any JSON value as HTML: dicts and lists of dicts as nested tables, numbers with units."""
    if isinstance(value, dict):
        if len(value) > 1 and all(isinstance(v, dict) and v for v in value.values()):
            # e.g. {"lowest_point": {"value": ..., "certified": ...}, ...}: one row each
            return _records_table(list(value.values()), [_split_unit(str(k))[0] for k in value],
                                  unit, digits)
        return _key_values(value, unit, digits)
    if isinstance(value, (list, tuple)):
        if not value:
            return "none"
        if all(isinstance(v, dict) for v in value):
            return _records_table(list(value), None, unit, digits)
        if all(isinstance(v, (list, tuple)) for v in value):
            return ", ".join(_value_html(v, unit, digits) for v in value)
        text = ", ".join(_vector_items(value, digits))
        return _e(f"({text}) {unit}".rstrip() if unit else f"({text})")
    if _is_number(value):
        return _e(_quantity(value, unit, digits, trim=True))
    return _e(_number(value))


def _vector_items(values, digits: int = 3) -> list[str]:
    """Items of a list as text; a number's round-off noise (1e-14 next to 140) reads as 0."""
    scale = max((abs(v) for v in values if _is_number(v)), default=0.0)
    return [_number(0.0 if abs(v) < 1e-9 * scale else v, digits, trim=True) if _is_number(v)
            else _number(v) for v in values]


def _key_values(mapping: dict, unit: str = "", digits: int = 3) -> str:
    """A two-column table of a dict; keys lose their unit suffix, values gain the unit."""
    rows = []
    for key, value in mapping.items():
        label, own_unit = _split_unit(str(key))
        shown = f"{label} ({own_unit})" if own_unit and isinstance(value, dict) else label
        cell = _value_html(value, own_unit or unit, digits)
        rows.append(f"<tr><td>{_e(shown)}</td><td>{cell}</td></tr>")
    return f'<table class="kv"><tbody>{"".join(rows)}</tbody></table>'


def _problem_list(problems, state: str = "fail") -> str:
    """``problems``: dicts with "code" and "message" (and optionally "path" or "stage")."""
    if not problems:
        return ""
    items = []
    for p in problems:
        where = p.get("path") or p.get("stage") or ""
        where = f" <code>{_e(where)}</code>" if where else ""
        items.append(f"<li>{_badge(state)} <code>[{_e(p.get('code', ''))}]</code>{where} "
                     f"{_e(p.get('message', ''))}</li>")
    return f'<ul class="issues">{"".join(items)}</ul>'


def _section(anchor: str, title: str, body: str) -> str:
    return f'<section id="{anchor}"><h2>{_e(title)}</h2>{body}</section>'


# ----------------------------------------------------------------------------------------------
# verdict


def _sweep_name(key: str, sweep: dict) -> str:
    return str(sweep.get("label") or _split_unit(key)[0])


def overall_checks(report: dict) -> list[tuple[str, bool, str]]:
    """Every pass/fail check the page's verdict rests on: ``(name, passed, detail)``.

    The design passes when all of them pass: its metric targets (planting) or
    forward check (pricking), each clearance sweep (target met, no interference),
    every gear cut and meshing free, the cam cuttable, every housing enclosing its
    gears, every stage ok, and, when the report gives one (``"failures"``), the
    report's own verdict. Gear problems such as undercut are warnings.
    """
    checks = []
    if report.get("mechanism") == "pricking":
        check = report.get("verification", {})
        checks.append(("forward kinematic check", bool(report.get("verified")),
                       f"tip loop reproduced to {_number(check.get('forward_deviation_mm'))} mm"))
    elif "metrics" in report:
        metrics = report["metrics"]
        met = sum(1 for m in metrics if m["passed"])
        checks.append(("metric targets", met == len(metrics), f"{met} of {len(metrics)} met"))
    for key, sweep in report.get("sweep", {}).items():
        ranges = sweep.get("interference_ranges_deg")
        detail = (f"minimum {_quantity(sweep.get('minimum_mm'), 'mm')}, target > "
                  f"{_quantity(sweep.get('target_mm'), 'mm', trim=True)}"
                  + (f", interference over {_degrees_ranges(ranges)}" if ranges else ""))
        checks.append((f"sweep: {_sweep_name(key, sweep)}",
                       bool(sweep.get("passed")) and not ranges, detail))
    train = report.get("gear_train")
    if train is not None:
        failures = train.get("failures", [])
        checks.append(("gears cut", not failures,
                       f"{len(failures)} could not be cut" if failures else
                       _plural(len(train.get("gears", [])), "gear") + " cut"))
        if train.get("meshes"):
            bad = [m["stage"] for m in train["meshes"] if m["interference_poses"]]
            detail = ", ".join(bad) or _plural(len(train["meshes"]), "mesh", "meshes") + " checked"
            checks.append(("gear meshes free of interference", not bad, detail))
    if "cam" in report:
        cam = report["cam"]
        ok = bool(cam.get("cuttable", True)) and not cam.get("problems")
        detail = "cuttable" if ok else _plural(len(cam.get("problems", [])), "problem")
        checks.append(("cam", ok, detail))
    if "solids" in report:
        rows = report["solids"].get("enclosure", [])
        ok = all(r.get("gears_enclosed", True) and r.get("axial_fit", True) for r in rows)
        checks.append(("housings enclose their gears", ok, _plural(len(rows), "housing")))
    if "stages" in report:
        bad = [f"{s['stage']} {s.get('status')}" for s in report["stages"]
               if s.get("status", "ok") != "ok"]
        checks.append(("stages ran", not bad, ", ".join(bad) or
                       _plural(len(report["stages"]), "stage") + " ok"))
    if "failures" in report:
        failures = report["failures"]
        checks.append(("report verdict", bool(report.get("passed", not failures)),
                       "no failures" if not failures else
                       _plural(len(failures), "failure") + " listed below"))
    return checks


def _failure_list(failures, shown: int = 3) -> str:
    """The report's own reasons for not passing: the first few, the rest folded away."""
    if not failures:
        return ""
    items = [f"<li>{_badge('fail')} {_e(text)}</li>" for text in failures]
    rest = items[shown:]
    more = (f"<details><summary>{len(rest)} more</summary>"
            f'<ul class="issues">{"".join(rest)}</ul></details>' if rest else "")
    return (f"<h3>Why it does not pass ({len(failures)})</h3>"
            f'<ul class="issues">{"".join(items[:shown])}</ul>{more}')


#: How the report's ``preset.knobs[*].from`` reads on the page.
_KNOB_SOURCES = {"file": "the parameter file", "preset": "preset {name}"}


def _preset_html(preset) -> str:
    """The accuracy preset: its name over a table of knob, value and where the value came
    from (the file, or the preset); any other value (an older report's name) as text."""
    if not isinstance(preset, dict):
        return _e(preset)
    name = str(preset.get("name", "?"))
    knobs = preset.get("knobs") or {}
    if not isinstance(knobs, dict) or not knobs:
        return _e(name)
    rows, classes = [], []
    for knob, entry in knobs.items():
        entry = entry if isinstance(entry, dict) else {"value": entry}
        source = str(entry.get("from", "?"))
        rows.append([f"<code>{_e(knob)}</code>", _value_html(entry.get("value")),
                     _e(_KNOB_SOURCES.get(source, source).format(name=name))])
        classes.append("from-" + re.sub(r"[^a-z0-9]+", "-", source.lower()).strip("-"))
    from_file = sum(1 for entry in knobs.values()
                    if isinstance(entry, dict) and entry.get("from") == "file")
    summary = (f"{_e(name)} ({_plural(len(knobs), 'knob')}: {from_file} from the parameter "
               f"file, {len(knobs) - from_file} from the preset)")
    return (f'<div class="preset">{summary}</div>'
            + _table(["knob", "value", "from"], rows, numeric=(1,), row_classes=classes))


def _header(report: dict) -> str:
    checks = overall_checks(report)
    passed = all(ok for _, ok, _ in checks)
    failed = sum(1 for _, ok, _ in checks if not ok)
    state = "pass" if passed else "fail"
    detail = (f"all {len(checks)} checks met" if passed
              else f"{failed} of {len(checks)} checks failed")
    warned = len(report.get("warnings") or [])
    if warned:   # checks of stages this build did not run, listed below the checks
        detail += f"; {warned} warning{'s' * (warned > 1)} (stages not run)"
    verdict = f'<span class="badge verdict {state}">{state.upper()}</span>{_e(detail)}'
    facts = {"mechanism": f"{report.get('mechanism', '?')} mechanism"}
    if "scene" in report:
        scene = report["scene"]
        effects = ", ".join(scene.get("effects", [])) or "none"
        facts["scene"] = f"{scene.get('case', '?')} (effects: {effects})"
        for effect, reason in scene.get("set_aside", {}).items():
            facts[f"not run: {effect}"] = reason
    facts["versions"] = ", ".join(f"{k} {v}" for k, v in report.get("versions", {}).items())
    cells = {key: _e(value) for key, value in facts.items()}
    if "preset" in report:
        cells = {"mechanism": cells.pop("mechanism"), "preset": _preset_html(report["preset"]),
                 **cells}
    rows = "".join(f"<tr><td>{_e(k)}</td><td>{v}</td></tr>" for k, v in cells.items())
    rows += (f'<tr><td>input SHA-256</td><td class="hash">'
             f'{_e(report.get("input_sha256", "—"))}</td></tr>')
    check_rows = [[_e(name), _pass_badge(ok), _e(detail)] for name, ok, detail in checks]
    return (f"<header><h1>{_e(report.get('design', 'design'))}</h1>"
            f'<p class="sub">{_e(facts["mechanism"])} design report</p>'
            f"<p>{verdict}</p>"
            + _row(_table(["check", "result", "detail"], check_rows,
                          row_classes=["" if ok else "fail" for _, ok, _ in checks]),
                   f'<table class="kv"><tbody>{rows}</tbody></table>')
            + _failure_list(report.get("failures"))
            + _warning_list(report.get("warnings")) + "</header>")


def _warning_list(warnings) -> str:
    """Checks of stages this build did not run: shown, not counted against the verdict."""
    if not warnings:
        return ""
    items = [{**w, "path": f"{w.get('path', '')} (stage {w.get('stage', '?')}, not run in this "
                           "build)"} for w in warnings]
    return ("<h3>Warnings: checks of stages this build did not run</h3>"
            + _problem_list(items, state="warn"))


# ----------------------------------------------------------------------------------------------
# mechanism sections


def _metrics_section(report: dict) -> str:
    metrics = report.get("metrics", [])
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
    return _section("metrics", "Design metrics against targets", body)


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
        parts.append("<h3>Derived geometry</h3>" + _key_values(report["derived"]))
    if not parts:
        return ""
    return _section("motion", "Planting motion and derived geometry", "".join(parts))


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
                     _e(_degrees_ranges(r.get("slow_windows_deg"))),
                     _e(_quantity(r["slow_window_total_deg"], "deg", 1)),
                     _e(_quantity(r["projected_height_mm"], "mm", 1)),
                     _e(_quantity(r["width_mm"], "mm", 1)),
                     _badge("fail") + " yes" if root else "no"])
        classes.append("fail" if root else "")
    note = (f"carrier at {_number(field.get('carrier_speed_rpm'), trim=True)} r/min, forward "
            f"speed {_number(field.get('forward_speed_mm_s'), trim=True)} mm/s, depth "
            f"{_number(field.get('depth_mm'), trim=True)} mm; {field.get('angles', '')}")
    note = f'<p class="note">{_e(note)}</p>'
    body = [note, _table(["inclination", "needle entry", "needle exit", "hole mouth", "in soil",
                          "slow windows", "slow total", "height", "width", "needle root in soil"],
                         rows, numeric=(0, 1, 2, 3, 4, 6, 7, 8), row_classes=classes)]
    findings = report.get("findings", [])
    # Newer reports count findings among their failures; older ones only warn.
    state = "fail" if "failures" in report else "warn"
    body.append(f"<h3>Findings ({len(findings)})</h3>"
                + (_problem_list(findings, state) or '<p class="note">none</p>'))
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
    return _section("sweep", "Interference and clearance sweep", body)


def _gears_section(report: dict) -> str:
    train = report.get("gear_train")
    if train is None:
        return ""
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
    body = [_table(["gear", "stage", "teeth", "module (mm)", "cutter", "convex", "undercut teeth",
                    "pointed teeth", "min root thickness (mm)", "min tip thickness (mm)",
                    "problems"], rows, numeric=(2, 3, 6, 7, 8, 9))
            if rows else '<p class="note">no gears were cut</p>']
    body.append(_problem_list(problems, "warn"))
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
    failures = train.get("failures", [])
    if failures:
        body.append(f"<h3>Gears not cut ({len(failures)})</h3>" + _problem_list(failures))
    return _section("gears", "Gears", "".join(body))


def _cam_section(report: dict) -> str:
    cam = report.get("cam")
    if cam is None:
        return ""
    state = "pass" if cam.get("cuttable", True) and not cam.get("problems") else "fail"
    shown = {k: v for k, v in cam.items() if k != "problems"}
    verdict = "the roller can follow the contour" if state == "pass" else "cam problems below"
    body = (f"<p>{_badge(state)} {verdict}</p>"
            + _key_values(shown) + _problem_list(cam.get("problems", [])))
    return _section("cam", "Duckbill cam", body)


def _solids_section(report: dict) -> str:
    solids = report.get("solids")
    if solids is None:
        return ""
    rows = [[_e(p["part"]), _e(p["kind"]), _e(str(p["instances"])),
             _e(_number(p["volume_mm3"], 0)), _e(_number(p["mass_kg"])),
             _e(_point(p["centre_of_mass_mm"], 2)), _e(str(p.get("triangles", "—"))),
             _pass_badge(p.get("watertight", True))]
            for p in solids.get("parts", [])]
    assembly = solids.get("assembly", {})
    body = [f'<p>total mass {_e(_quantity(solids.get("total_mass_kg"), "kg"))} at density '
            f'{_e(_number(solids.get("density_kg_m3"), trim=True))} kg/m³; assembly '
            f'<code>{_e(assembly.get("file", "—"))}</code> at carrier angle '
            f'{_e(_number(assembly.get("carrier_angle_deg"), trim=True))} deg</p>',
            _table(["part", "kind", "instances", "volume (mm³)", "mass each (kg)",
                    "centre of mass (mm)", "triangles", "watertight"], rows,
                   numeric=(2, 3, 4, 6))]
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
    if solids.get("frames"):
        body.append(f'<p class="note">{_e(solids["frames"])}</p>')
    return _section("solids", "Solids", "".join(body))


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
    return _section("stages", "Stages", _table(headers, rows, numeric=(1,), row_classes=classes))


def _accuracy_section(report: dict) -> str:
    if not report.get("accuracy"):
        return ""
    # More digits than elsewhere: here the point is how far apart value and bound are.
    return _section("accuracy", "Accuracy achieved", _key_values(report["accuracy"], digits=9))


def _parameters_section(report: dict) -> str:
    if not report.get("parameters"):
        return ""
    return _section("parameters", "Input parameters",
                    f"<details><summary>show the validated parameters</summary>"
                    f"{_key_values(report['parameters'])}</details>")


# ----------------------------------------------------------------------------------------------
# figures


def _natural_key(text: str):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", text)]


def figure_caption(name: str) -> str:
    """A caption from a figure's file name: ``"gears-3-train-1-sun-to-idler-1.png"`` ->
    ``"Gear pair 3: train 1 sun to idler 1"``, ``"tip_velocity.png"`` -> ``"Tip velocity"``."""
    stem = Path(name).stem
    match = re.fullmatch(r"gears-(\d+)-(.+)", stem)
    if match:
        return f"Gear pair {match[1]}: {match[2].replace('-', ' ')}"
    words = re.sub(r"[-_]+", " ", stem).strip()
    return words[:1].upper() + words[1:] if words else name


def _figure_order(name: str) -> tuple:
    """Sort key: the figure's group, then the first of the group's words it holds, then name."""
    stem = Path(name).stem.lower()
    for index, (_, words) in enumerate(_FIGURE_GROUPS):
        matches = [k for k, word in enumerate(words) if word in stem]
        if matches:
            return index, matches[0], _natural_key(name)
    return len(_FIGURE_GROUPS), 0, _natural_key(name)


def _png_size(data: bytes) -> tuple[int, int] | None:
    # Width and height are the first two fields of the IHDR chunk right after the signature.
    if len(data) >= 24 and data[12:16] == b"IHDR":
        return struct.unpack(">II", data[16:24])
    return None


def _figure_html(name: str, data: bytes) -> str:
    caption = figure_caption(name)
    size = _png_size(data)
    dims = f' width="{size[0]}" height="{size[1]}"' if size else ""
    encoded = base64.b64encode(data).decode("ascii")
    return (f'<figure><img src="data:image/png;base64,{encoded}" alt="{_e(caption)}"{dims}>'
            f"<figcaption>{_e(caption)} <code>{_e(name)}</code></figcaption></figure>")


def _figures_section(figures: dict) -> str:
    if not figures:
        return ""
    groups: dict[int, list[str]] = {}
    for name in sorted(figures, key=_figure_order):
        groups.setdefault(_figure_order(name)[0], []).append(name)
    parts = []
    for index in sorted(groups):
        title = _FIGURE_GROUPS[index][0] if index < len(_FIGURE_GROUPS) else "Other figures"
        items = "".join(_figure_html(name, figures[name]) for name in groups[index])
        parts.append(f'<h3>{_e(title)}</h3><div class="gallery">{items}</div>')
    return _section("figures", "Figures", "".join(parts))


# ----------------------------------------------------------------------------------------------
# page


def render_html(report: dict, figures: dict[str, bytes] | None = None) -> str:
    """The report and its figures as one self-contained HTML page.

    Parameters
    ----------
    report : dict
        A design's report (the content of ``report.json``), of either mechanism kind.
        Optional sections (``gear_train``, ``cam``, ``solids``, ``sweep``, ``stages``,
        ``scene``, ``preset``) are shown when present.
    figures : dict of str to bytes, optional
        PNG files by file name (``"attitude.png"``); embedded as ``data:`` URIs and
        grouped by what they show.

    Returns
    -------
    str
        The page: inline CSS, no scripts, no external references; the same input
        gives the same string.

    Raises
    ------
    ValueError
        If a figure is not PNG data.
    """
    if not isinstance(report, dict):
        raise TypeError(f"report must be a dict, not {type(report).__name__}")
    figures = dict(figures or {})
    for name, data in figures.items():
        if not isinstance(data, (bytes, bytearray)) or not bytes(data).startswith(_PNG_SIGNATURE):
            raise ValueError(f"figure {name!r} is not PNG data")
        figures[name] = bytes(data)
    # The verdict's evidence first (targets, then the clearance sweep), then the details.
    if report.get("mechanism") == "pricking":
        mechanism = [_pricking_section(report), _sweep_section(report)]
    else:
        mechanism = [_metrics_section(report), _sweep_section(report),
                     _planting_motion_section(report)]
    sections = [*mechanism, _gears_section(report), _cam_section(report),
                _solids_section(report), _figures_section(figures), _stages_section(report),
                _accuracy_section(report), _parameters_section(report)]
    sections = [s for s in sections if s]
    titles = re.findall(r'<section id="([^"]+)"><h2>([^<]+)</h2>', "".join(sections))
    nav = "<nav>" + "".join(f'<a href="#{a}">{t}</a>' for a, t in titles) + "</nav>"
    title = _e(f"{report.get('design', 'design')}: cadgen report")
    return ("<!DOCTYPE html>\n"
            f'<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{title}</title><style>{_CSS}</style></head>\n"
            f"<body><main>{_header(report)}{nav}\n" + "\n".join(sections)
            + "\n</main></body></html>\n")


def write_html(report: dict, figures: dict[str, bytes] | None,
               path: str | os.PathLike) -> Path:
    """Render the page (:func:`render_html`) and write it to ``path`` atomically.

    Returns
    -------
    Path
        The written file; its directory must exist.
    """
    from cadgen.export.atomic import write_text_atomic

    return write_text_atomic(path, render_html(report, figures))


def load_figures(directory: str | os.PathLike) -> dict[str, bytes]:
    """Every ``*.png`` in ``directory`` (e.g. ``outputs/<design>/plots``), by file name.

    A missing directory gives no figures.
    """
    directory = Path(directory)
    if not directory.is_dir():
        return {}
    return {p.name: p.read_bytes() for p in sorted(directory.glob("*.png"))}
