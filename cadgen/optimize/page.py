"""optimize.html: one self-contained page for the designer (plots inlined, nothing fetched).

What it shows: the verdict (a design meeting every target found and certified, or not, and
then the least-violating one); the chosen design against the base design, target by target,
with the screen's value, the exact value, their difference, the exact margin and pass/fail;
the free variables with their bounds and base values; every certified design (the best
candidates, or the Pareto front) with screened and exact objectives; the search itself
(method, population, evaluations, where, times); the convergence and Pareto plots; the
study file.
"""

from __future__ import annotations

import base64
import html
import math

__all__ = ["optimize_html"]

_STYLE = """
body{font:14px/1.45 system-ui,sans-serif;margin:2em auto;max-width:1100px;padding:0 1em;color:#222}
h1{font-size:1.5em;margin-bottom:.2em}
h2{font-size:1.15em;margin-top:1.8em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;margin:.6em 0;font-size:13px}
td,th{border:1px solid #ddd;padding:3px 7px}
th{background:#f4f4f4;text-align:left} td.n{text-align:right;font-variant-numeric:tabular-nums}
.pass{color:#11772d;font-weight:600} .fail{color:#b3261e;font-weight:600}
.verdict{font-size:1.1em;padding:.6em 1em;border-radius:6px;margin:1em 0}
.ok{background:#e7f5ea} .no{background:#fbe9e7} pre{background:#f7f7f7;padding:.8em;overflow:auto}
img{max-width:100%} .small{color:#666;font-size:12px} .wide{overflow-x:auto;max-width:100%}
"""


def _e(text) -> str:
    return html.escape(str(text), quote=True)


def _n(value, digits: int = 6) -> str:
    if value is None or isinstance(value, bool):
        return "" if value is None else str(value)
    try:
        value = float(value)
    except (TypeError, ValueError):
        return _e(value)
    return "" if not math.isfinite(value) else f"{value:.{digits}g}"


def _verdict(flag) -> str:
    if flag is None:
        return ""
    return '<span class="pass">pass</span>' if flag else '<span class="fail">fail</span>'


def _table(head: list, rows: list, numeric_from: int = 1) -> str:
    # a wide table (the certified front has a column per objective) scrolls in its own box,
    # never the page
    out = ['<div class="wide"><table><tr>' + "".join(f"<th>{_e(h)}</th>" for h in head)
           + "</tr>"]
    for row in rows:
        cells = []
        for k, cell in enumerate(row):
            raw = isinstance(cell, tuple)   # (html,) is already markup
            text = cell[0] if raw else _e(cell)
            cls = ' class="n"' if k >= numeric_from and not raw else ""
            cells.append(f"<td{cls}>{text}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    return "\n".join(out) + "</table></div>"


def _min_margin(design) -> float | None:
    return design.min_margin


#: The clearances the screen and the exact evaluator measure, named by method as the build's
#: report and summary name them (a build with solids measures them on the solids with FCL).
MEASURED = {"arm_distance": "arm_distance (centre lines)",
            "ground_clearance": "ground_clearance (envelope circles)"}


def _targets_table(result) -> str:
    chosen, base = result.chosen, result.base
    labels = list(result.constraint_labels)
    rows = []
    for label in labels:
        exact_margin = chosen.exact.get("margins", {}).get(label)
        screened_margin = chosen.screened.get("margins", {}).get(label)
        base_margin = base.exact.get("margins", {}).get(label) if base else None
        rows.append([MEASURED.get(label, label),
                     _n(base.exact.get("values", {}).get(label)) if base else "",
                     _n(base_margin, 4), (_verdict(None if base_margin is None
                                                   else base_margin >= 0),),
                     _n(chosen.screened.get("values", {}).get(label)),
                     _n(chosen.exact.get("values", {}).get(label)),
                     _n(_diff(chosen.exact.get("values", {}).get(label),
                              chosen.screened.get("values", {}).get(label)), 3),
                     _n(screened_margin, 4), _n(exact_margin, 4),
                     (_verdict(None if exact_margin is None else exact_margin >= 0),)])
    head = ["target", "base value (exact)", "base margin", "base", "screened value",
            "exact value", "exact - screened", "screened margin", "exact margin", "verdict"]
    return _table(head, rows)


def _diff(a, b):
    try:
        a, b = float(a), float(b)
    except (TypeError, ValueError):
        return None
    return a - b if math.isfinite(a) and math.isfinite(b) else None


def _values_table(result) -> str:
    """Every figure the exact path gives that is not a target's (objectives, pricking's)."""
    chosen, base = result.chosen, result.base
    keys = [k for k in chosen.exact.get("values", {}) if k not in result.constraint_labels]
    if not keys:
        return ""
    rows = [[k, _n(base.exact.get("values", {}).get(k)) if base else "",
             _n(chosen.screened.get("values", {}).get(k)), _n(chosen.exact["values"][k]),
             _n(_diff(chosen.exact["values"][k], chosen.screened.get("values", {}).get(k)), 3)]
            for k in keys]
    return _table(["figure", "base (exact)", "screened", "exact", "exact - screened"], rows)


def _variables_table(result) -> str:
    chosen, base = result.chosen, result.base
    rows = [[name, _n(low), _n(high), _n(base.x[k]) if base is not None else "",
             _n(chosen.x[k], 8) if chosen is not None else ""]
            for k, (name, low, high) in enumerate(zip(result.variables, result.lower,
                                                       result.upper))]
    return _table(["variable", "lower", "upper", "base design", "chosen design"], rows)


def _finals_table(result) -> str:
    head = ["#", "role", "exact verdict", "smallest exact margin",
            "build stages"] + list(result.variables)
    for key, sense in result.objectives:
        head += [f"{key} ({sense}) screened", f"{key} exact", "difference"]
    rows = []
    for number, final in enumerate(result.finals, start=1):
        refused = final.exact.get("stage_problems") or []
        row = [number, final.role, (_verdict(final.passed),), _n(_min_margin(final), 4),
               ", ".join(sorted({p.get("code", "") for p in refused})) or "ok",
               *[_n(v, 7) for v in final.x]]
        for key, _ in result.objectives:
            screened = final.screened["objectives"].get(key)
            exact = final.exact.get("objectives", {}).get(key)
            row += [_n(screened), _n(exact), _n(_diff(exact, screened), 3)]
        rows.append(row)
    return _table(head, rows)


def _image(name: str, data: bytes) -> str:
    encoded = base64.b64encode(data).decode("ascii")
    return f'<p><img alt="{_e(name)}" src="data:image/png;base64,{encoded}"></p>'


def optimize_html(result, plots: dict) -> str:
    """The page's text; ``plots`` maps file names to PNG bytes (inlined as base64)."""
    study = result.study
    chosen, base = result.chosen, result.base
    key = result.objectives[0][0]
    parts = [f"<!doctype html><html lang='en'><head><meta charset='utf-8'>"
             f"<title>cadgen optimize: {_e(study.name)}</title><style>{_STYLE}</style>"
             "</head><body>",
             f"<h1>cadgen optimize: {_e(study.name)}</h1>",
             f"<p class='small'>study {_e(study.path)}; base design {_e(study.base_path)} "
             f"({_e(study.kind)})</p>"]
    if result.found:
        base_value = base_margin = ""
        if base is not None:
            base_value = f"; base design: {_n(base.exact.get('objectives', {}).get(key))}"
            base_margin = f" (base {_n(_min_margin(base), 4)})"
        parts.append(f"<div class='verdict ok'>A design meeting every target was found and "
                     f"certified by the exact evaluator (the one <code>cadgen build</code> "
                     f"uses); it passes the build's own checks too (duckbill cam, "
                     f"drivetrain). Exact {_e(key)}: "
                     f"<b>{_n(chosen.exact['objectives'].get(key))}</b>"
                     f"{base_value}. Smallest exact margin {_n(_min_margin(chosen), 4)}"
                     f"{base_margin}.</div>")
    elif chosen is not None:
        parts.append(f"<div class='verdict no'>No design meeting every target was found in "
                     f"{result.evaluations} evaluations. The least-violating certified design "
                     f"is below (total exact violation {_n(chosen.exact_violation, 4)}); its "
                     "file is least-violating.toml.</div>")
    else:
        parts.append("<div class='verdict no'>No design could be evaluated.</div>")
    if chosen is not None:
        failures = chosen.exact.get("build_failures") or []
        if failures:
            parts.append("<p class='fail'>A build of this design fails these checks:</p><ul>"
                         + "".join(f"<li>{_e(f)}</li>" for f in failures) + "</ul>")
        for key, text in (("problems", "The exact path refused this design:"),
                          ("stage_problems", "A full build would refuse this design (a build "
                           "stage's check the screen does not model):")):
            problems = chosen.exact.get(key) or []
            if problems:
                parts.append(f"<p class='fail'>{_e(text)}</p><ul>" + "".join(
                    f"<li>{_e(p.get('path'))}: {_e(p.get('message'))} [{_e(p.get('code'))}]"
                    "</li>" for p in problems) + "</ul>")
        parts += ["<h2>The chosen design against the base design, target by target</h2>",
                  "<p class='small'>Margins are normalised by the target's bound (&gt; 0: met "
                  "with room). <i>screened</i>: the vectorised screen the search used; "
                  "<i>exact</i>: the certified evaluator of <code>cadgen build</code>.</p>",
                  _targets_table(result), _values_table(result),
                  "<h2>Free variables</h2>", _variables_table(result)]
    which = ("The feasible Pareto front, spread along it" if len(result.objectives) > 1
             else "The best screened-feasible designs, in order")
    parts += ["<h2>Certified designs</h2>",
              f"<p class='small'>{which} ({len(result.finals)} certified); the chosen design "
              "first.</p>",
              _finals_table(result),
              "<h2>The search</h2>",
              _table(["", ""], [
                  ["method", result.algorithm],
                  ["objectives", ", ".join(f"{k} ({s})" for k, s in result.objectives)],
                  ["constraints", ", ".join(result.constraint_labels)],
                  ["population", result.population],
                  ["evaluations (budget)", f"{result.evaluations} ({study.evaluations})"],
                  ["generations", result.generations],
                  ["seed", study.seed], ["evaluated on", result.where],
                  ["screen time", f"{result.seconds.get('screen', 0):.2f} s"],
                  ["certification time", f"{result.seconds.get('certify', 0):.2f} s"]],
                     numeric_from=9)]
    for name, data in plots.items():
        parts.append(f"<h2>{_e(name.removesuffix('.png').capitalize())}</h2>" + _image(name, data))
    parts += ["<h2>Study file</h2>", f"<pre>{_e(study.text)}</pre>", "</body></html>"]
    return "\n".join(parts) + "\n"
