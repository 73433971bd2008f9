"""The studio's answers as JSON: a design's evaluation (``POST /api/evaluate``), its
parameter problems (422) and the opened file (``GET /api/design``).

The page computes nothing: every curve it draws comes from here, sampled from the
same kinematic models the metrics and the report use. The sections that the report
also holds (planting ``metrics``, ``events``, ``derived``; the pricking sections) are
made by the report's own functions, so the studio and ``report.json`` can never
disagree. Arrays are columnar (``{"x": [...], "y": [...]}``), lengths in mm, angles
in degrees, rounded to 0.01 (a hundredth of a mm is far below a pixel and keeps the
answer small); a value that is not finite becomes ``null`` (strict JSON).

Everything here is vectorised numpy over the sample grids; nothing already in the
evaluation (events, holes, housing circles) is recomputed.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np

__all__ = ["ANGLE_SAMPLES", "MAX_PROBLEMS", "jsonable", "planting_payload", "pricking_payload",
           "evaluation_payload", "evaluate_request", "problems_answer", "problem_dict",
           "design_answer"]

#: The most problems an error answer lists (the count says how many there were).
MAX_PROBLEMS = 200

#: Samples of the carrier angle over one turn for the paths and the series (0.5 deg apart,
#: both ends included so the plotted curves close).
ANGLE_SAMPLES = 721
#: Decimals of every sampled coordinate in the answer (mm, deg, mm/s).
DECIMALS = 2


def _column(values, decimals: int = DECIMALS) -> list:
    """A 1-D array as a JSON list rounded to ``decimals``, ``None`` where not finite."""
    values = np.round(np.asarray(values, dtype=float).ravel(), decimals)
    finite = np.isfinite(values)
    if finite.all():
        return values.tolist()
    return [v if ok else None for v, ok in zip(values.tolist(), finite.tolist())]


def _point(xy, decimals: int = DECIMALS) -> list:
    return _column(np.asarray(xy, dtype=float).reshape(2), decimals)


def _finite_or_none(value):
    return float(value) if value is not None and math.isfinite(value) else None


def jsonable(value):
    """``value`` with numpy scalars and arrays made plain and non-finite floats ``None``.

    The report's sections hold numpy scalars, tuples and the odd NaN (a metric a bench
    run cannot measure); Python's json would write NaN, which is not JSON.
    """
    if isinstance(value, dict):
        return {str(k) if not isinstance(k, str) else k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _spacing_key(spacing: float) -> str:
    return f"{float(spacing):g}"


# --------------------------------------------------------------------------- planting
def _relative(mechanism, evaluation, phi, tip_arm1, soil) -> dict:
    """Tip paths of both arms, both arms' points and gearbox-2 circles at the catching pose."""
    events = evaluation.events
    paths, arms, circles = [], [], []
    catching = np.array([0.0])
    for arm in (0, 1):
        tip = tip_arm1 if arm == 0 else mechanism.positions(phi, arm=1, points=("N",))["N"]
        paths.append({"arm": arm + 1, "x": _column(tip[:, 0]), "y": _column(tip[:, 1])})
        pose = mechanism.positions(catching, arm=arm, points=("C", "E", "P1", "N"))
        points = {"O": [0.0, 0.0], **{name: _point(xy[0]) for name, xy in pose.items()}}
        arms.append({"arm": arm + 1, "points": points})
        for circle in evaluation.housing_circles:
            if circle.gearbox != "gearbox2":
                continue   # gearbox 1 turns about O with both arms: the report draws only gearbox 2
            centre = mechanism.positions(catching, arm=arm, points=(circle.point,))[circle.point][0]
            circles.append({"name": f"{circle.gearbox} at {circle.point}", "arm": arm + 1,
                            "x": round(float(centre[0]), DECIMALS),
                            "y": round(float(centre[1]), DECIMALS),
                            "r": round(float(circle.radius), DECIMALS)})
    angles = np.array([0.0, events.entry, events.lowest, events.exit])
    marks = mechanism.motion(angles, "N").position
    return {"paths": paths, "arms": arms, "circles": circles, "soil": soil,
            "events": [{"name": name, "x": round(float(x), DECIMALS),
                        "y": round(float(y), DECIMALS)}
                       for name, (x, y) in zip(("catching", "entry", "lowest", "exit"), marks)]}


def _absolute(mechanism, evaluation, phi, tip, soil) -> dict:
    """Tip paths over the ground at each plant spacing: ``X = x + (S / pi) phi`` (one turn)."""
    events = evaluation.events
    marks_phi = np.array([events.entry, events.exit, events.lowest])
    marks = mechanism.motion(marks_phi, "N").position
    spacings = []
    for hole in evaluation.holes:
        drift = hole.spacing / np.pi
        shifted = marks[:, 0] + drift * marks_phi
        spacings.append({
            "spacing": hole.spacing, "x": _column(tip[:, 0] + drift * phi), "y": _column(tip[:, 1]),
            **{name: _point([shifted[k], marks[k, 1]])
               for k, name in enumerate(("entry", "exit", "lowest"))}})
    return {"soil": soil, "spacings": spacings}


def _series(mechanism, evaluation, phi, velocity) -> dict:
    """Attitude and tip speeds against the carrier angle, and the events' angles."""
    omega = 2 * np.pi * evaluation.carrier_speed_rpm / 60.0
    events = evaluation.events
    relative = velocity * omega
    absolute = {_spacing_key(hole.spacing):
                _column(np.hypot(relative[:, 0] + hole.spacing / np.pi * omega, relative[:, 1]))
                for hole in evaluation.holes}
    events_deg = {"catching": 0.0, "entry": math.degrees(events.entry),
                  "lowest": math.degrees(events.lowest), "exit": math.degrees(events.exit)}
    return {"angle_deg": _column(np.degrees(phi)),
            "attitude_deg": _column(np.degrees(mechanism.attitude(phi))),
            "speed_relative_mm_s": _column(np.hypot(relative[:, 0], relative[:, 1])),
            "speed_absolute_mm_s": absolute,
            "events_deg": {k: round(v, DECIMALS) for k, v in events_deg.items()},
            "attitude_events_deg": {k: _finite_or_none(v)
                                    for k, v in evaluation.attitudes_deg.items()}}


def planting_payload(params, mechanism, evaluation) -> dict:
    """The planting answer's kind-specific sections (see the module docstring and the contract).

    Parameters
    ----------
    params : PlantingParameters
        With the scene's accuracy preset applied (as a build applies it).
    mechanism : kinematics.planting.PlantingMechanism
    evaluation : kinematics.evaluation.PlantingEvaluation
    """
    from cadgen.report.content import report_dict
    from cadgen.studio.animation import studio_planting_animation

    case = params.scene.case
    sections = report_dict(params, mechanism, evaluation, case)
    soil_level = evaluation.events.soil_level
    soil = (round(float(soil_level), DECIMALS)
            if case == "field" and soil_level is not None and math.isfinite(soil_level) else None)
    phi = np.linspace(0.0, 2 * np.pi, ANGLE_SAMPLES)
    tip_motion = mechanism.motion(phi, "N", 0)
    return {
        "metrics": jsonable(sections["metrics"]),
        "events": jsonable(sections.get("events")),
        "derived": jsonable(sections.get("derived")),
        "relative": _relative(mechanism, evaluation, phi, tip_motion.position, soil),
        "absolute": _absolute(mechanism, evaluation, phi, tip_motion.position, soil),
        "series": _series(mechanism, evaluation, phi, tip_motion.velocity),
        "animation": studio_planting_animation(params, mechanism, evaluation,
                                               with_soil=case == "field"),
    }


# --------------------------------------------------------------------------- pricking
def _concave_ranges(gear, motion) -> list:
    """Index ranges ``[i0, i1]`` (inclusive) of the gear's table samples in concave stretches.

    The stretches are given in carrier progress (deg from the outer dead centre); the
    table's samples are mapped to the same progress as the report's pitch-curve plot maps
    them, with the plot's half-degree margin.
    """
    progress = np.degrees(motion.sense * (np.asarray(gear.table["carrier_angle"], dtype=float)
                                          - motion.phi1_start))
    mask = np.zeros(progress.shape, dtype=bool)
    for stretch in gear.concave_stretches:
        low, high = sorted(stretch["carrier_deg"])
        mask |= (progress >= low - 0.5) & (progress <= high + 0.5)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return [[int(start), int(stop) - 1] for start, stop in zip(edges[::2], edges[1::2])]


def _pitch_curves(design) -> list:
    out = []
    for gear in design.gears:
        radius = np.asarray(gear.table["radius"], dtype=float)
        angle = np.asarray(gear.table["body_angle"], dtype=float)
        out.append({"name": gear.name, "stage": gear.stage, "role": gear.role,
                    "convex": bool(gear.convex),
                    "x": _column(radius * np.cos(angle)), "y": _column(radius * np.sin(angle)),
                    "concave": _concave_ranges(gear, design.motion)})
    return out


def _field_paths(design, field, params, samples: int = ANGLE_SAMPLES) -> list:
    """Absolute tip paths over two loops per inclination, in the hole's vertical plane.

    As the report's field plot draws them: ``X`` the absolute travel, ``Y = y cos(theta)``,
    the surface line likewise projected.
    """
    from kinematics.pricking_field import _FieldModel

    model = _FieldModel(design, params.field.carrier_speed_rpm, params.field.forward_speed)
    v = np.linspace(0.0, 2 * design.motion.period, samples)
    x = _column(model.absolute_x(v))
    y = model.tip(v)[:, 1]
    out = []
    for result in field:
        c = math.cos(math.radians(result.inclination_deg))
        out.append({"inclination_deg": result.inclination_deg,
                    "entry_angle_deg": _finite_or_none(result.entry_angle_deg),
                    "exit_angle_deg": _finite_or_none(result.exit_angle_deg),
                    "tip": {"x": x, "y": _column(y * c)},
                    "surface": round(float(result.surface_level) * c, DECIMALS)})
    return out


def pricking_payload(params, design, field) -> dict:
    """The pricking answer's kind-specific sections.

    Parameters
    ----------
    params : PrickingParameters
    design : kinematics.pricking.PrickingDesign
    field : list of kinematics.pricking_field.InclinationResult
    """
    from cadgen.report.animation import pricking_animation
    from cadgen.report.pricking import pricking_report

    curve = design.curve
    loop = curve(np.linspace(0.0, curve.period, ANGLE_SAMPLES))
    return {
        "metrics": [],
        "report": jsonable(pricking_report(params, design, field)),
        "loop": {"x": _column(loop[:, 0]), "y": _column(loop[:, 1])},
        "points": [[float(x), float(y)] for x, y in params.trajectory.points],
        "centre": [float(v) for v in design.linkage.centre],
        "pitch_curves": _pitch_curves(design),
        "field": _field_paths(design, field, params),
        # one animation per inclination: the needle's motion is the same, the soil line is not
        "animation": [pricking_animation(design, [result]) for result in field],
    }


def evaluation_payload(params) -> dict:
    """Evaluate validated ``params`` (scene preset applied) and return the kind's sections.

    Raises what the evaluation raises (``DesignError`` for a design the field motion
    cannot place, say); the server turns it into a 422 answer.
    """
    import cadgen
    from cadgen.design import build_mechanism, pricking_field

    if params.mechanism == "pricking":
        design = cadgen.evaluate(params)
        return pricking_payload(params, design, pricking_field(params, design))
    mechanism = build_mechanism(params)
    return planting_payload(params, mechanism, cadgen.evaluate(params, mechanism))


# --------------------------------------------------------------------------- the answer
def problem_dict(problem) -> dict:
    return {"path": problem.path, "code": problem.code, "message": problem.message,
            "stage": problem.stage}


def problems_answer(problems, error: str | None = None) -> dict:
    """The 422 answer of parameters that do not validate (at most :data:`MAX_PROBLEMS`)."""
    problems = list(problems)
    count = len(problems)
    shown = [problem_dict(p) for p in problems[:MAX_PROBLEMS]]
    if error is None:
        first = problems[0] if problems else None
        error = (f"{count} problem{'s' * (count != 1)} in the parameters"
                 + (f"; first: {first.path or '<file>'}: {first.message}" if first else ""))
    answer = {"ok": False, "error": error, "field": shown[0]["path"] if shown else "params",
              "problems": shown}
    if count > MAX_PROBLEMS:
        answer["problems_omitted"] = count - MAX_PROBLEMS
    return answer


def _margins(params, metrics: list) -> list:
    """How far each metric passes its target (its unit; negative: fails by that much).

    The one definition of a margin, :mod:`kinematics.margins` (the screen and the
    optimiser use it too), from the file's targets. Normalised by the bound's size
    (None where the bound is 0).
    """
    from kinematics.evaluation import Targets
    from kinematics.margins import bounds_of, margins

    targets = Targets(**params.targets.model_dump())
    out = []
    for metric in metrics:
        low, high = bounds_of(metric["key"], targets)
        value = metric["value"]
        margin = normalised = None
        if value is not None and (low is not None or high is not None):
            found, scale = margins(value, low, high)
            margin = float(found)
            if math.isfinite(margin) and math.isfinite(scale):
                normalised = margin / scale
        out.append({"key": metric["key"], "spacing_mm": metric.get("spacing_mm"),
                    "margin": margin, "margin_normalised": normalised})
    return out


#: The finest resolution an evaluation of the page runs at (the "fine" preset's): the paper's
#: design evaluates in about 0.4 s at 36,000 steps per revolution and kernel-b's inverse design
#: in about 0.2 s at 2,880 samples, where 1,000,000 steps took 10 s. A file asking for more
#: is evaluated at these, says so, and gets its own when it is built.
LIVE_RESOLUTION_CAPS = {"resolution.steps_per_revolution": 36_000,
                        "resolution.inverse_grid": 2_880}


def live_resolution(data):
    """``(data, warnings)``: the parameters sent (a TOML-like dict) with each resolution knob
    at most its live cap (:data:`LIVE_RESOLUTION_CAPS`), and a warning for each lowered. A
    value that is not a whole number is left for validation to name."""
    import copy

    warnings, out = [], data
    for path, cap in LIVE_RESOLUTION_CAPS.items():
        table_name, key = path.split(".")
        table = data.get(table_name) if isinstance(data, dict) else None
        value = table.get(key) if isinstance(table, dict) else None
        if not (isinstance(value, int) and not isinstance(value, bool) and value > cap):
            continue
        if out is data:
            out = copy.deepcopy(data)
        out[table_name][key] = cap
        warnings.append({"path": path, "code": "capped_for_live_evaluation", "stage": None,
                         "message": f"{key} = {value:,} is evaluated here at {cap:,} (the fine "
                                    f"preset's), so that the page answers in well under a "
                                    f"second; cadgen build uses {value:,}"})
    return out, warnings


def evaluate_request(params_data: dict) -> tuple[int, dict]:
    """``(status, answer)`` of ``POST /api/evaluate`` for the parameters sent."""
    from cadgen import MechanismError, stage_problems, validate_data
    from cadgen.params.scene import apply_preset

    start = time.perf_counter()
    # capped before validation: its design checks run at the file's resolution too
    params_data, capped = live_resolution(params_data)
    try:
        params = validate_data(params_data)
        warnings = [problem_dict(p) for p in stage_problems(params)]
        # the build applies the scene's accuracy preset to the knobs the file leaves out: so do we
        params, _ = apply_preset(params, params.scene.preset)
        warnings += capped
        sections = evaluation_payload(params)
    except RecursionError:
        return 422, problems_answer([], "the parameters are nested too deeply to validate")
    except MechanismError as exc:
        # ParameterError and DesignError list their problems; a check that could not finish
        # (a ConvergenceError) is still a verdict on these parameters, as `cadgen validate` says
        problems = getattr(exc, "problems", None)
        if problems:
            return 422, problems_answer(problems)
        from kinematics.errors import Problem

        return 422, problems_answer([Problem("", type(exc).__name__.lower(),
                                             " ".join(str(exc).split()))])
    answer = {"ok": True, "kind": params.mechanism, "elapsed_ms": 0.0, "problems": [],
              "warnings": warnings, **sections}
    if params.mechanism == "planting":
        answer["margins"] = _margins(params, answer["metrics"])
    answer["elapsed_ms"] = round((time.perf_counter() - start) * 1e3, 2)
    return 200, answer


# --------------------------------------------------------------------------- the design file
def _bundled_design() -> tuple[str, str]:
    """The bundled paper design's (text, file name)."""
    import importlib.resources

    from cadgen.params.templates import TEMPLATES

    name = TEMPLATES["planting"]
    return (importlib.resources.files("cadgen.params") / "examples" / name).read_text(
        encoding="utf-8"), name


def _toml_json(value):
    """tomllib's values as JSON (a date or time, which no parameter takes, as its text)."""
    if isinstance(value, dict):
        return {k: _toml_json(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_toml_json(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None   # TOML's nan/inf: the validator would refuse them; JSON cannot carry them
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    return str(value)


def design_answer(path, folder) -> dict:
    """``GET /api/design``: the opened file's tables as tomllib gives them (``path`` None:
    the bundled paper design, read-only); ``folder`` is where "save as" writes."""
    from cadgen.params.loading import parse_toml

    if path is None:
        text, file_name = _bundled_design()
        writable = False
    else:
        text = path.read_text(encoding="utf-8").removeprefix("\ufeff")
        file_name = path.name
        writable = os.access(path, os.W_OK)
    params = parse_toml(text, file_name)
    name = params.get("name") if isinstance(params.get("name"), str) else Path(file_name).stem
    return {"path": None if path is None else str(path), "name": name,
            "kind": params.get("mechanism"), "params": _toml_json(params),
            "writable": writable, "folder": str(folder)}
