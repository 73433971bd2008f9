"""One design, in the calling process: validate, build, summarise (:func:`run_design`)."""

from __future__ import annotations

import importlib
import numbers
import os
import re
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from kinematics.errors import DesignError, MechanismError

from cadgen.batch.grid import DesignJob

__all__ = ["DEFAULT_BUILD", "run_design"]

DEFAULT_BUILD = "cadgen.pipeline.build:build"
"""The build each design runs unless told otherwise: ``"module:function"``, called as
``build(params, output_root=Path, **build_kwargs)``; it returns an object with
``report`` (dict) and ``output_dir`` (and optionally ``files``), or the report dict."""

_TRACEBACK_LINES = 30

Build = Callable[..., Any] | str


def _resolve_build(build: Build | None) -> Callable[..., Any]:
    build = DEFAULT_BUILD if build is None else build
    if callable(build):
        return build
    module, _, name = str(build).partition(":")
    if not module or not name:
        raise ValueError(f"build must be a callable or 'module:function', not {build!r}")
    return getattr(importlib.import_module(module), name)


def _is_default_build(build: Build | None) -> bool:
    """Whether ``build`` is :data:`DEFAULT_BUILD`, by name or as the function itself."""
    return build is None or build == DEFAULT_BUILD or build is _resolve_build(DEFAULT_BUILD)


def _snake(name: str) -> str:
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def _number(value: Any) -> float | int | None:
    """A plain Python number (numpy scalars would print as ``np.float64(...)``)."""
    if value is None:
        return None
    return int(value) if isinstance(value, numbers.Integral) else float(value)


def _flag(value: Any) -> bool | None:
    return None if value is None else bool(value)


#: Metrics two methods measure (the kinematic estimate of the metrics stage, the FCL sweep of
#: the solids): a summary's id names the method, as the report's label does.
MEASURED_BY_METHOD = ("arm_distance", "ground_clearance")


def _with_method(key: str, label: str) -> str:
    """``key (method)`` from a label ending in its method: ``arm distance (solids, FCL)``."""
    import re

    method = re.search(r"\(([^()]*)\)\s*$", label or "")
    return f"{key} ({method.group(1)})" if method else key


def _report_metrics(report: Mapping) -> dict:
    """``{metric id: {value, unit, target, passed}}`` of a report, in report order.

    Planting: the report's metrics, ``key@<spacing>mm`` for per-spacing ones. Pricking
    (no targets, so ``passed`` is None): the forward-check deviation, the number of
    findings, and per inclination the hole mouth, time in soil and projected height.
    """
    metrics = {}
    for m in report.get("metrics", ()):
        spacing = m.get("spacing_mm")
        key = m["key"] if spacing is None else f"{m['key']}@{float(spacing):g}mm"
        if m["key"] in MEASURED_BY_METHOD:   # what was measured is in the id: the centre
            key = _with_method(key, m["label"])   # lines' estimate or the solids' sweep
            if m.get("kinematic_estimate") is not None:
                metrics[_with_method(m["key"], m.get("kinematic_label", ""))] = {
                    "value": _number(m["kinematic_estimate"]), "unit": m.get("unit", ""),
                    "target": m.get("target"), "passed": None}
        metrics[key] = {"value": _number(m.get("value")), "unit": m.get("unit", ""),
                        "target": m.get("target"), "passed": _flag(m.get("passed"))}
    if report.get("mechanism") == "pricking":
        def add(key, value, unit):
            metrics[key] = {"value": _number(value), "unit": unit, "target": None, "passed": None}

        add("forward_deviation", report.get("verification", {}).get("forward_deviation_mm"), "mm")
        add("findings", len(report.get("findings", ())), "")
        for row in report.get("field", {}).get("per_inclination", ()):
            at = f"@{float(row['inclination_deg']):g}deg"
            add("hole_mouth" + at, row.get("hole_mouth_mm"), "mm")
            add("time_in_soil" + at, row.get("time_in_soil_deg"), "deg")
            add("projected_height" + at, row.get("projected_height_mm"), "mm")
    return metrics


def _summary(job: DesignJob, start: float, **fields) -> dict:
    summary = {"name": job.name, "source": job.source, "values": dict(job.values), "ok": False,
               "passed": None, "metrics": {}, "notes": [], "failure": None, "files": [],
               "output_dir": None}
    summary.update(fields)
    summary["seconds"] = round(time.perf_counter() - start, 3)
    return summary


def _problem_failure(exc: DesignError) -> dict:
    problems = [{"path": p.path, "code": p.code, "message": p.message} for p in exc.problems]
    return {"code": problems[0]["code"] if problems else _snake(type(exc).__name__),
            "message": "; ".join(str(p) for p in exc.problems) or str(exc),
            "exception": type(exc).__name__, "problems": problems}


def _exception_failure(exc: BaseException, code: str | None = None) -> dict:
    import traceback

    text = "".join(traceback.format_exception(exc)).splitlines()[-_TRACEBACK_LINES:]
    return {"code": code or _snake(type(exc).__name__),
            "message": f"{type(exc).__name__}: {exc}", "exception": type(exc).__name__,
            "problems": [], "traceback": "\n".join(text)}


def run_design(job: DesignJob, output_root: str | os.PathLike, build: Build | None = None,
               build_kwargs: Mapping | None = None) -> dict:
    """Validate and build one design; never raises for a bad design.

    Parameters
    ----------
    job : DesignJob
    output_root : str or path-like
        The build writes ``<output_root>/<name>/``.
    build : callable or str, optional
        ``build(params, output_root=Path, **build_kwargs)``, or ``"module:function"``;
        :data:`DEFAULT_BUILD` when omitted.
    build_kwargs : mapping, optional
        Extra keyword arguments of the build (``plots=False``...).

    Returns
    -------
    dict
        ``name``, ``source``, ``values`` (grid values), ``ok`` (built), ``passed``
        (targets met: bool, or None without targets or a build), ``metrics``
        (``{id: {value, unit, target, passed}}``), ``notes`` (the report's
        ``failures`` sentences, when it has them: why a built design did not pass),
        ``failure`` (None, or ``code``, ``message``, ``exception``, ``problems`` as
        ``{path, code, message}`` dicts, and ``traceback`` for an unexpected
        exception; see :func:`~cadgen.batch.isolated.run_design_isolated` for the
        failures of a design's process), ``files`` (written, relative to
        ``output_dir``), ``seconds`` and ``output_dir`` (str or None).
    """
    start = time.perf_counter()
    try:
        from cadgen.params import load_params, validate_data

        if job.path is not None:
            params = load_params(job.path)
        else:
            params = validate_data(job.data, job.source)
        if job.blocked_by:
            return _summary(job, start, failure={
                "code": "duplicate_name", "message": job.blocked_by,
                "exception": None, "problems": []})
        result = _resolve_build(build)(params, output_root=Path(output_root),
                                       **dict(build_kwargs or {}))
    except DesignError as exc:  # ParameterError too
        return _summary(job, start, failure=_problem_failure(exc))
    except MechanismError as exc:  # e.g. ConvergenceError: a verdict on the design
        return _summary(job, start, failure=_exception_failure(exc))
    except Exception as exc:  # a bug or an engine error: still only this design fails
        return _summary(job, start, failure=_exception_failure(exc, "exception"))
    report = result if isinstance(result, Mapping) else getattr(result, "report", {}) or {}
    output_dir = None if isinstance(result, Mapping) else getattr(result, "output_dir", None)
    files = [] if isinstance(result, Mapping) else list(getattr(result, "files", None) or [])
    notes = [str(note) for note in report.get("failures", ()) or ()]
    return _summary(job, start, ok=True, passed=_flag(report.get("passed")),
                    metrics=_report_metrics(report), notes=notes, files=[str(f) for f in files],
                    failure=_stage_failure(report),
                    output_dir=None if output_dir is None else str(output_dir))


def _stage_failure(report: Mapping) -> dict | None:
    """A built design whose stages did not all run (``"stage_failed"``), as a failure: the
    stages and their problems (a teeth stage's ``fractional_teeth`` names the key to set)."""
    failed = [r for r in report.get("stages", ()) if r.get("status", "ok") not in ("ok", "skipped")]
    if not failed:
        return None
    problems = [dict(p) for r in failed for p in r.get("problems", ())]
    return {"code": "stage_failed",
            "message": "; ".join(f"stage {r['stage']} {r['status']}: {r.get('message', '')}"
                                 for r in failed),
            "exception": None, "problems": problems,
            "stages": [r["stage"] for r in failed]}
