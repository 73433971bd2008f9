"""A study's files: best.toml, pareto.csv, the plots, optimize.html and optimize.json.

Written under ``<output root>/<study name>/`` through a staged folder swapped in whole
(:func:`cadgen.export.atomic.staged_directory`, as a build writes its folder), so a failure
leaves the previous outputs as they were:

- ``best.toml``: the base file's text with the best design's values in place, every
  comment kept (the studio's saving, :func:`cadgen.studio.save.saved_text`), under a header
  naming the study, the seed and the date; checked to load to the certified parameters.
  Named ``least-violating.toml`` when no design met every target (exit 1);
- ``pareto.csv`` and ``pareto.png`` (several objectives): the certified front, screened and
  exact objectives side by side;
- ``convergence.png``: the best feasible objective and the smallest constraint violation
  against the evaluations;
- ``optimize.html`` (self-contained, :mod:`cadgen.optimize.page`) and ``optimize.json``
  (everything machine-readable).

Same study and seed: the same best.toml and pareto.csv, byte for byte (on the same day:
best.toml's header carries the date).
"""

from __future__ import annotations

import csv
import datetime
import io
import json
import math
from pathlib import Path

import numpy as np

__all__ = ["write_outputs", "write_optimize_outputs", "optimize_summary", "best_file_name",
           "best_toml_text", "pareto_csv_text",
           "result_json", "convergence_png", "pareto_png", "design_name"]

#: The chosen design's file when it meets every target, and when it does not.
BEST_FILE = "best.toml"
LEAST_VIOLATING_FILE = "least-violating.toml"


def best_file_name(result) -> str:
    return BEST_FILE if result.found else LEAST_VIOLATING_FILE


def design_name(result) -> str:
    """The chosen design's name (its build folder, beside the study's): ``<study>-best``."""
    from cadgen.params._tables import NAME_MAX_LENGTH

    suffix = "-best" if result.found else "-least-violating"
    return result.study.name[:NAME_MAX_LENGTH - len(suffix)] + suffix


def _number(value, digits: int = 6) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    return f"{value:.{digits}g}"


def _jsonable(value):
    """Plain JSON data: numpy arrays and numbers as lists and floats, NaN and inf as null."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if hasattr(value, "as_dict"):
        return _jsonable(value.as_dict())
    return value


# --------------------------------------------------------------------------- best.toml


def best_toml_text(result, *, date: datetime.date | None = None) -> str:
    """The chosen design as a complete, commented parameter file (the base file's text).

    Raises RuntimeError (a bug) if the text does not load to the certified parameters.
    """
    import tomllib

    from cadgen.params import validate_data
    from cadgen.studio.save import saved_text

    study, chosen = result.study, result.chosen
    tables = dict(result.chosen_tables)
    tables["name"] = design_name(result)
    base_text = study.base_path.read_bytes().decode("utf-8-sig")
    body = saved_text(tables, base_text)
    reloaded = validate_data(tomllib.loads(body), check_feasibility=False)
    if reloaded != validate_data(tables, check_feasibility=False):
        raise RuntimeError("best.toml does not load to the certified design (a bug in "
                           "cadgen.optimize.outputs)")
    date = date or datetime.date.today()
    verdict = ("certified by the exact evaluator: every target met" if result.found else
               "NO design met every target: this is the least-violating one found")
    bases = result.base.x if result.base else [None] * len(chosen.x)
    moved = [f"{name} {_number(base)} -> {_number(value)}"
             for name, base, value in zip(result.variables, bases, chosen.x)]
    shown = 8   # a pricking study moves two dozen coordinates: optimize.html has them all
    changes = ", ".join(moved[:shown]) + (f", and {len(moved) - shown} more (optimize.html)"
                                          if len(moved) > shown else "")
    exact = chosen.exact.get("objectives", {})
    base_exact = result.base.exact.get("objectives", {}) if result.base else {}
    objectives = "; ".join(f"{k} {_number(exact.get(k))} (base {_number(base_exact.get(k))})"
                           for k, _ in result.objectives)
    header = [f"# {best_file_name(result)} of the study {study.name!r} "
              f"({study.path.name}), written by cadgen optimize on {date.isoformat()}",
              f"# seed {study.seed}, {result.evaluations} designs screened ({result.algorithm}); "
              f"{verdict}",
              f"# exact {objectives}",
              f"# changed from {study.base_path.name}: {changes}",
              f"# (the base design's own description is in {study.base_path.name}; the comments "
              "below are its, each changed value's saying so)",
              "", ""]
    body = _true_comments(body, result, tables["name"])
    return "\n".join(header) + body


def _true_comments(body: str, result, name: str) -> str:
    """The base file's text made true for the new file: its header (which describes the
    base design and names its file) left out, the name's comment naming the new output
    folder, and each changed value's comment saying what it was."""
    import re

    lines = body.split("\n")
    while lines and (lines[0].startswith("#") or not lines[0].strip()):
        lines.pop(0)   # the base file's header: our own stands above
    body = "\n".join(lines)
    body = re.sub(r'(?m)^(name\s*=\s*"[^"]*"\s*)#.*$',
                  lambda m: f"{m.group(1)}# design name; outputs are written to "
                            f"outputs/{name}/", body, count=1)
    base = result.base.x if result.base else None
    chosen = result.chosen
    if chosen is None or base is None:
        return body
    if result.study.kind == "pricking":
        return _moved_points_comments(body, result)
    for path, old, new in zip(result.variables, base, chosen.x):
        if _number(old) == _number(new):
            continue
        table, _, key = path.rpartition(".")
        body = _comment_after(body, table, key, f"(cadgen optimize; {result.study.base_path.name}: "
                                                f"{_number(old)})")
    return body


def _comment_after(body: str, table: str, key: str, note: str) -> str:
    """``body`` with ``note`` added to the comment of ``key`` in ``[table]`` (or one made)."""
    import re

    header = re.search(rf"(?m)^\[{re.escape(table)}\][^\n]*$", body) if table else None
    start = header.end() if header else 0
    following = re.search(r"(?m)^\[", body[start:]) if header else None
    end = start + following.start() if following else len(body)
    section = body[start:end]
    line = re.search(rf"(?m)^({re.escape(key)}\s*=\s*[^#\n]*?)(\s*#[^\n]*)?$", section)
    if line is None:
        return body
    comment = (line.group(2) or "").rstrip()
    text = f"{line.group(1)}{comment} {note}" if comment else f"{line.group(1)}   # {note}"
    return body[:start] + section[:line.start()] + text + section[line.end():] + body[end:]


def _moved_points_comments(body: str, result) -> str:
    """The comment of each moved type-value point says where it was in the base file."""
    import re

    moved = {}
    for name, value in zip(result.variables, result.chosen.x - result.base.x):
        number = int(name[1:].split(".")[0])
        if abs(value) > 0:
            moved[number] = True
    base_points = result.study.base_params.trajectory.points
    block = re.search(r"(?ms)^points\s*=\s*\[[^\n]*\n(.*?)^\s*\]", body)
    if block is None:
        return body
    rows, number = [], 0
    for line in block.group(1).split("\n"):
        match = re.match(r"(\s*\[[^\]]*\],?)(.*)$", line)
        if match:
            number += 1
            if number in moved:
                x, y = base_points[number - 1]
                line = (f"{match.group(1)}   # Q{number} moved by cadgen optimize from "
                        f"({_number(x)}, {_number(y)})")
        rows.append(line)
    return body[:block.start(1)] + "\n".join(rows) + body[block.end(1):]


# --------------------------------------------------------------------------- pareto.csv


def pareto_csv_text(result) -> str:
    """One row per certified design: variables, screened and exact objectives, verdict."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    head = ["design", "role", "passed_exact", "min_margin_exact", "build_stage_refusals",
            *result.variables]
    for key, sense in result.objectives:
        head += [f"{key} ({sense}) screened", f"{key} exact", f"{key} difference"]
    writer.writerow(head)
    for number, final in enumerate(result.finals, start=1):
        refused = sorted({p.get("code", "") for p in final.exact.get("stage_problems") or ()})
        row = [number, final.role, "yes" if final.passed else "no",
               _number(final.min_margin, 8), " ".join(refused),
               *[_number(float(v), 10) for v in final.x]]
        for key, _ in result.objectives:
            screened = final.screened["objectives"].get(key)
            exact = final.exact.get("objectives", {}).get(key)
            row += [_number(screened, 8), _number(exact, 8),
                    _number(exact - screened if _finite(exact) and _finite(screened) else None,
                            4)]
        writer.writerow(row)
    return out.getvalue()


def _finite(value) -> bool:
    return isinstance(value, (int, float, np.floating)) and math.isfinite(value)


# --------------------------------------------------------------------------- plots


def _figure(nrows=1, height=4.0):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.5, height), dpi=120, layout="constrained")
    FigureCanvasAgg(figure)
    return figure, figure.subplots(nrows=nrows, sharex=True)


def _png(figure) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", metadata={"Software": None})
    return buffer.getvalue()


def convergence_png(result) -> bytes:
    """Best feasible objective (top) and smallest constraint violation (bottom) vs evaluations."""
    key, sense = result.objectives[0]
    figure, (top, bottom) = _figure(nrows=2, height=5.0)
    evaluations = np.array([c["evaluations"] for c in result.convergence], dtype=float)
    best = np.array([np.nan if c["best"] is None else c["best"] for c in result.convergence])
    violation = np.array([c["violation"] for c in result.convergence], dtype=float)
    alone = " alone" if len(result.objectives) > 1 else ""
    top.plot(evaluations, best, marker=".", color="tab:blue",
             label=f"best feasible{alone} (screen)")
    if result.best is not None and _finite(result.best.exact["objectives"].get(key)):
        top.axhline(result.best.exact["objectives"][key], color="tab:green", ls="--",
                    label="chosen design, exact")
    if result.base is not None and _finite(result.base.exact.get("objectives", {}).get(key)):
        top.axhline(result.base.exact["objectives"][key], color="tab:gray", ls=":",
                    label="base design, exact")
    top.set_ylabel(f"{key} ({'max' if sense == 'max' else 'min'})")
    top.set_title(f"{result.study.name}: {result.algorithm}, seed {result.study.seed}")
    top.legend(fontsize=8)
    top.grid(alpha=0.3)
    bottom.plot(evaluations, violation, marker=".", color="tab:red")
    bottom.set_yscale("symlog", linthresh=1e-4)
    # plain tick labels (1e-04): the default ones are mathtext powers whose superscript minus
    # makes matplotlib hunt fallback fonts, one warning line each on the user's terminal
    from matplotlib.ticker import FuncFormatter

    bottom.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:.0e}" if value
                                                   else "0"))
    finite = violation[np.isfinite(violation)]
    bottom.set_ylim(bottom=0.0, top=max(1e-3, 2.0 * float(finite.max(initial=0.0))))
    bottom.set_ylabel("smallest constraint\nviolation (sum of G > 0)")
    bottom.set_xlabel("designs evaluated")
    bottom.grid(alpha=0.3)
    return _png(figure)


def pareto_png(result, archive_F=None) -> bytes:
    """The certified front in the first two objectives: screened and exact."""
    (k1, s1), (k2, s2) = result.objectives[:2]
    figure, ax = _figure(height=4.5)
    for final in result.finals:
        sx, sy = final.screened["objectives"].get(k1), final.screened["objectives"].get(k2)
        exact = final.exact.get("objectives", {})
        ex, ey = exact.get(k1), exact.get(k2)
        if _finite(sx) and _finite(ex):
            ax.plot([sx, ex], [sy, ey], color="0.7", lw=0.8, zorder=1)
    def scatter(group, **style):
        points = np.array([[d[group].get("objectives", {}).get(k1, np.nan),
                            d[group].get("objectives", {}).get(k2, np.nan)]
                           for d in ({"s": f.screened, "e": f.exact} for f in result.finals)],
                          dtype=float).reshape(-1, 2)
        ax.scatter(points[:, 0], points[:, 1], **style)
    scatter("s", marker="o", facecolors="none", edgecolors="tab:blue", label="screened")
    scatter("e", marker="x", color="tab:red", label="exact")
    if result.best is not None:
        ax.scatter([result.best.exact["objectives"][k1]], [result.best.exact["objectives"][k2]],
                   marker="*", s=180, color="tab:green", label="best (exact)", zorder=3)
    ax.set_xlabel(f"{k1} ({s1})")
    ax.set_ylabel(f"{k2} ({s2})")
    ax.set_title(f"{result.study.name}: certified Pareto front ({len(result.finals)} designs)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return _png(figure)


# --------------------------------------------------------------------------- optimize.json


def _design_json(final) -> dict:
    if final is None:
        return None
    return {"role": final.role, "x": final.x, "passed": final.passed,
            "screened": final.screened,
            "exact": {k: v for k, v in final.exact.items()},
            "differences": final.differences()}


def result_json(result) -> dict:
    study = result.study
    free = (list(study.free) if study.kind == "planting" else study.free)
    return _jsonable({
        "study": {"file": str(study.path), "name": study.name, "base": str(study.base_path),
                  "kind": study.kind, "free": free,
                  "objectives": [{"key": k, "sense": s} for k, s in study.objectives],
                  "budget": {"evaluations": study.evaluations, "seed": study.seed}},
        "found": result.found, "exit_code": result.exit_code,
        "best_file": best_file_name(result) if result.chosen else None,
        "variables": result.variables, "lower": result.lower, "upper": result.upper,
        "objectives": [{"key": k, "sense": s} for k, s in result.objectives],
        "constraints": result.constraint_labels,
        "search": {"algorithm": result.algorithm, "population": result.population,
                   "evaluations": result.evaluations, "generations": result.generations,
                   "evaluated_on": result.where, "seconds": result.seconds,
                   "screened_pareto_front": result.front_size},
        "convergence": result.convergence,
        "best": _design_json(result.best),
        "least_violating": _design_json(result.least_violating),
        "base": _design_json(result.base),
        "finals": [_design_json(f) for f in result.finals],
    })


# --------------------------------------------------------------------------- writing


def write_outputs(result, output_root, *, date: datetime.date | None = None) -> Path:
    """Write the study's folder ``<output_root>/<name>/`` atomically; its path.

    Returns
    -------
    Path
        The folder written.
    """
    from cadgen.export.atomic import staged_directory, write_bytes_atomic, write_text_atomic
    from cadgen.optimize.page import optimize_html

    folder = Path(output_root) / result.study.name
    plots = {"convergence.png": convergence_png(result)}
    if len(result.objectives) > 1 and result.finals:
        plots["pareto.png"] = pareto_png(result)
    with staged_directory(folder) as staging:
        if result.chosen is not None:
            write_text_atomic(staging / best_file_name(result), best_toml_text(result, date=date))
        if len(result.objectives) > 1:
            write_text_atomic(staging / "pareto.csv", pareto_csv_text(result))
        for name, data in plots.items():
            write_bytes_atomic(staging / name, data)
        write_text_atomic(staging / "optimize.json",
                          json.dumps(result_json(result), indent=1, allow_nan=False) + "\n")
        write_text_atomic(staging / "optimize.html", optimize_html(result, plots))
    return folder


#: The name :mod:`cadgen` exports (``cadgen.write_optimize_outputs``).
write_optimize_outputs = write_outputs


# --------------------------------------------------------------------------- the summary


def _g(value) -> str:
    return "-" if value is None else f"{value:.6g}"


def optimize_summary(result, folder) -> str:
    """The terminal summary of a run (``cadgen optimize`` prints it): what was searched,
    the chosen design's objectives (exact, screened, the base's), its values, the verdict."""
    study, chosen, base = result.study, result.chosen, result.base
    lines = [f"study {study.name} ({study.kind}): {result.evaluations} designs screened by "
             f"{result.algorithm} in {result.generations} generations on {result.where} "
             f"({result.seconds['screen']:.1f} s), {len(result.finals)} certified exactly "
             f"({result.seconds['certify']:.1f} s)"]
    if chosen is None:
        lines.append("no design could be evaluated")
    else:
        exact = chosen.exact.get("objectives", {})
        for name, direction in result.objectives:
            line = (f"  {name} ({direction}): exact {_g(exact.get(name))}, screened "
                    f"{_g(chosen.screened['objectives'].get(name))}")
            if base is not None:
                line += f"; base design {_g(base.exact.get('objectives', {}).get(name))}"
            lines.append(line)
        shown = 12   # a pricking study moves two dozen coordinates: the page has them all
        bases = base.x if base is not None else [None] * len(chosen.x)
        lines += [f"  {name}: {_g(b)} -> {_g(v)}"
                  for name, b, v in list(zip(result.variables, bases, chosen.x))[:shown]]
        if len(result.variables) > shown:
            lines.append(f"  ... and {len(result.variables) - shown} more (optimize.html)")
    if result.found:
        lines.append(f"FOUND: a design meeting every target and passing every check of a "
                     f"build, certified ({best_file_name(result)})")
    elif chosen is not None:
        why = [f"{p['path']}: {p['message']}" for p in chosen.exact.get("stage_problems") or []]
        why += list(chosen.exact.get("build_failures") or [])
        lines.append("NOT FOUND: no design met every target and check; the least-violating "
                     f"one is in {best_file_name(result)} (total exact violation "
                     f"{_g(chosen.exact_violation)}" + (f"; a build fails it: {why[0]}"
                                                        if why else "") + ")")
    lines.append(f"wrote {folder}")
    return "\n".join(lines)
