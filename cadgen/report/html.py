"""A design's report as one self-contained HTML page: tables and plots for a person.

The page embeds every figure as a ``data:`` URI and carries its own CSS and scripts, so
it opens anywhere (an e-mail attachment, an offline laptop) and references nothing
outside itself: no scripts, fonts, style sheets or images to fetch. It is a pure
function of the report and the figures (no dates, no dictionary-order surprises
in the figure gallery), so the same design gives the same bytes.

Sections that a report lacks are left out, so reports of either mechanism kind,
and reports with or without gears, cam, solids, sweep or stage statuses, render.
Each section folds by its heading (``<details>``); reference sections (bill of
materials, stages, accuracy, parameters) start folded unless they hold a failure.
A table of contents beside the page (a bar over it on a narrow window) links every
section; a small inline script (``toc.js``) marks the section in view, opens a folded
section its link leads to and folds or unfolds them all. Without scripts the page reads
the same: plain links, native folding. Numbers follow one precision rule
(:mod:`cadgen.report.html_tables`); report.json keeps every digit.

This module assembles the page: its verdict (the checks, the header), the figure
gallery, the contents and the skeleton. The sections live in
:mod:`cadgen.report.html_sections` and :mod:`cadgen.report.html_machine`, the table and
number helpers in :mod:`cadgen.report.html_tables`, and the skeleton, style sheet and
contents script are package data beside this module (``page.html``, ``report.css``,
``toc.js``).
"""

from __future__ import annotations

import base64
import functools
import importlib.resources
import os
import re
import string
import struct
from pathlib import Path

from cadgen.report.gear_verdict import gear_verdict
from cadgen.report.html_sections import (_accuracy_section, _cam_section, _gears_section,
                                         _metrics_section, _parameters_section,
                                         _planting_motion_section, _pricking_section,
                                         _solids_section, _stages_section, _sweep_name,
                                         _sweep_section)
from cadgen.report.html_machine import bom_section_html as _bom_section_html
from cadgen.report.html_machine import machine_checks
from cadgen.report.html_machine import machine_section_html as _machine_section_html
from cadgen.report.html_tables import (FAILING_MARKS, _badge, _degrees_ranges, _e, _number,
                                       _pass_badge, _plural, _problem_list, _prose, _quantity,
                                       _row, _section, _table, _value_html)

__all__ = ["render_html", "write_html", "load_figures", "figure_caption", "overall_checks"]

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# Figure gallery groups, in page order: (heading, words that put a file in the group).
_FIGURE_GROUPS = (
    ("Motion: paths, attitude, velocity", ("path", "attitude", "velocity", "loop", "field")),
    ("Gears", ("pitch", "ratio", "gear")),
    ("Cam", ("cam",)),
    ("Solids and assembly", ("assembly", "solid", "part", "housing")),
    ("Clearance and interference sweep", ("clearance", "sweep", "interference", "distance")),
)


@functools.cache
def _page_resources() -> tuple[string.Template, str, str]:
    """The page skeleton (``page.html``, ``$name`` placeholders), its style sheet
    (``report.css``) and the contents' script (``toc.js``), package data next to this module."""
    folder = importlib.resources.files("cadgen.report")
    return (string.Template(folder.joinpath("page.html").read_text(encoding="utf-8")),
            folder.joinpath("report.css").read_text(encoding="utf-8"),
            folder.joinpath("toc.js").read_text(encoding="utf-8"))


# ----------------------------------------------------------------------------------------------
# verdict


def overall_checks(report: dict) -> list[tuple[str, bool, str]]:
    """Every pass/fail check the page's verdict rests on: ``(name, passed, detail)``.

    The design passes when all of them pass: its metric targets (planting) or
    forward check and pitch-curve findings (pricking), each clearance sweep (target
    met, no interference), every gear cut, checked and meshing free, the cam
    cuttable, every housing enclosing its gears, every stage ok. Every failing row
    names its own cause: a failure of the report (``"failures"``) that no row covers
    gets a row of its own, named by it. Undercut follows one policy for both
    mechanisms: a tooth whose remaining root thickness is at least the limit is a
    warning, one below it fails its gear's row; the pricking kinematic undercut
    finding is a prediction (a warning), the cut teeth decide.
    """
    from cadgen.report.content import FAILING_GEAR_PROBLEMS, PREDICTED_FINDINGS

    checks, covered = [], []
    if report.get("mechanism") == "pricking":
        check = report.get("verification", {})
        checks.append(("forward kinematic check", bool(report.get("verified")),
                       f"tip loop reproduced to {_number(check.get('forward_deviation_mm'))} mm"))
        findings = report.get("findings", [])
        # a failing finding is a row of its own; an undercut prediction is a warning (the
        # cut teeth decide), listed with the warnings
        for f in findings:
            if f["code"] not in PREDICTED_FINDINGS:
                gear = f.get("path", "").removeprefix("gears.").replace("_", " ")
                checks.append((f"pitch-curve findings: {gear or 'design'} "
                               f"{f['code'].replace('_', ' ')}", False, f["message"]))
                covered.append(f"[{f['code']}] {f['message']}")
    elif "metrics" in report:
        metrics = report["metrics"]
        met = sum(1 for m in metrics if m["passed"])
        checks.append(("metric targets", met == len(metrics), f"{met} of {len(metrics)} met"))
        covered += [f for f in report.get("failures", [])
                    if any(f.startswith(m["label"]) for m in metrics if not m["passed"])]
    for key, sweep in report.get("sweep", {}).items():
        ranges = sweep.get("interference_ranges_deg")
        detail = (f"minimum {_quantity(sweep.get('minimum_mm'), 'mm')}, target > "
                  f"{_quantity(sweep.get('target_mm'), 'mm', trim=True)}"
                  + (f", interference over {_degrees_ranges(ranges)}" if ranges else ""))
        checks.append((f"sweep: {_sweep_name(key, sweep)}",
                       bool(sweep.get("passed")) and not ranges, detail))
        covered.append(f"{sweep.get('label', '')}:")
    train = report.get("gear_train")
    if train is not None:
        failures = train.get("failures", [])
        verdict = gear_verdict(report)   # the gears section and the terminal say the same
        checks.append(("gears cut", verdict.passed and not failures, verdict.statement()))
        covered += [f"[{f['code']}]" for f in failures]
        gears = train.get("gears", [])
        bad = False
        for gear in gears:
            for problem in gear.get("problems", []):
                fails = (problem["severity"] == "failure" if "severity" in problem
                         else problem["code"] in FAILING_GEAR_PROBLEMS)
                if fails:
                    bad = True
                    cause = ("undercut below the root-thickness limit"
                             if problem["code"] == "undercut_root_too_thin"
                             else problem["code"].replace("_", " "))
                    checks.append((f"gear checks: {gear['gear']} {cause}", False,
                                   problem["message"]))
        if gears and not bad:
            warned = sum(1 for g in gears for p in g.get("problems", []))
            undercut = sum(1 for g in gears if g.get("undercut_teeth"))
            limit = next((g["root_thickness_limit_mm"] for g in gears
                          if g.get("root_thickness_limit_mm")), None)
            detail = (_plural(len(gears), "gear") + " checked"
                      + (f"; {_plural(undercut, 'gear')} undercut within the root-thickness "
                         f"limit ({_plural(warned, 'warning')})" if undercut else
                         f"; {_plural(warned, 'warning')}" if warned else ""))
            if limit and undercut:
                detail += f"; limit {_number(limit)} mm at the first module"
            checks.append(("gear checks", True, detail))
        covered.append("gear checks:")
        if train.get("meshes"):
            bad = [m["stage"] for m in train["meshes"] if m["interference_poses"]]
            detail = ", ".join(bad) or _plural(len(train["meshes"]), "mesh", "meshes") + " checked"
            checks.append(("gear meshes free of interference", not bad, detail))
            covered.append("mesh ")
    if "cam" in report:
        cam = report["cam"]
        ok = bool(cam.get("cuttable", True)) and not cam.get("problems")
        detail = "cuttable" if ok else _plural(len(cam.get("problems", [])), "problem")
        checks.append(("cam", ok, detail))
        covered += [f"[{p['code']}]" for p in cam.get("problems", [])]
    checks += machine_checks(report)
    covered += ["machine: ", "gear hub "]
    if "solids" in report:
        rows = report["solids"].get("enclosure", [])
        ok = all(r.get("gears_enclosed", True) and r.get("axial_fit", True) for r in rows)
        checks.append(("housings enclose their gears", ok, _plural(len(rows), "housing")))
        covered += [f"{r['housing']} does not enclose" for r in rows]
        overlaps = report["solids"].get("overlaps")
        if overlaps:
            bad = overlaps.get("failures", [])
            checks.append(("no parts overlap", not bad,
                           "; ".join(bad) if bad else
                           f"{overlaps['pairs_examined']} touching pairs checked at "
                           f"{_number(overlaps['carrier_angle_deg'], trim=True)} deg: only "
                           "their fits' chord-error shells and screw threads"))
            covered.append("parts overlap at the assembly pose")
    if "stages" in report:
        bad = [f"{s['stage']} {s.get('status')}" for s in report["stages"]
               if s.get("status", "ok") != "ok"]
        checks.append(("stages ran", not bad, ", ".join(bad) or
                       _plural(len(report["stages"]), "stage") + " ok"))
        covered.append("stage ")
    # a failure no row above covers (a report from elsewhere, a new kind): its own row
    for failure in report.get("failures") or []:
        if not any(failure.startswith(prefix) for prefix in covered if prefix):
            name = failure if len(failure) <= 80 else failure[:79].rstrip() + "…"
            checks.append((name, False, failure))
    return checks


def _failure_list(failures, shown: int = 3) -> str:
    """The report's own reasons for not passing: the first few, the rest folded away."""
    if not failures:
        return ""
    items = [f"<li>{_badge('fail')} {_e(_prose(text))}</li>" for text in failures]
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
    from cadgen.report.content import check_warnings

    checks = overall_checks(report)
    passed = all(ok for _, ok, _ in checks) and report.get("passed", True)
    failed = sum(1 for _, ok, _ in checks if not ok)
    state = "pass" if passed else "fail"
    # the verdict as the terminal summary words it ("PASS, 2 warnings"), then the checks
    held = report.get("check_warnings")
    held = check_warnings(report) if held is None else held
    stage_warned = len(report.get("warnings") or [])
    warned = stage_warned + len(held)
    failures = report.get("failures") or []
    words = [f"{len(failures)} failure{'s' * (len(failures) != 1)}"] if failures and not passed \
        else []
    if warned:
        words.append(f"{warned} warning{'s' * (warned != 1)}"
                     + (" (stages not run)" if not held else
                        f" ({stage_warned} of stages not run)" if stage_warned else ""))
    detail = "; ".join(([", ".join(words)] if words else [])
                       + [f"all {len(checks)} checks met" if passed
                          else f"{failed} of {len(checks)} checks failed"])
    verdict = (f'<span title="{_e(state.upper())}{_e(", " + ", ".join(words) if words else "")}"'
               f' class="badge verdict {state}">{state.upper()}</span>{_e(detail)}')
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
    check_rows = [[_e(_prose(name)), _pass_badge(ok), _e(_prose(detail))]
                  for name, ok, detail in checks]
    return (f'<header><h1 id="verdict">{_e(report.get("design", "design"))}</h1>'
            f'<p class="sub">{_e(facts["mechanism"])} design report</p>'
            f"<p>{verdict}</p>"
            + _row(_table(["check", "result", "detail"], check_rows,
                          row_classes=["" if ok else "fail" for _, ok, _ in checks]),
                   f'<table class="kv"><tbody>{rows}</tbody></table>')
            + _failure_list(report.get("failures"))
            + (f"<h3>Warnings: checks that hold with a warning ({len(held)})</h3>"
               + _problem_list(held, state="warn") if held else "")
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
# figures


def _natural_key(text: str):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", text)]


#: Captions of the figures a build draws, by file stem (others are made from the name).
_CAPTIONS = {
    "relative_path": "Relative tip path, both arms at the catching pose",
    "absolute_paths": "Absolute tip paths per plant spacing",
    "attitude": "Planter attitude over a carrier turn",
    "tip_velocity": "Tip speed, relative and absolute",
    "pitch_curves": "Pitch curves",
    "cam-follower": "Cam follower: roller lift, lever angle, blade opening and mouth",
    "cam-contour": "Cam contour",
    "assembly": "Assembly (front view)",
    "clearance": "Clearances of the solids (FCL sweep)",
    "loop": "Needle-tip loop and linkage",
    "ratio": "Transmission ratios",
    "field_paths": "Field paths per inclination",
    "dynamics-torque": "Dynamics: input torque and power over a carrier turn",
    "dynamics-meshes": "Dynamics: gear mesh normal forces",
    "dynamics-bearings": "Dynamics: bearing loads",
    "dynamics-shaking": "Dynamics: shaking force on the frame (polar)",
}


def _gear_pair_words(slug: str) -> str:
    """A gear pair's name back from its file-name slug: ``"1-1-pair-d-to-e"`` -> ``"1:1 pair D to
    E"``, ``"train-1-sun-to-idler-1"`` -> ``"train 1: sun to idler 1"``, ``"non-circular-pair"``
    stays hyphenated."""
    text = re.sub(r"^(\d+)-(\d+)-pair\b", r"\1:\2 pair", slug)
    text = re.sub(r"\btrain-(\d+)-set-(i+)-", lambda m: f"train {m[1]} set {m[2].upper()}: ",
                  text)
    text = re.sub(r"\btrain-(\d+)-(?=[a-z])", r"train \1: ", text)
    text = text.replace("non-circular", "non\0circular")   # a hyphen the next line keeps
    text = text.replace("-", " ").replace("\0", "-")
    # single letters are the mechanism's points (gear D, planet gear E)
    return re.sub(r"\b([a-z])\b", lambda m: m[1].upper(), text)


def figure_caption(name: str) -> str:
    """A readable caption from a figure's file name.

    ``"gears-2-1-1-pair-d-to-e.png"`` -> ``"Gear pair 2: 1:1 pair D to E"``,
    ``"gears-3-train-1-sun-to-idler-1.png"`` -> ``"Gear pair 3: train 1: sun to idler 1"``,
    ``"tip_velocity.png"`` -> ``"Tip speed, relative and absolute"`` (the figures a build draws
    have captions of their own), ``"housing-gearbox1.png"`` -> ``"Housing gearbox1: plan and
    section through the bearing seats"``, ``"mystery_plot.png"`` -> ``"Mystery plot"``.
    """
    stem = Path(name).stem
    match = re.fullmatch(r"gears-(\d+)-(.+)", stem)
    if match:
        return f"Gear pair {match[1]}: {_gear_pair_words(match[2])}"
    if stem in _CAPTIONS:
        return _CAPTIONS[stem]
    match = re.fullmatch(r"housing-(.+)", stem)
    if match:
        return f"Housing {match[1]}: plan and section through the bearing seats"
    words = re.sub(r"[-_]+", " ", stem).strip()
    return words[:1].upper() + words[1:] if words else name


def _figure_order(name: str) -> tuple:
    """Sort key: the figure's group, then the first of the group's words it holds, then name.

    A group whose word begins the name wins (``housing-gearbox1`` is a housing's picture,
    not a gear's); otherwise the first group with a word anywhere in it."""
    stem = Path(name).stem.lower()
    for index, (_, words) in enumerate(_FIGURE_GROUPS):
        starts = [k for k, word in enumerate(words) if stem.startswith(word)]
        if starts:
            return index, starts[0], _natural_key(name)
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
    return _section("figures", "Figures", "".join(parts), gist=_plural(len(figures), "figure"))


# ----------------------------------------------------------------------------------------------
# page


def render_html(report: dict, figures: dict[str, bytes] | None = None, *,
                animation: dict | None = None, assembly_glb: bytes | None = None,
                assembly_view: bytes | None = None) -> str:
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
    animation, assembly_glb : optional
        The mechanism's poses (:func:`cadgen.report.animation.animation_data`) and
        ``solids/assembly.glb``: an animation and a 3D view (of a lighter copy of the
        GLB, :mod:`cadgen.report.view_glb`), each with its inline script
        (:mod:`cadgen.report.viewer`).
    assembly_view : bytes, optional
        The lighter copy of ``assembly_glb``, made already (a build keeps it in its cache).

    Returns
    -------
    str
        The page: inline CSS, the contents' script (and those of the animation and
        the 3D view when given), no external references; the same input gives the
        same string.

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
    from cadgen.report.viewer import interactive_sections

    sections = [*mechanism, *interactive_sections(animation, assembly_glb, assembly_view),
                _gears_section(report), _cam_section(report),
                _machine_section_html(report), _solids_section(report), _bom_section_html(report),
                _figures_section(figures), _stages_section(report),
                _accuracy_section(report), _parameters_section(report)]
    sections = [s for s in sections if s]
    header = _header(report)
    title = _e(f"{report.get('design', 'design')}: cadgen report")
    page, css, script = _page_resources()
    return page.substitute(title=title, css=css, header=header,
                           nav=_contents(report, header, sections), sections="\n".join(sections),
                           script=script)


#: A section's heading as :func:`cadgen.report.html_tables._section` writes it.
_HEADING = re.compile(r'<section id="([^"]+)"><details class="fold"[^>]*><summary><h2>([^<]+)</h2>')
def _contents(report: dict, header: str, sections: list[str]) -> str:
    """The table of contents: a link per section (the verdict first), a mark on those that
    hold a failing row, and the fold controls (shown by the page's script; without it every
    section still folds by its own heading)."""
    entries = [("verdict", "Verdict and checks", any(f in header for f in FAILING_MARKS))]
    for html_text in sections:
        match = _HEADING.match(html_text)
        if match:
            entries.append((match[1], match[2], any(f in html_text for f in FAILING_MARKS)))
    items = "".join(
        f'<li><a href="#{anchor}"' + (' class="has-fail" title="holds a failing check"'
                                      if failing else "") + f">{text}</a></li>"
        for anchor, text, failing in entries)
    name = _e(report.get("design", "design"))
    return (f'<nav class="toc" aria-label="Contents"><p class="toc-title">'
            f'<a href="#verdict">{name}</a></p><ol>{items}</ol>'
            '<p class="toc-fold" hidden><button type="button" data-fold="open">Expand all'
            '</button><button type="button" data-fold="close">Collapse all</button></p></nav>')


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
