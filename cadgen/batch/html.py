"""The batch summary as one self-contained HTML page (``batch-summary.html``).

A table per kind of design (the designs sharing one set of metrics: planting and
pricking designs side by side would make one table too wide to read), each built
design's name a link to its ``report.html``, numbers rounded for reading (the CSV keeps
them exact), the reason a design failed or did not pass on a full-width row under it,
and, for a grid, a small plot of every metric against every varied key with its target
drawn and the failed designs marked. matplotlib is imported only for a grid's plots.
"""

from __future__ import annotations

import base64
import html
import io
import math
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from urllib.parse import quote

from kinematics.errors import Problem

__all__ = ["summary_html", "format_number", "parse_target"]

_HTML_STYLE = """
body { font-family: system-ui, sans-serif; margin: 1em; color: #222; max-width: 1400px; }
table { border-collapse: collapse; font-size: 0.8em; margin-bottom: 1.5em; }
th { background: #f3f3f3; font-weight: 600; font-size: 0.95em; }
td.name { white-space: nowrap; }
td.name small { display: block; white-space: normal; overflow-wrap: anywhere;
  color: #666; max-width: 12em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.35em; vertical-align: top; }
th small { font-weight: normal; color: #555; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
.ok { color: #176117; } .failed, .miss { color: #a40000; font-weight: bold; }
tr.reason td { border-top: none; color: #444; font-size: 0.95em; white-space: pre-wrap;
  overflow-wrap: anywhere; padding-left: 1.5em; }
tr.reason.failed td { color: #a40000; font-weight: normal; background: #fff6f6; }
tr.design.has-reason td { border-bottom: none; }
.plots { display: grid; grid-template-columns: repeat(auto-fill, minmax(300px, 1fr));
  gap: 0.8em; }
.plots figure { margin: 0; } .plots img { width: 100%; height: auto; }
.plots figcaption { font-size: 0.8em; color: #444; }
"""

#: Decimals shown at most (the CSV keeps every value exact).
MAX_DECIMALS = 3
#: Significant digits shown (more only for the digits before the point).
SIGNIFICANT = 3

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_BOUND = re.compile(rf"^\s*(<=?|>=?|=|≤|≥)\s*({_NUMBER})\s*$")
_RANGE = re.compile(rf"^\s*({_NUMBER})\s*(?:-|–|\.\.|to)\s*({_NUMBER})\s*$")


def format_number(value) -> str:
    """``value`` for reading: ``SIGNIFICANT`` significant digits, at most ``MAX_DECIMALS``
    decimals, integers as integers, values too small for that in
    exponent form (692.087 -> ``692``, 2.7330 -> ``2.73``,
    0.07342 -> ``0.073``, 185.0 -> ``185``, 2.1e-05 -> ``2.1e-05``); anything else as
    ``str``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return "" if value is None else str(value)
    if isinstance(value, int) or (math.isfinite(value) and float(value).is_integer()):
        return str(int(value))
    if not math.isfinite(value):
        return str(value)
    if value and abs(value) < 0.5 * 10.0 ** -MAX_DECIMALS:  # would read as 0: keep its size
        return f"{value:.1e}"
    magnitude = math.floor(math.log10(abs(value))) if value else 0
    decimals = min(MAX_DECIMALS, max(0, SIGNIFICANT - 1 - magnitude))
    text = f"{value:.{decimals}f}"
    return "0" if float(text) == 0 else text


def parse_target(target) -> tuple[float | None, float | None] | None:
    """A report's target text as ``(low, high)`` (either None: unbounded): ``"0-20"``,
    ``"> 10"``, ``"< 10"``, ``"= 1"``; None when it reads as neither."""
    if not isinstance(target, str):
        return None
    bound = _BOUND.match(target)
    if bound:
        op, number = bound[1], float(bound[2])
        return ((number, number) if op == "=" else
                (number, None) if op in (">", ">=", "≥") else (None, number))
    pair = _RANGE.match(target)
    return (float(pair[1]), float(pair[2])) if pair else None


def _order(summary: Mapping) -> tuple:
    """The CSV's order: by name, then source; a file given twice: the built one first."""
    failure = summary["failure"] or {}
    return summary["name"], summary["source"], not summary["ok"], failure.get("code", "")


def _reason(summary: Mapping) -> str:
    """Why a design failed (every problem), or why a built one did not pass."""
    failure = summary["failure"]
    if failure:
        if failure.get("problems"):
            return "\n".join(str(Problem(**p)) for p in failure["problems"])
        return f"{failure['message']} [{failure['code']}]"
    lines = list(summary.get("notes") or ())
    missed = [k for k, m in summary["metrics"].items() if m.get("passed") is False]
    if missed:
        lines.insert(0, "missed targets: " + ", ".join(missed))
    return "\n".join(lines)


def _report_link(summary: Mapping, root) -> str | None:
    """The design's report.html relative to the summary's folder, or None (not built)."""
    if not summary["ok"] or not summary.get("output_dir"):
        return None
    files = [Path(f).as_posix() for f in summary.get("files") or ()]
    if files and "report.html" not in files:
        return None
    folder = Path(summary["output_dir"])
    relative = (Path(os.path.relpath(folder, root)) if root is not None else Path(folder.name))
    return quote((relative / "report.html").as_posix())


def _groups(ordered: Sequence[Mapping]) -> list[tuple[list[str], list[Mapping]]]:
    """Designs grouped by their metric ids (first-seen order); a design with no metrics
    (not built) joins the only group, else a group of its own."""
    groups: dict[tuple, list] = {}
    unbuilt = []
    for s in ordered:
        (groups.setdefault(tuple(s["metrics"]), []) if s["metrics"] else unbuilt).append(s)
    if len(groups) == 1:
        (key, members), = groups.items()
        return [(list(key), sorted(members + unbuilt, key=_order))]
    result = [(list(key), members) for key, members in groups.items()]
    return result + ([([], unbuilt)] if unbuilt else [])


def _header(metric: str, unit: str) -> str:
    # spaces for the underscores and a break before "@": headers wrap instead of widening
    # the columns (the CSV's headers keep the ids)
    name = html.escape(metric).replace("_", " ").replace("@", "<wbr>@")
    return name + (f" <small>({html.escape(unit)})</small>" if unit else "")


def _table(metric_ids, members, grid_keys, units, root, show_source) -> str:
    esc = html.escape
    head = (["design", "result"] + [esc(k) for k in grid_keys]
            + [_header(k, units.get(k, "")) for k in metric_ids])
    rows = []
    for s in members:
        status = "ok" if s["ok"] else "failed"
        link = _report_link(s, root)
        name = (f'<a href="{esc(link)}">{esc(s["name"])}</a>' if link else esc(s["name"]))
        if show_source:  # under the name, not a column of its own: the table stays narrow
            name += f"<small>{esc(s['source'])}</small>"
        # one column for built/failed and passed: "passed", "not passed", "built" (no
        # targets) or "failed" (not built)
        result, style = (("failed", "failed") if not s["ok"] else
                         ("built", "") if s["passed"] is None else
                         ("passed", "ok") if s["passed"] else ("not passed", "miss"))
        cells = [f'<td class="name">{name}</td>', f'<td class="{style}">{result}</td>']
        cells += [f'<td class="num">{esc(format_number(s.get("values", {}).get(k)))}</td>'
                  for k in grid_keys]
        for k in metric_ids:
            m = s["metrics"].get(k) or {"value": None}
            title = f' title="target {esc(str(m["target"]))}"' if m.get("target") else ""
            mark = " miss" if m.get("passed") is False else ""
            cells.append(f'<td class="num{mark}"{title}>{esc(format_number(m["value"]))}</td>')
        reason = _reason(s)
        rows.append(f'<tr class="design{" has-reason" if reason else ""}">' + "".join(cells)
                    + "</tr>")
        if reason:
            rows.append(f'<tr class="reason {status}"><td colspan="{len(cells)}">'
                        f"{esc(reason)}</td></tr>")
    return ("<table>\n<thead><tr>" + "".join(f"<th>{h}</th>" for h in head)
            + "</tr></thead>\n<tbody>\n" + "\n".join(rows) + "\n</tbody>\n</table>\n")


# --------------------------------------------------------------------------- grid plots


def _varied(ordered: Sequence[Mapping]) -> list[str]:
    """Grid keys with numeric values that take at least two values across the designs."""
    keys = list(dict.fromkeys(k for s in ordered for k in s.get("values", {})))
    varied = []
    for key in keys:
        values = [s["values"].get(key) for s in ordered if key in s.get("values", {})]
        if (all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)
                and len(set(values)) > 1):
            varied.append(key)
    return varied


def _plot(metric: str, unit: str, key: str, others: list[str], members) -> bytes:
    """PNG of ``metric`` against grid key ``key``: one line per combination of the other
    varied keys, the target as a band or line, missed targets hollow red circles, designs
    that did not pass for another reason orange squares, designs that were not built red
    crosses on the axis."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.transforms import blended_transform_factory

    figure, ax = plt.subplots(figsize=(3.6, 2.7), dpi=150, layout="constrained")
    series: dict[tuple, list] = {}
    for s in members:
        other = tuple(s["values"].get(k) for k in others)
        series.setdefault(other, []).append(s)
    target, labelled = None, set()
    for number, (other, designs) in enumerate(series.items()):
        colour = f"C{number % 10}"
        label = ", ".join(f"{k}={format_number(v)}" for k, v in zip(others, other)) or None
        built = sorted(((s["values"][key], s["metrics"][metric]) for s in designs
                        if s["ok"] and s["metrics"].get(metric, {}).get("value") is not None),
                       key=lambda pair: pair[0])
        if built:
            ax.plot([x for x, _ in built], [m["value"] for _, m in built], "-o", color=colour,
                    ms=4, lw=1.2, label=label)
            missed = [(x, m["value"]) for x, m in built if m.get("passed") is False]
            if missed:
                ax.plot(*zip(*missed), "o", ms=7, mfc="none", mec="#c00000", mew=1.5,
                        label=None if "missed" in labelled else "missed target")
                labelled.add("missed")
            # built, this target met, but the design did not pass (another target, a stage)
            other_reason = [(s["values"][key], s["metrics"][metric]["value"]) for s in designs
                            if s["ok"] and s["passed"] is False
                            and s["metrics"].get(metric, {}).get("passed") is not False
                            and s["metrics"].get(metric, {}).get("value") is not None]
            if other_reason:
                ax.plot(*zip(*other_reason), "s", ms=8, mfc="none", mec="#d07000", mew=1.3,
                        label=None if "other" in labelled else "did not pass")
                labelled.add("other")
            target = target or parse_target(built[0][1].get("target"))
        failed = [s["values"][key] for s in designs if not s["ok"]]
        if failed:
            on_axis = blended_transform_factory(ax.transData, ax.transAxes)
            ax.plot(failed, [0.03] * len(failed), "x", color="#c00000", ms=8, mew=2,
                    transform=on_axis, clip_on=False,
                    label=None if "failed" in labelled else "not built")
            labelled.add("failed")
    if target is not None:
        low, high = target
        band = dict(color="#2a9d2a", alpha=0.12, lw=0)
        if low is not None and high is not None and low != high:
            ax.axhspan(low, high, **band, label="target")
        else:
            for bound, other in ((low, high), (high, low)):
                if bound is not None:
                    ax.axhline(bound, color="#2a9d2a", lw=1.2, ls="--",
                               label=None if "target" in labelled else "target")
                    labelled.add("target")
    ax.set_xlabel(key, fontsize=8)
    ax.set_ylabel(f"{metric} ({unit})" if unit else metric, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.margins(x=0.08, y=0.12)
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if handles:  # below the axes, never over the data
        ax.legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.25),
                  ncol=min(3, len(handles)), frameon=False)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", metadata={"Software": None},
                   pil_kwargs={"compress_level": 6})
    plt.close(figure)
    return buffer.getvalue()


def _plots_section(metric_ids, members, varied, units) -> str:
    esc = html.escape
    figures = []
    for metric in metric_ids:
        if not any(isinstance(s["metrics"].get(metric, {}).get("value"), (int, float))
                   for s in members):
            continue
        target = next((s["metrics"][metric].get("target") for s in members
                       if s["metrics"].get(metric, {}).get("target")), None)
        for key in varied:
            data = _plot(metric, units.get(metric, ""), key, [k for k in varied if k != key],
                         members)
            encoded = base64.b64encode(data).decode("ascii")
            caption = f"{metric} against {key}" + (f"; target {target}" if target else "")
            figures.append(f'<figure class="plot"><img src="data:image/png;base64,{encoded}" '
                           f'alt="{esc(caption)}"><figcaption>{esc(caption)}</figcaption>'
                           "</figure>")
    if not figures:
        return ""
    return ("<h2>Metrics against the grid</h2>\n<p>Green: the target (a band, or a dashed "
            "bound); hollow red circles: this target missed; orange squares: a design that "
            "did not pass for another reason (see the table); red crosses on the axis: "
            "designs that were not built.</p>\n<div class=\"plots\">\n" + "\n".join(figures)
            + "\n</div>\n")


def summary_html(summaries: Sequence[Mapping], title: str = "Batch summary", *,
                 root: str | os.PathLike | None = None) -> str:
    """The batch summary as one self-contained HTML page (inline style and images).

    Parameters
    ----------
    summaries : sequence of dict
        One per design (see :func:`~cadgen.batch.single.run_design`), in any order: the
        page lists them as the CSV does.
    title : str
    root : path-like, optional
        The folder the page is written to: links to each built design's ``report.html``
        are relative to it (default: the design folder's name, the output root's layout).

    Returns
    -------
    str
        The page: the counts, a table per kind of design (grid values and metrics rounded
        by :func:`format_number`, units in the headers, missed targets marked, every
        failure and the reason a built design did not pass on a row under it), and for a
        grid one plot per metric and varied key.
    """
    esc = html.escape
    ordered = sorted(summaries, key=_order)
    grid_keys = list(dict.fromkeys(k for s in ordered for k in s.get("values", {})))
    units = {k: m.get("unit") or "" for s in reversed(ordered) for k, m in s["metrics"].items()}
    built = sum(s["ok"] for s in ordered)
    not_passed = sum(s["ok"] and s["passed"] is False for s in ordered)
    sources = list(dict.fromkeys(s["source"] for s in ordered))
    body = [f"<h1>{esc(title)}</h1>",
            f"<p>{len(ordered)} designs: {built} built, {len(ordered) - built} failed, "
            f"{not_passed} built but did not pass."
            + (f" Source: <code>{esc(sources[0])}</code>." if len(sources) == 1 else "")
            + " Each built design's name links to its report; exact values are in "
              "batch-summary.csv.</p>"]
    groups = _groups(ordered)
    varied = _varied(ordered)
    for metric_ids, members in groups:
        if len(groups) > 1:
            names = ", ".join(s["name"] for s in members[:3]) + (", ..." if len(members) > 3
                                                                 else "")
            body.append(f"<h2>{'Not built' if not metric_ids else 'Designs'}: {esc(names)}</h2>")
        keys = [k for k in grid_keys if any(k in s.get("values", {}) for s in members)]
        body.append(_table(metric_ids, members, keys, units, root, len(sources) > 1))
    if varied:
        for metric_ids, members in groups:
            members = [s for s in members if all(k in s.get("values", {}) for k in varied)]
            if metric_ids and members:
                body.append(_plots_section(metric_ids, members, varied, units))
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<title>{esc(title)}</title>\n<style>{_HTML_STYLE}</style>\n</head>\n<body>\n"
        + "\n".join(body) + "\n</body>\n</html>\n"
    )
