"""`cadgen analyze`: kinematics, design metrics, report.json and plots of one design."""

from __future__ import annotations

import hashlib
import json
import math
import platform
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["AnalysisResult", "run_analysis", "format_metrics_table", "report_dict"]


@dataclass
class AnalysisResult:
    """What one analysis produced: the evaluation, the report and where it was written."""

    name: str
    report: dict
    output_dir: Path | None
    files: list = field(default_factory=list)

    def summary_text(self) -> str:
        if self.report["mechanism"] == "pricking":
            from .pricking_report import pricking_summary

            text = pricking_summary(self.report)
        else:
            text = format_metrics_table(self.report)
        if "gear_train" in self.report:
            text += "\n\n" + format_gear_table(self.report["gear_train"])
        if "cam" in self.report:
            text += "\n\n" + format_cam(self.report["cam"])
        if "solids" in self.report:
            text += "\n\n" + format_solids(self.report["solids"])
        return text + (
            f"\nwrote {len(self.files)} files to {self.output_dir}" if self.output_dir else "")


def _stage(timings: dict, name: str):
    class _Timer:
        def __enter__(self):
            self.start = time.perf_counter()

        def __exit__(self, *exc):
            timings[name] = round(time.perf_counter() - self.start, 6)

    return _Timer()


def input_hash(params) -> str:
    """SHA-256 of the validated parameters in canonical JSON (same design, same hash)."""
    canonical = json.dumps(params.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


def _versions() -> dict:
    import scipy

    from . import __version__

    return {"cadgen": __version__, "python": platform.python_version(),
            "numpy": np.__version__, "scipy": scipy.__version__}


def report_dict(params, mechanism, evaluation, timings) -> dict:
    """The JSON report: parameters, derived geometry, metrics against targets, accuracy."""
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
    return {
        "design": params.name,
        "mechanism": params.mechanism,
        "input_sha256": input_hash(params),
        "passed": evaluation.passed,
        "metrics": [{"key": m.key, "label": m.label, "value": m.value, "unit": m.unit,
                     "target": m.target, "passed": m.passed, "spacing_mm": m.spacing}
                    for m in evaluation.metrics],
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
        "stages_s": timings,
        "versions": _versions(),
        "parameters": params.model_dump(mode="json"),
    }


def format_metrics_table(report: dict) -> str:
    """Plain-text table of the metrics against their targets."""
    rows = [("metric", "spacing", "value", "target", "")]
    for m in report["metrics"]:
        spacing = f"{m['spacing_mm']:g} mm" if m["spacing_mm"] is not None else ""
        value = f"{m['value']:.3f} {m['unit']}".strip()
        rows.append((m["label"], spacing, value, f"{m['target']} {m['unit']}".strip(),
                     "pass" if m["passed"] else "FAIL"))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    lines = [f"design {report['design']} ({report['mechanism']} mechanism): "
             f"{'all targets met' if report['passed'] else 'TARGETS MISSED'}"]
    for k, row in enumerate(rows):
        lines.append("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        if k == 0:
            lines.append("  ".join("-" * w for w in widths))
    ev = report["events"]
    att = ev["attitude_deg"]
    lines.append("")
    lines.append("attitude Psi (deg): catching {catching:.3f}, entry {entry:.3f}, lowest {lowest:.3f}, "
                 "exit {exit:.3f}".format(**att))
    vl = ev["tip_velocity_relative_lowest_mm_s"]
    lines.append(f"tip velocity at the lowest point, relative: ({vl[0]:.2f}, {vl[1]:.2f}) mm/s "
                 f"at {ev['carrier_speed_rpm']:g} r/min")
    for row in report["per_spacing"]:
        v = row["tip_velocity_absolute_lowest_mm_s"]
        lines.append(f"  absolute at S = {row['spacing_mm']:g} mm: ({v[0]:.2f}, {v[1]:.2f}) mm/s")
    lines.append(f"catching-to-planting height: {ev['catch_to_plant_height_mm']:.3f} mm")
    d = report["derived"]
    lines.append(f"centre distance a = {d['centre_distance_a_mm']:.6f} mm, "
                 f"module {d['module_mm']:.4f} mm, ratio {d['ratio_min']:.4f}..{d['ratio_max']:.4f}")
    return "\n".join(lines)


def format_cam(cam: dict) -> str:
    """Plain-text summary of the duckbill cam and its checks."""
    events = cam["carrier_angle_deg"]
    lines = [f"cam: opening {cam['opening_angle_deg']:.2f} deg (mouth {cam['mouth_mm']:.1f} mm for "
             f"{cam['required_mouth_mm']:.1f} mm), push-rod stroke {cam['push_rod_stroke_mm']:.2f} "
             f"mm, roller lift {cam['roller_lift_mm']:.2f} mm",
             f"     opens {events['opening'][0]:.1f}..{events['opening'][1]:.1f} deg, closes "
             f"{events['closing'][0]:.1f}..{events['closing'][1]:.1f} deg (lowest point "
             f"{events['lowest']:.1f}, exit {events['exit']:.1f}, seedling cleared "
             f"{events['seedling_cleared']:.1f})",
             f"     pressure angle max {cam['pressure_angle_max_deg']:.2f} deg, smallest convex "
             f"pitch radius {cam['pitch_radius_convex_min_mm']:.2f} mm for a "
             f"{cam['roller_radius_mm']:g}-mm roller"]
    for problem in cam["problems"]:
        lines.append(f"     FAIL [{problem['code']}] {problem['message']}")
    return "\n".join(lines)


def format_solids(solids: dict) -> str:
    """Plain-text summary of the solids: parts, mass, enclosure."""
    parts = solids["parts"]
    instances = sum(p["instances"] for p in parts)
    lines = [f"solids: {len(parts)} parts ({instances} placed), total mass "
             f"{solids['total_mass_kg']:.2f} kg at {solids['density_kg_m3']:g} kg/m3, assembly at "
             f"carrier angle {solids['assembly']['carrier_angle_deg']:g} deg"]
    for row in solids["enclosure"]:
        margin = row["smallest_margin_mm"]
        if margin is None:
            lines.append(f"     {row['housing']}: no gears were cut, so its size is a coarse "
                         "estimate (each gear within the centre distance)")
            continue
        state = ("encloses its gears" if row["gears_enclosed"] else "DOES NOT enclose its gears")
        lines.append(f"     {row['housing']} {state} (smallest margin {margin:.2f} mm, "
                     f"{row['nearest_gear']})")
    return "\n".join(lines)


def format_gear_table(gear_train: dict) -> str:
    """Plain-text table of the generated gears and their meshes."""
    rows = [("gear", "teeth", "module", "cutter", "undercut teeth", "pointed", "problems")]
    for g in gear_train["gears"]:
        rows.append((g["gear"], str(g["teeth"]), f"{g['module_mm']:.4f}", g["cutter"] +
                     (f" (z={g['shaper_teeth']})" if g["shaper_teeth"] else ""),
                     str(len(g["undercut_teeth"])), str(len(g["pointed_teeth"])),
                     ", ".join(p["code"] for p in g["problems"]) or "-"))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    lines.append("")
    for m in gear_train["meshes"]:
        relief = m["tip_relief"]
        lines.append(
            f"mesh {m['stage']}: {m['interference_poses']} interfering poses of {m['poses']} "
            f"(largest overlap {m['overlap_area_max_mm2']:.1e} mm2), backlash "
            f"{m['backlash_deg'][0]:.1e}..{m['backlash_deg'][1]:.1e} deg, transmission error "
            f"{m['transmission_error_pp_deg']:.1e} deg p-p"
            + (f"; tip relief on the {relief['gear']} gear: {relief['removed_area_mm2']:.3f} mm2, "
               f"up to {relief['depth_mm']:.3f} mm deep" if relief else ""))
    for f in gear_train["failures"]:
        lines.append(f"NOT CUT [{f['code']}] {f['message']}")
    return "\n".join(lines)


@dataclass
class _Outcome:
    """What a mechanism's analysis hands to the writer: the report, PNGs and file writers.

    Each writer takes the staging directory and returns the paths it wrote,
    relative to it; they run inside the staged (atomic) output directory.
    """

    report: dict
    figures: dict = field(default_factory=dict)
    writers: list = field(default_factory=list)


def run_analysis(params, output_root: Path | str | None = Path("outputs"),
                 steps_per_revolution: int | None = None, plots: bool = True,
                 gears: bool = True, cam: bool = True, solids: bool = True) -> AnalysisResult:
    """Analyse one validated design; write ``<output_root>/<name>/`` atomically.

    With ``output_root=None`` nothing is written (the report is still returned).
    ``gears`` generates, checks and meshes every gear of the trains and writes
    their DXF files under ``gears/``; ``cam`` designs the planting mechanism's
    duckbill cam and writes ``cam.dxf`` (when the roller can follow the contour);
    ``solids`` builds every part (manifold3d), checks that the housings enclose
    their gears, and writes ``solids/*.stl`` and the assembly file.
    """
    draw = plots and output_root is not None
    if params.mechanism == "pricking":
        outcome = _pricking(params, draw, gears, solids)
    else:
        outcome = _planting(params, steps_per_revolution, draw, gears, cam, solids)
    report = outcome.report
    if output_root is None:
        return AnalysisResult(params.name, report, None)
    from .atomic import staged_directory

    final = Path(output_root) / params.name
    files = []
    with staged_directory(final) as staging:
        (staging / "plots").mkdir()
        for writer in outcome.writers:
            files += [str(path) for path in writer(staging)]
        for name, data in outcome.figures.items():
            (staging / "plots" / name).write_bytes(data)
            files.append(f"plots/{name}")
        (staging / "report.json").write_text(json.dumps(report, indent=2, default=_jsonable) + "\n")
        files.append("report.json")
    return AnalysisResult(params.name, report, final, sorted(files))


def _gear_train(timings: dict, wanted: bool, build):
    """The gear stage, timed, when it is wanted: ``build()`` makes the mechanism's train."""
    if not wanted:
        return None
    with _stage(timings, "gears"):
        return build()


def _with_train(outcome: _Outcome, train, chord_tolerance: float) -> _Outcome:
    """Add the gear train's report section, pictures and DXF writer to an outcome."""
    if train is None:
        return outcome
    from .gear_trains import train_report, write_train_files

    outcome.report["gear_train"] = train_report(train)
    if not train.stages:
        return outcome

    def write(staging):
        (staging / "gears").mkdir()
        return [f"gears/{Path(path).name}"
                for path in write_train_files(train, staging / "gears", chord_tolerance)]

    outcome.writers.append(write)
    return outcome


def _planting(params, steps_per_revolution, plots, gears=True, cam=True, solids=True) -> _Outcome:
    from .design import build_mechanism, evaluate
    from .gear_trains import pair_figures, planting_train

    timings: dict = {}
    with _stage(timings, "kinematics"):
        mechanism = build_mechanism(params)
        mechanism.closure  # solve the closure inside its own stage
    with _stage(timings, "metrics"):
        evaluation = evaluate(params, mechanism, steps=steps_per_revolution)
    train = _gear_train(timings, gears, lambda: planting_train(params, mechanism))
    cam_design = None
    if cam:
        from .cam_design import design_cam

        with _stage(timings, "cam"):
            cam_design = design_cam(params, mechanism, evaluation.events)
    solid_parts = None
    if solids:
        from .solids.planting import planting_assembly

        with _stage(timings, "solids"):
            assembly, housings, _ = planting_assembly(params, mechanism, train, cam_design,
                                                      evaluation.events.soil_level)
            solid_parts = _solids_outcome(params, assembly,
                                          {"gearbox1": housings[0], "gearbox2": housings[1]})
    figures = {}
    if plots:
        with _stage(timings, "plots"):
            from .plots import planting_figures

            figures = planting_figures(mechanism, evaluation)
            if train is not None and train.stages:
                figures.update(pair_figures(train))
            if cam_design is not None:
                from .plots_cam import cam_figures

                figures.update(cam_figures(cam_design, params.cam.profile_points))
            if solid_parts is not None:
                from .plots_solids import assembly_view

                angle = solid_parts.carrier_angle
                tip = mechanism.motion(np.linspace(0, 2 * np.pi, 721), "N").position
                figures["assembly.png"] = assembly_view(
                    solid_parts.assembly, angle, paths=[(tip, "tip path N (relative)")],
                    soil_level=evaluation.events.soil_level,
                    title=f"Solids at carrier angle {np.degrees(angle):g} deg (front view)")
    outcome = _Outcome(report_dict(params, mechanism, evaluation, timings), figures)
    if cam_design is not None:
        outcome.report["cam"] = _cam_section(cam_design, params)
        if cam_design.cuttable:
            outcome.writers.append(lambda staging: _write_cam(staging, cam_design, params))
    _with_solids(outcome, solid_parts, timings)
    return _with_train(outcome, train, params.gears.chord_tolerance)


def _solids_outcome(params, assembly, housings):
    from .solids.stage import SolidsOutcome, enclosure_checks

    settings = params.solids
    return SolidsOutcome(assembly, housings, enclosure_checks(assembly, housings),
                         settings.assembly_carrier_angle_rad, settings.density_kg_m3,
                         settings.assembly_format)


def _with_solids(outcome: _Outcome, solid_parts, timings) -> None:
    """Add the solids' report section (mass properties, enclosure) and their file writer."""
    if solid_parts is None:
        return
    from .solids.stage import solids_report, write_solids

    with _stage(timings, "solids_report"):
        outcome.report["solids"] = solids_report(solid_parts)
    outcome.writers.append(lambda staging: write_solids(solid_parts, staging))


def _cam_section(design, params) -> dict:
    from .cam_design import cam_report

    section = cam_report(design)
    if not design.cuttable:
        section["not_written"] = "cam.dxf is not written: the roller cannot follow this contour"
    return section


def _write_cam(staging, design, params):
    from .export_dxf import write_cam_dxf

    points = params.cam.profile_points
    write_cam_dxf(staging / "cam.dxf", design.profile.working_profile(points),
                  design.profile.pitch_curve(points), bore_radius=params.cam.bore_diameter / 2,
                  chord_tolerance=params.gears.chord_tolerance)
    return ["cam.dxf"]


def _pricking(params, plots, gears=True, solids=True) -> _Outcome:
    from .design import pricking_design, pricking_field
    from .gear_trains import pair_figures, pricking_train
    from .pricking_report import pricking_report

    timings: dict = {}
    with _stage(timings, "inverse_design"):
        design = pricking_design(params)
    with _stage(timings, "field"):
        field_motion = pricking_field(params, design)
    train = _gear_train(timings, gears, lambda: pricking_train(params, design))
    solid_parts = None
    if solids:
        from .solids.pricking import pricking_assembly

        with _stage(timings, "solids"):
            assembly, housings = pricking_assembly(params, design, train, field_motion)
            solid_parts = _solids_outcome(params, assembly, housings)
    figures = {}
    if plots:
        with _stage(timings, "plots"):
            from .plots_pricking import pricking_figures

            figures = pricking_figures(params, design, field_motion)
            if train is not None and train.stages:
                figures.update(pair_figures(train))
            if solid_parts is not None:
                from .plots_solids import assembly_view

                angle = solid_parts.carrier_angle
                loop = design.motion.tip(np.linspace(0, design.motion.period, 721))
                figures["assembly.png"] = assembly_view(
                    solid_parts.assembly, angle, paths=[(loop, "needle-tip loop")],
                    soil_level=field_motion[0].surface_level,
                    title=f"Solids {np.degrees(angle):g} deg of carrier turn after the outer dead "
                          "centre (front view, in the mechanism plane)")
    report = pricking_report(params, design, field_motion, timings, _versions(), input_hash(params))
    outcome = _Outcome(report, figures)
    _with_solids(outcome, solid_parts, timings)
    return _with_train(outcome, train, params.gears.chord_tolerance)


def _jsonable(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")
