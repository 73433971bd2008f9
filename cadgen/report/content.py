"""The build's report: parameters, metrics against targets, checks, stages, versions, hash."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import platform

import numpy as np

__all__ = ["input_hash", "report_dict", "assemble_report", "failures", "check_warnings",
           "warning_count", "verdict_text", "machine_section", "PREDICTED_FINDINGS",
           "FAILING_GEAR_PROBLEMS", "FAILING_RIM_PROBLEMS", "round_part_volume_error"]

#: Pricking findings that predict what the cutting check measures (the pitch curve bends
#: tighter than a rack cuts without undercut): a warning, never a failure by themselves; the cut
#: teeth's root thickness (gear checks, ``MIN_ROOT_THICKNESS``) decides. Where the teeth were
#: cut, the measured check stands for the prediction and the prediction is not counted again.
PREDICTED_FINDINGS = frozenset({"undercut"})
#: Gear-check codes that fail a design (read from a report written before problems carried
#: their ``severity``); ``cadgen.gears.pairs.FAILING_PROBLEMS`` is the source.
FAILING_GEAR_PROBLEMS = frozenset({"undercut_root_too_thin"})
#: Rim checks of a gear's bore that fail the design (a rim too thin, a hub set screw standing
#: proud among the mating teeth); the others (a thin rim, a gear no shaft carries) are
#: warnings (:mod:`cadgen.machine.hubs`).
FAILING_RIM_PROBLEMS = frozenset({"rim_too_thin", "set_screw_proud"})


def input_hash(params) -> str:
    """SHA-256 of the validated parameters in canonical JSON (same design, same hash)."""
    canonical = json.dumps(params.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


def _versions() -> dict:
    from importlib.metadata import version   # not ``import scipy``: a metrics-only build has
                                             # no other use for it (7 ms)

    from cadgen import __version__

    return {"cadgen": __version__, "python": platform.python_version(),
            "numpy": np.__version__, "scipy": version("scipy")}


def report_dict(params, mechanism, evaluation, case: str = "field") -> dict:
    """The planting metrics' sections: metrics against targets, events, derived geometry, accuracy.

    A bench run has no soil: the metrics that need it (holes, entry/exit attitude,
    ground clearance, absolute speeds) are left out.
    """
    closure = mechanism.closure
    ratio_1, ratio_2 = mechanism.converted_ratios
    events = evaluation.events
    per_spacing = []
    for hole in evaluation.holes:
        s = hole.spacing
        per_spacing.append({
            "spacing_mm": s, "hole_width_mm": hole.width, "hole_verticality_mm": hole.verticality,
            "hole_span_mm": hole.span, "x_entry_mm": hole.x_entry, "x_exit_mm": hole.x_exit,
            "x_lowest_mm": hole.x_lowest,
            "tip_velocity_absolute_lowest_mm_s": evaluation.speeds["absolute_lowest"][s],
            "tip_velocity_absolute_catching_mm_s": evaluation.speeds["absolute_catching"][s],
        })
    metrics = [{"key": m.key, "label": m.label, "value": m.value, "unit": m.unit,
                "target": m.target, "passed": m.passed, "verdict": m.verdict,
                "spacing_mm": m.spacing,
                **({} if m.bound is None else {"certified_bound": m.bound})}
               for m in evaluation.metrics
               if case == "field" or m.key not in FIELD_METRICS]
    return {
        "metrics": metrics,
        "per_spacing": per_spacing,
        "events": {
            "carrier_angle_deg": {"catching": 0.0, "entry": math.degrees(events.entry),
                                  "lowest": math.degrees(events.lowest),
                                  "exit": math.degrees(events.exit)},
            "attitude_deg": evaluation.attitudes_deg,
            "tip_height_mm": {"catching": events.lowest_height + evaluation.catch_to_plant_height,
                              "lowest": events.lowest_height, "highest": events.highest_height},
            "soil_level_mm": events.soil_level,
            "catch_to_plant_height_mm": evaluation.catch_to_plant_height,
            "soil_penetrations": events.penetrations,
            "tip_velocity_relative_lowest_mm_s": evaluation.speeds["relative_lowest"],
            "tip_velocity_relative_catching_mm_s": evaluation.speeds["relative_catching"],
            "carrier_speed_rpm": evaluation.carrier_speed_rpm,
        },
        "derived": {
            "centre_distance_a_mm": closure.centre_distance,
            "carrier_radii_mm": mechanism.carrier_radii,
            "path_height_of_E_mm": mechanism.path_height_of_E(),
            "pitch_radius_min_mm": closure.radius_min[1],
            "pitch_radius_max_mm": closure.radius_max[1],
            "intermediate_radius_min_mm": closure.centre_distance - closure.radius_max[1],
            "ratio_min": closure.ratio_min, "ratio_max": closure.ratio_max,
            "pitch_perimeter_mm": evaluation.perimeter,
            "module_mm": evaluation.module,
            "converted_ratios_train1": {"gearbox2_set": ratio_1, "central_gear_set": ratio_2},
            "arm_distance_at_deg": evaluation.arm_distance_at_deg,
            "ground_clearance_at_deg": evaluation.extras["ground_clearance_at_deg"],
            "ground_clearance_nearest": f"{evaluation.ground_clearance_circle.gearbox} at "
                                        f"{evaluation.ground_clearance_circle.point}",
            "housing_circles_mm": [{"gearbox": c.gearbox, "axis": c.point, "radius": c.radius}
                                   for c in evaluation.housing_circles],
            "clearance_method": evaluation.extras["clearance_method"],
        },
        "accuracy": evaluation.accuracy,
    } if case == "field" else {
        "metrics": metrics,
        "derived": {"centre_distance_a_mm": closure.centre_distance,
                    "pitch_perimeter_mm": evaluation.perimeter, "module_mm": evaluation.module,
                    "ratio_min": closure.ratio_min, "ratio_max": closure.ratio_max,
                    "arm_distance_at_deg": evaluation.arm_distance_at_deg},
        "accuracy": _without_soil(evaluation.accuracy),
    }


def _without_soil(accuracy: dict) -> dict:
    """The accuracy section of a bench run: the searches of metrics that need the soil (the
    housings' clearance over the soil surface) left out with their metrics."""
    searches = accuracy.get("minimum_searches")
    if not isinstance(searches, dict):
        return accuracy
    return {**accuracy, "minimum_searches": {key: search for key, search in searches.items()
                                             if key not in FIELD_METRICS}}


#: Metrics that need the soil: not evaluated on a bench run.
FIELD_METRICS = {"hole_width", "hole_verticality", "angle_difference", "ground_clearance",
                 "soil_penetrations"}


def _header(params, run) -> dict:
    return {"design": params.name, "mechanism": params.mechanism,
            "input_sha256": input_hash(params),
            "scene": {"case": run.case, "effects": list(run.effects)}}


def assemble_report(run, set_aside: dict) -> dict:
    """The whole report of a build from what its stages made (sections only for stages that ran)."""
    params = run.params
    report = _header(params, run)
    report["scene"]["set_aside"] = dict(set_aside)
    report["preset"] = getattr(run, "preset", {"name": "standard", "knobs": {}})
    values = run.values
    ok = {r.stage for r in run.records if r.status == "ok"}
    if params.mechanism == "pricking" and {"kinematics", "metrics"} <= ok:
        from cadgen.report.pricking import pricking_report

        report.update(pricking_report(params, values["kinematics"], values["metrics"]))
    elif params.mechanism == "planting" and "metrics" in ok:
        report.update(report_dict(params, values["kinematics"], values["metrics"], run.case))
    if "teeth" in ok:
        from cadgen.gears.trains import train_report

        train = values["teeth"]
        strength = getattr(values.get("dynamics"), "strength", None) if "dynamics" in ok \
            else None
        if strength is not None:   # the teeth under the dynamics' loads, not the assumed one
            train = dataclasses.replace(train, strength=strength)
        report["gear_train"] = train_report(train)
    if "cam" in ok:
        from cadgen.cam.design import cam_section

        report["cam"] = cam_section(values["cam"])
    if "drivetrain" in ok:
        report["machine"] = machine_section(params, values["drivetrain"],
                                            values["teeth"] if "teeth" in ok else None)
        duckbill = values["drivetrain"].fixings.get("duckbill")
        if duckbill is not None:   # the linkage's spring, roller, pins and loads
            from cadgen.machine.duckbill import duckbill_report

            report["duckbill"] = duckbill_report(duckbill)
        # the assembly model: the solids' (placed, with the bought items of their joints)
        # when they were built, else the joint graph from the drivetrain records alone
        from cadgen.assembly.machine import model_report

        model = getattr(values["parts"].assembly, "model", None) if "parts" in ok else None
        report["assembly"] = (assembly_section(params, values["drivetrain"],
                                               values["teeth"] if "teeth" in ok else None)
                              if model is None else model_report(model))
    if "parts" in ok:
        from cadgen.report.bom import bom_rows
        from cadgen.solids.outcome import solids_report

        report["solids"] = solids_report(values["parts"])
        report["bom"] = bom_rows(values["parts"], report["solids"],
                                 values["drivetrain"] if "drivetrain" in ok else None, params)
    sweeps = {key: values[key] for key in ("arm_interference", "ground_clearance") if key in ok}
    if sweeps:
        report["sweep"] = sweeps
        _replace_kinematic_estimates(report, sweeps)
    if "dynamics" in ok:
        from cadgen.dynamics import dynamics_report

        report["dynamics"] = dynamics_report(values["dynamics"], params)
    elif "dynamics" in set_aside:   # said, never a silent zero
        report["dynamics"] = {"modelled": False, "reason": set_aside["dynamics"]}
    report["warnings"] = [p.as_dict() for p in getattr(run, "warnings", [])]
    report["check_warnings"] = check_warnings(report)
    report["accuracy_achieved"] = accuracy_achieved(params, report, values, ok)
    report["stages"] = [record.as_dict() for record in run.records]
    # the gear cache's use in this build (cadgen.pipeline.gear_cache.cache_record): none
    # when the teeth did not run
    report["gear_cache"] = getattr(run, "gear_cache", None) or {
        "used": False, "directory": None, "hits": 0, "misses": 0}
    report["failures"] = failures(report)
    report["passed"] = not report["failures"]
    report["versions"] = _versions()
    report["parameters"] = params.model_dump(mode="json")
    return report


def machine_section(params, drivetrain, train=None) -> dict:
    """Shafts, bearings, keys and fits (:func:`cadgen.machine.drivetrain.drivetrain_report`),
    the process's allowances and materials, and each gear's rim under its bore."""
    from cadgen.machine.drivetrain import drivetrain_report
    from cadgen.machine.fits import design_fits

    from cadgen.machine.retention import retention_report

    section = drivetrain_report(drivetrain)
    section["load_sources"] = load_sources(drivetrain)
    section["fits"] = design_fits(params).as_dict()
    section["retention"] = retention_report(getattr(drivetrain, "retention", ()) or ())
    rims = []
    for rim in (train.rims if train is not None else ()):
        thickness = None if math.isnan(rim.thickness) else float(rim.thickness)
        rims.append({"gear": rim.gear, "rim_mm": thickness, "limit_mm": float(rim.limit),
                     "warning_limit_mm": float(rim.warning_limit), "module_mm": float(rim.module),
                     "passed": bool(rim.passed),
                     "where_mm": [list(map(float, point)) for point in rim.where],
                     "problems": [p.as_dict() for p in rim.problems]})
    section["hubs"] = rims
    return section


def load_sources(drivetrain) -> dict:
    """What the machine's sizes were chosen from and what its reported loads, torques and lives
    are (``cadgen.machine.cycle_loads``: the assumed tip force, the dynamics with estimated
    masses, or with the solids' masses), with the re-check's verdict when there was one."""
    shafts = drivetrain.shafts
    out = {"sized_from": sorted({s.sized_from for s in shafts}),
           "checked_with": sorted({s.load_source for s in shafts})}
    recheck = drivetrain.rules.get("recheck")
    if recheck is not None:
        out["recheck_passed"] = recheck["passed"]
    return out


def assembly_section(params, drivetrain, train=None) -> dict:
    """The joint graph (:mod:`cadgen.assembly.machine`) from the drivetrain records alone: parts,
    joints, mobility, loose parts (no placements: no solids were built)."""
    from cadgen.assembly.machine import model_report, planting_model, pricking_model

    meshes = [tuple(stage.generated.pair.names) for stage in (train.stages if train else ())]
    build = planting_model if params.mechanism == "planting" else pricking_model
    return model_report(build(drivetrain, meshes))


def _replace_kinematic_estimates(report: dict, sweeps: dict) -> None:
    """The solids' clearances stand for the metrics; the kinematic estimates stay beside them."""
    for metric in report.get("metrics", []):
        sweep = sweeps.get({"arm_distance": "arm_interference",
                            "ground_clearance": "ground_clearance"}.get(metric["key"], ""))
        if sweep:
            metric["kinematic_estimate"] = metric["value"]
            metric["kinematic_label"] = metric["label"]   # its method named: centre lines...
            metric["value"] = sweep["minimum_mm"]
            metric["label"] = sweep["label"]
            metric["passed"] = sweep["passed"]
            metric["verdict"] = sweep.get("verdict", "pass" if sweep["passed"] else "fail")
            metric["certified_bound"] = sweep["certified_bound_mm"]


def failures(report: dict) -> list:
    """Every reason the design does not pass, one sentence each (empty: it passes)."""
    out = []
    for metric in report.get("metrics", []):
        if not metric["passed"]:
            where = f" at {metric['spacing_mm']:g} mm" if metric.get("spacing_mm") else ""
            undecided = ("undecided: the search did not certify, true minimum in "
                         f"[{metric['certified_bound']:.6g}, {metric['value']:.6g}]; "
                         if metric.get("verdict") == "undecided" and metric.get("value") is not None
                         else "")
            value = "n/a" if metric.get("value") is None else f"{metric['value']:.3f}"
            out.append(f"{metric['label']}{where}: {value} {metric['unit']} "
                       f"({undecided}target {metric['target']} {metric['unit']})"
                       .replace("  ", " "))
    for finding in report.get("findings", []):
        if finding["code"] not in PREDICTED_FINDINGS:
            out.append(f"[{finding['code']}] {finding['message']}")
    gear_train = report.get("gear_train", {})
    for failure in gear_train.get("failures", []):
        out.append(f"[{failure['code']}] {failure['message']}")
    for gear in gear_train.get("gears", []):
        for problem in gear.get("problems", []):
            if _gear_problem_fails(problem):
                out.append(f"gear checks: {gear['gear']} [{problem['code']}] {problem['message']}")
    for mesh in gear_train.get("meshes", []):
        if mesh["interference_poses"]:
            out.append(f"mesh {mesh['stage']}: {mesh['interference_poses']} interfering poses")
    for problem in report.get("cam", {}).get("problems", []):
        out.append(f"[{problem['code']}] {problem['message']}")
    machine = report.get("machine", {})
    for problem in machine.get("problems", []):
        out.append(f"machine: [{problem['code']}] {problem['message']}")
    for problem in report.get("gear_train", {}).get("strength", {}).get("problems", []):
        out.append(f"tooth strength: [{problem['code']}] {problem['message']}")
    for rim in machine.get("hubs", []):
        for problem in rim["problems"]:
            if problem["code"] in FAILING_RIM_PROBLEMS:
                out.append(f"gear hub {rim['gear']}: [{problem['code']}] {problem['message']}")
    dynamics = report.get("dynamics", {})
    for reason in dynamics.get("outside_validity", []):
        out.append(f"dynamics: {reason}")
    if dynamics.get("modelled") and dynamics["energy_balance_max_rel"] > 1e-6:
        out.append(f"dynamics: the power balance and Newton-Euler differ by "
                   f"{dynamics['energy_balance_max_rel']:.2g} of the peak power")
    for failure in report.get("solids", {}).get("overlaps", {}).get("failures", []):
        out.append(f"parts overlap at the assembly pose: {failure}")
    for row in report.get("solids", {}).get("enclosure", []):
        if not row["gears_enclosed"]:
            out.append(f"{row['housing']} does not enclose its gears (margin "
                       f"{row['smallest_margin_mm']:.2f} mm at {row['nearest_gear']})")
    for key, sweep in report.get("sweep", {}).items():
        if sweep.get("interference_ranges_deg"):
            out.append(f"{sweep['label']}: interference over "
                       + ", ".join(f"{a:.1f}..{b:.1f} deg" for a, b in
                                   sweep["interference_ranges_deg"]))
    for record in report.get("stages", []):
        if record["status"] != "ok":
            out.append(f"stage {record['stage']} {record['status']}: {record['message']}")
    return out




def _gear_problem_fails(problem: dict) -> bool:
    if "severity" in problem:
        return problem["severity"] == "failure"
    return problem["code"] in FAILING_GEAR_PROBLEMS


def check_warnings(report: dict) -> list:
    """Checks that hold but warn, one dict each (``check``, ``path``, ``code``, ``message``).

    Every gear-check problem that does not fail the design (an undercut tooth whose root
    thickness is adequate, a pointed tooth, ...), and each pricking prediction
    (:data:`PREDICTED_FINDINGS`) for a gear whose teeth were not cut in this build.
    """
    out = []
    gear_train = report.get("gear_train", {})
    cut = {gear["gear"] for gear in gear_train.get("gears", [])}
    for gear in gear_train.get("gears", []):
        for problem in gear.get("problems", []):
            if not _gear_problem_fails(problem):
                out.append({"check": "gear checks", "path": f"gears.{gear['gear']}",
                            "code": problem["code"], "message": problem["message"]})
    for problem in gear_train.get("strength", {}).get("warnings", []):
        out.append({"check": "tooth strength", **problem})
    for rim in report.get("machine", {}).get("hubs", []):
        for problem in rim["problems"]:
            if problem["code"] not in FAILING_RIM_PROBLEMS:
                out.append({"check": "gear hubs", "path": problem.get("path", ""),
                            "code": problem["code"], "message": problem["message"]})
    for row in report.get("solids", {}).get("alignment", []):
        if not row["passed"]:
            out.append({"check": "seat alignment", "path": "manufacturing.process",
                        "code": "seats_misaligned",
                        "message": f"shaft {row['shaft']}'s seats in {row['housing']}'s base and "
                                   f"cover can tilt {row['misalignment_arcmin']:.1f}' against "
                                   f"each other ({row['span_mm']:.1f} mm apart), more than the "
                                   f"{row['allowance_arcmin']:g}' a deep-groove ball bearing "
                                   "accepts: bore both seats in one set-up, or machine the housing"})
    for finding in report.get("findings", []):
        gear = finding.get("path", "").removeprefix("gears.").replace("_", " ")
        if finding["code"] in PREDICTED_FINDINGS and gear not in cut:
            out.append({"check": "pitch-curve findings", "path": finding.get("path", ""),
                        "code": finding["code"],
                        "message": finding["message"] + " (its teeth were not cut in this build)"})
    return out


def warning_count(report: dict) -> int:
    """Warnings of a report: checks of stages not run, and checks that hold but warn."""
    return len(report.get("warnings") or []) + len(report.get("check_warnings")
                                                    or check_warnings(report))


def verdict_text(report: dict) -> str:
    """``"PASS"``, ``"PASS, 2 warnings"``, ``"FAIL, 3 failures, 1 warning"``: the verdict in
    words, the same in the terminal summary and the HTML header."""
    failed = report.get("failures") or []
    passed = report.get("passed", not failed)
    parts = ["PASS" if passed else "FAIL"]
    if not passed and failed:
        parts.append(f"{len(failed)} failure{'s' * (len(failed) != 1)}")
    warned = warning_count(report)
    if warned:
        parts.append(f"{warned} warning{'s' * (warned != 1)}")
    return ", ".join(parts)


def _searches_achieved(searches: dict) -> str:
    """What the minimum searches certified: "certified" only for those that did."""
    done = [name for name, s in searches.items() if s["certified"]]
    open_ = [name for name, s in searches.items() if not s["certified"]]
    parts = []
    if done:
        parts.append(f"certified: {', '.join(done)}")
    for name in open_:
        search = searches[name]
        why = (f"budget of {search['evaluations']} evaluations spent"
               if search.get("budget_spent") else "did not close")
        parts.append(f"NOT certified: {name} ({why}), true minimum in "
                     f"[{search['certified_bound']:.9g}, {search['value']:.9g}]")
    return "minimum searches " + "; ".join(parts)


def round_part_volume_error(segments: int) -> float:
    """The relative volume a round part loses as the inscribed polygon of ``segments`` sides:
    ``1 - sin(a) / a`` with ``a = 2 pi / segments`` (the report page rounds volumes and
    masses to it)."""
    angle = 2 * math.pi / segments
    return 1 - math.sin(angle) / angle


def accuracy_achieved(params, report: dict, values: dict, ok: set) -> list:
    """What each resolution knob of this build buys, with the basis of the figure.

    Bounds where one exists (the DXF chord tolerance, the polygon of a round part, the
    cam contour's chord sag, the sweeps' certificate); the metrics' own certificate;
    the tooth profile from the study's measured law; for a pricking design, what its
    inverse design achieves.
    """
    rows = []
    if params.mechanism == "pricking" and "kinematics" in ok:
        # what the inverse design achieves: the loop through its points, the Chebyshev fits
        # of the carrier and needle angles, and the forward check of the inverse grid
        from kinematics.pricking import FORWARD_TOLERANCE

        inverse = values["kinematics"]
        curve, motion = inverse.curve, inverse.motion
        # the curve is the design: it must pass through the type-value points it was given
        through = float(np.max(np.linalg.norm(curve(curve.knots[:-1]) - curve.points, axis=1)))
        fits = (motion.phi1, motion.phi2)
        pieces = sum(len(f.coefficients) for f in fits)
        order = fits[0].coefficients.shape[1] - 1
        # the fit stops halving a piece once its last three coefficients fall below rtol x scale
        tail = max(float(np.abs(f.coefficients[:, -3:]).max()) for f in fits)
        closure = max([inverse.grid_closure_error]
                      + [float(stage.closure_error) for stage in inverse.stages])
        grid = params.resolution.inverse_grid
        rows += [
            {"knob": "trajectory.degree", "value": curve.degree,
             "achieved": f"the tip loop passes its {len(curve.points)} type-value points within "
                         f"{through:.1e} mm, continuous to derivative {curve.degree - 1}",
             "basis": "periodic interpolating B-spline: the residual at the points, measured"},
            {"knob": "Chebyshev fits (fixed rtol 1e-13)",
             "value": f"{pieces} pieces, degree {order}",
             "achieved": f"carrier and needle angles phi1, phi2: trailing coefficients at most "
                         f"{tail:.1e} rad",
             "basis": "spectral decay of each piece's coefficients (pieces halved until below "
                      "1e-13 of the angles' scale)"},
            {"knob": "resolution.inverse_grid", "value": grid,
             "achieved": f"tip loop rebuilt from the pitch curves within "
                         f"{inverse.forward_deviation:.1e} mm of the designed loop (tolerance "
                         f"{FORWARD_TOLERANCE:g} mm); the pitch curves close to {closure:.1e} rad",
             "basis": "forward check: the pitch curves tabulated at the grid's carrier steps run "
                      "back through the linkage (spline error ~ step^4)"},
        ]
    if params.mechanism == "planting" and "metrics" in ok:
        accuracy = values["metrics"].accuracy
        error = accuracy["closure_centre_distance_error_mm"]
        rows.append({"knob": "resolution.steps_per_revolution",
                     "value": params.resolution.steps_per_revolution,
                     "achieved": f"{_searches_achieved(accuracy['minimum_searches'])}; centre "
                                 f"distance within {error:.1e} mm",
                     "basis": "certified search and the closure's own error estimate"})
    if "teeth" in ok:
        train = values["teeth"]
        modules = [stage.generated.system.module for stage in train.stages] or [0.0]
        points = params.gears.flank_points
        rows.append({"knob": "gears.flank_points", "value": points,
                     "achieved": f"tooth profile within about {0.42 * max(modules) / points**2:.1e}"
                                 " mm of the exact envelope",
                     "basis": "measured law 0.42 m / n^2 mm (docs/gears.md, against a "
                              "simulated rack cut)"})
        rows.append({"knob": "gears.chord_tolerance", "value": params.gears.chord_tolerance,
                     "achieved": f"every DXF polyline within {params.gears.chord_tolerance:g} mm "
                                 "of the dense outline",
                     "basis": "bound: the thinning keeps it"})
    if "cam" in ok:
        design = values["cam"]
        points = params.cam.profile_points
        contour = design.profile.working_profile(points)
        chord = float(np.max(np.linalg.norm(np.diff(np.vstack([contour, contour[:1]]), axis=0),
                                            axis=1)))
        radius = max(design.check.profile_radius_min, 1e-9)
        rows.append({"knob": "cam.profile_points", "value": points,
                     "achieved": f"cam contour within {chord**2 / (8 * radius):.1e} mm of the "
                                 "exact offset curve before DXF thinning",
                     "basis": "bound: chord sag s^2 / (8 rho) at the largest chord and the "
                              "smallest radius of the contour"})
    if "parts" in ok:
        n = params.solids.segments_per_circle
        rows.append({"knob": "solids.segments_per_circle", "value": n,
                     "achieved": f"round parts {round_part_volume_error(n):.1e} short in "
                                 f"volume; housings at most {1 / math.cos(math.pi / n) - 1:.1e} "
                                 "of their radius too large (they always enclose)",
                     "basis": "closed form of the inscribed and circumscribed n-gons"})
    for key, sweep in report.get("sweep", {}).items():
        rows.append({"knob": "resolution.sweep_atol", "value": params.resolution.sweep_atol,
                     "achieved": f"{sweep['label']}: "
                                 + ("" if sweep.get("certified", True) else "NOT certified, ")
                                 + f"true minimum in [{sweep['certified_bound_mm']:.6f}, "
                                   f"{sweep['minimum_mm']:.6f}] mm",
                     "basis": "certificate of the sweep (speed and acceleration bounds)"})
    return rows

