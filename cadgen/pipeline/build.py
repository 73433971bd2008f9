"""`cadgen build`: run exactly the stages a scene's effects need, then write the outputs atomically.

A scene (``[scene]`` in the file, or ``effects``/``case`` given here) names the
effects wanted; :func:`cadgen.pipeline.plan.plan` resolves the stages they need, in
order, and nothing else runs: a scene asking only for ``metrics`` generates no teeth,
builds no solids and never imports fcl.

Stages (each timed and recorded ``ok``, ``failed`` with the reason, or
``skipped`` because a stage it needs failed):

==================  ==========================================================
kinematics          the mechanism (planting: closure; pricking: inverse design)
metrics             the design metrics (planting) or the field motion (pricking)
drivetrain          shafts from torque, catalogue bearings (L10 life), keys, fits
                    (:mod:`cadgen.machine`): numbers only, no solids
teeth               every gear cut, checked and run through its meshing check,
                    each bored for its shaft with its keyway (rim check)
cam                 the duckbill cam (planting)
parts               the solids: split housings (base and cover with bearing
                    seats and bolt flanges), shafts, planter or needle, ground;
                    gears and the cam plate when those ran; mass and enclosure
                    checks
arm_interference    FCL sweep of arm against arm (planting)
ground_clearance    FCL sweep of every housing against the ground
dynamics            inverse dynamics over a carrier turn: drive torque,
                    bearing and mesh forces, shaking force (:mod:`cadgen.dynamics`)
plots               PNG pictures of what ran
==================  ==========================================================

A problem validation found in one stage's checks (``Problem.stage``, e.g. the
duckbill linkage, stage ``cam``) refuses the build when the scene runs that stage
(a :class:`~cadgen.params.ParameterError` before anything runs or is written) and is
a warning otherwise: in the report's ``warnings`` with its stage, and in the summary.

Outputs go to a staged folder that replaces ``<output_root>/<name>/`` only when
everything was written: a failed stage leaves its outputs out and says why in
the report, and a failure while writing leaves the previous folder untouched.
Every file but report.json (which holds the stage timings) is byte-identical for
the same input.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from kinematics.errors import ConvergenceError, DesignError, MechanismError

# the scene's planning, here too for the callers that import it from the build
from cadgen.pipeline.plan import (EFFECT_STAGES, STAGE_NEEDS, STAGE_ORDER, check_build, plan,
                                  scene_plan, stage_warnings)
from cadgen.pipeline.progress import WRITE_STAGE

__all__ = ["EFFECT_STAGES", "plan", "scene_plan", "stage_warnings", "BuildResult", "build",
           "EXIT_OK", "EXIT_CHECKS_FAILED", "run_analysis", "AnalysisResult"]


EXIT_OK = 0
EXIT_CHECKS_FAILED = 1


@dataclass
class StageRecord:
    stage: str
    status: str            # "ok", "failed", "skipped"
    seconds: float = 0.0
    message: str = ""
    problems: list = field(default_factory=list)

    def as_dict(self) -> dict:
        out = {"stage": self.stage, "status": self.status, "seconds": round(self.seconds, 6),
               "message": self.message}
        if self.problems:
            out["problems"] = self.problems
        return out


@dataclass
class BuildResult:
    """What a build produced: the report, the folder written and its files."""

    name: str
    report: dict
    output_dir: Path | None
    files: list = field(default_factory=list)

    @property
    def exit_code(self) -> int:
        """0 when every stage ran and every target and check passed, else 1."""
        return EXIT_OK if self.report.get("passed") else EXIT_CHECKS_FAILED

    def summary_text(self) -> str:
        from cadgen.report.summary import summary_text

        text = summary_text(self.report)
        for warning in self.report.get("warnings", []):
            text += (f"\nwarning: {warning['path'] or '<file>'}: {warning['message']} "
                     f"[{warning['code']}] (stage {warning['stage']}, not run in this build)")
        count = len(self.files)
        return text + (f"\nwrote {count} file{'s' * (count != 1)} to {self.output_dir}"
                       if self.output_dir else "")


class _Build:
    """One build's state: the values each stage made, its records, figures and writers."""

    def __init__(self, params, stages, steps, progress=None):
        from cadgen.pipeline.progress import StageProgress

        self.params = params
        self.progress = progress if isinstance(progress, StageProgress) \
            else StageProgress(progress)
        self.stages = stages
        self.steps = steps
        self.values: dict = {}
        self.records: list = []
        self.figures: dict = {}
        self.writers: list = []
        self.warnings: list = []
        self.effects: tuple = ()       # the scene's (set by :func:`build`)
        self.case = "field"
        self.parallel: bool | None = None   # False: no worker forked (see :func:`build`)
        self._beside = None            # the forked worker until collected (see run)

    @property
    def soil(self) -> bool:
        """Whether the run has soil: a bench run has none, and its figures, animation and
        report leave out what needs it."""
        return self.case != "bench"

    def status(self, stage: str) -> str:
        return next((r.status for r in self.records if r.stage == stage), "not run")

    def run(self, functions: dict) -> None:
        try:
            beside = self._run_stages(functions)
            if beside is not None:
                from cadgen.pipeline.beside import collect

                collect(self, beside)
        except BaseException:
            # interrupted (or a bug): the worker's tasks are abandoned, and it must not run on
            # while this process ends, nor hold up that end (see _Beside.stop)
            if self._beside is not None:
                self._beside.stop()
            raise
        finally:
            self._beside = None
        self.records.sort(key=lambda record: STAGE_ORDER.index(record.stage))

    def _run_stages(self, functions: dict):
        """Run the stages in order; the forked worker if its results are still to collect."""
        beside = None
        for stage in self.stages:
            if stage == "teeth" and beside is None:
                from cadgen.pipeline.beside import start_beside

                beside = start_beside(self, functions)   # (sets self._beside)
            if beside is not None and stage in beside.sweeps:
                continue            # the worker's: collected with its figures (_collect)
            failed = [need for need in STAGE_NEEDS[stage]
                      if need in self.stages and self.status(need) != "ok"]
            if failed:
                record = StageRecord(stage, "skipped", message=(
                    f"needs {', '.join(failed)}, which did not complete"))
                self.records.append(record)
                self.progress.finished(stage, "skipped", 0.0, detail=record.message)
                continue
            if beside is not None and stage == "plots":
                from cadgen.pipeline.beside import plots_beside

                record, value = plots_beside(self, beside)
                beside = self._beside = None     # collected
            else:
                self.progress.started(stage)
                record, value = _run_stage(self, stage, functions)
                self.progress.finished(stage, record.status, record.seconds,
                                       detail=record.message)
            self.records.append(record)
            if record.status == "ok":
                self.values[stage] = value
        return beside


def _run_stage(run, stage: str, functions: dict):
    """Run one stage: ``(StageRecord, value)``; a design or model error fails the stage only."""
    start = time.perf_counter()
    try:
        value = functions[stage](run)
    except (DesignError, ConvergenceError) as error:
        problems = [{"path": p.path, "code": p.code, "message": p.message}
                    for p in getattr(error, "problems", [])]
        message = "; ".join(f"[{p['code']}] {p['message']}" for p in problems) or str(error)
        return StageRecord(stage, "failed", time.perf_counter() - start, message, problems), None
    except MechanismError as error:
        return StageRecord(stage, "failed", time.perf_counter() - start,
                           f"{type(error).__name__}: {error}"), None
    return StageRecord(stage, "ok", time.perf_counter() - start), value


#: The FCL sweeps (run beside the teeth where they can: :mod:`cadgen.pipeline.beside`).
SWEEP_STAGES = ("arm_interference", "ground_clearance")


# --------------------------------------------------------------------------- stages
def _kinematics(run):
    params = run.params
    if params.mechanism == "pricking":
        from cadgen.design import pricking_design

        return pricking_design(params)
    from cadgen.design import build_mechanism

    mechanism = build_mechanism(params)
    mechanism.closure   # the closure is solved here, inside its stage
    return mechanism


def _metrics(run):
    params = run.params
    if params.mechanism == "pricking":
        from cadgen.design import pricking_field

        return pricking_field(params, run.values["kinematics"])
    from cadgen.design import evaluate

    return evaluate(params, run.values["kinematics"], steps=run.steps)


def _drivetrain(run):
    from cadgen.machine.drivetrain import drivetrain

    cam = run.values.get("cam") if run.status("cam") == "ok" else None   # screwed to gearbox 2
    sized = drivetrain(run.params, run.values["kinematics"], cam)
    # sized again from the dynamics' loads (estimated masses, the field's) in every scene and
    # case: a design is the same parts whatever the build is asked (pricking: the tip force)
    if run.params.mechanism == "planting" and run.status("metrics") == "ok":
        from cadgen.dynamics.sizing import size_from_dynamics

        sized = size_from_dynamics(run.params, run.values["kinematics"], sized, cam=cam,
                                   events=run.values["metrics"].events)
    return sized


def _events(run):
    """The soil level and the lowest point (None: a bench run, or no metrics: no soil)."""
    return run.values["metrics"].events if run.soil and run.status("metrics") == "ok" else None


def _teeth(run):
    """Every gear cut with the process's backlash (or from the gear cache), then bored for its
    shaft (when the drivetrain ran): the rim checks ride on the train (``GearTrain.rims``)."""
    from cadgen.gears.trains import planting_train, pricking_train
    from cadgen.machine.fits import process_fits
    from cadgen.pipeline.gear_cache import cache_record, open_cache

    def cut(done, total, pair):
        run.progress.step("teeth", pair, steps=total)

    params = run.params
    fits = process_fits(params.manufacturing.process)
    if params.gears.backlash is None:   # the process's allowance (the file left it out)
        params = params.model_copy(update={"gears": params.gears.model_copy(
            update={"backlash": fits.backlash})})
    make = pricking_train if params.mechanism == "pricking" else planting_train
    asked = getattr(run, "cache", None)   # a run made outside build() has no cache
    cache = open_cache(asked)   # opened here: a scene without teeth never touches it
    options = {}
    if params.mechanism == "planting" and run.status("drivetrain") == "ok":
        options["drive"] = run.values["drivetrain"].drive   # designed round its shafts
    train = make(params, run.values["kinematics"], progress=cut, cache=cache, **options)
    run.gear_cache = cache_record(cache, asked)   # hits and misses, for the report
    if run.status("drivetrain") == "ok" and train.stages:
        from cadgen.machine.hubs import hub_train

        train, rims = hub_train(train, run.values["drivetrain"],
                                key_slot_allowance=fits.key_slot_allowance,
                                segments=params.solids.segments_per_circle)
        train = dataclasses.replace(train, rims=rims)
        if {"parts", "dxf"} & ({*run.stages} | {*run.effects}):
            from cadgen.pipeline.gear_cache import remember_cutting_outlines

            remember_cutting_outlines(train, params.gears.chord_tolerance)
    if train.stages:   # every cut gear's teeth under the design load over the cycle
        from cadgen.machine.gear_strength import train_strength

        train = dataclasses.replace(train, strength=train_strength(
            params, run.values["kinematics"], train))
    return train


def _cam(run):
    from cadgen.cam.design import design_cam

    return design_cam(run.params, run.values["kinematics"], run.values["metrics"].events)


def _gearless_parts(run):
    return _parts(run, gears=False)


def _parts(run, gears: bool = True):
    from cadgen.solids.outcome import solids_outcome

    params = run.params
    train = run.values.get("teeth") if gears and run.status("teeth") == "ok" else None
    if params.mechanism == "pricking":
        from cadgen.solids.pricking import pricking_assembly

        assembly, housings = pricking_assembly(params, run.values["kinematics"], train,
                                               run.values["metrics"],
                                               drivetrain=run.values["drivetrain"],
                                               soil=run.soil)
        return solids_outcome(params, assembly, housings)
    from cadgen.solids.planting import planting_assembly

    cam = run.values.get("cam") if run.status("cam") == "ok" else None
    soil_level = run.values["metrics"].events.soil_level if run.soil else None  # bench: none
    assembly, housings, _ = planting_assembly(params, run.values["kinematics"], train, cam,
                                              soil_level, drivetrain=run.values["drivetrain"])
    return solids_outcome(params, assembly, dict(zip(("gearbox1", "gearbox2", "frame"),
                                                     housings)))


def _arm_interference(run):
    from cadgen.pipeline.clearances import arm_interference

    return arm_interference(run.params, run.values["kinematics"], run.values["parts"],
                            run.values.get("cam"), evaluation=run.values.get("metrics"))


def _ground_clearance(run):
    from cadgen.pipeline.clearances import ground_clearance

    return ground_clearance(run.params, run.values["kinematics"], run.values["parts"],
                            run.values["metrics"])


def _dynamics(run):
    """Inverse dynamics over a carrier turn: masses from the solids when the parts and the
    gears were built, else estimated from the parameters."""
    from cadgen.dynamics import planting_dynamics

    pricking = run.params.mechanism == "pricking"
    masses, source, skipped = None, "estimated", ()
    # a pricking stage that could not be cut leaves its gears out of the solids: estimate
    cut = run.status("teeth") == "ok" and not (pricking and run.values["teeth"].failures)
    if run.status("parts") == "ok" and cut:
        from cadgen.dynamics.mass import solid_mass_properties

        if run._beside is not None:     # the worker's meshes of the gearless parts, not again
            from cadgen.pipeline.beside import take_meshes

            take_meshes(run, run._beside)
        from cadgen.dynamics.pricking_mass import pricking_body_of_part

        masses, skipped = solid_mass_properties(
            run.values["parts"], **({"body_of": pricking_body_of_part} if pricking else {}))
        source = "solids"
    if pricking:
        from cadgen.dynamics import pricking_dynamics

        field = run.values["metrics"] if run.soil and run.status("metrics") == "ok" else None
        result = pricking_dynamics(run.params, run.values["kinematics"],
                                   run.values["drivetrain"], field=field, masses=masses,
                                   mass_source=source, skipped=skipped)
    else:
        cam = run.values.get("cam") if run.status("cam") == "ok" else None
        result = planting_dynamics(run.params, run.values["kinematics"],
                                   run.values["drivetrain"], cam=cam, events=_events(run),
                                   masses=masses, mass_source=source, skipped=skipped)
        # the drivetrain as built, checked with these loads: what fails is the machine's (the
        # field's loads only: load case "none" checks the model, not the machine)
        if result.load_case == "planting":
            from cadgen.dynamics.sizing import recheck_drivetrain

            run.values["drivetrain"] = recheck_drivetrain(
                run.params, run.values["kinematics"], run.values["drivetrain"], result)
    train = run.values.get("teeth") if run.status("teeth") == "ok" else None
    if train is not None and train.stages and result.meshes:
        # the teeth under the computed loads: what the report's strength then says
        from cadgen.machine.gear_strength import dynamics_mesh_forces, train_strength

        result.strength = train_strength(
            run.params, run.values["kinematics"], train,
            dynamics_mesh_forces(result, run.params.machine.service_factor))
    return result


def _plots(run):
    from cadgen.pipeline.figures import build_figures

    return build_figures(run, parallel=False if run.parallel is False else None)


STAGE_FUNCTIONS = {"kinematics": _kinematics, "metrics": _metrics, "drivetrain": _drivetrain,
                   "teeth": _teeth, "cam": _cam,
                   "parts": _parts, "arm_interference": _arm_interference,
                   "ground_clearance": _ground_clearance, "dynamics": _dynamics,
                   "plots": _plots}


# --------------------------------------------------------------------------- the build
def build(params, output_root: Path | str | None = Path("outputs"), *, effects=None,
          case: str | None = None, steps: int | None = None,
          preset: str | None = None, progress=None, cache=True,
          parallel: bool | None = None) -> BuildResult:
    """Build one validated design: the stages its effects need, then its outputs.

    Parameters
    ----------
    params : PlantingParameters or PrickingParameters
        Validated (see :func:`cadgen.params.load_params`).
    output_root : path or None
        Outputs go to ``<output_root>/<name>/``, atomically; ``None`` writes nothing.
    effects : sequence of str, optional
        Overrides the file's ``scene.effects``.
    case : {"field", "bench"}, optional
        Overrides the file's ``scene.case``.
    steps : int, optional
        Overrides ``resolution.steps_per_revolution`` (planting).
    preset : {"draft", "standard", "fine"}, optional
        Overrides the file's ``scene.preset``: the resolution of every knob the file
        leaves out (see :mod:`cadgen.params.scene`).
    progress : callable, optional
        Called with a :class:`~cadgen.pipeline.progress.ProgressEvent` as each stage
        starts, steps on (teeth: per gear pair; plots: per figure; writing: per group of
        files) and finishes, and for the pseudo-stage ``"write"`` (the output folder).
        In this process, never twice at once; the sweeps run beside the teeth, so their
        events interleave with the teeth's (``event.beside``). Nothing is printed.
    cache : bool or path, default True
        The gear cache (:mod:`cadgen.gears.cache`): True, the user's (see
        :func:`cadgen.pipeline.gear_cache.cache_directory`); a path, that directory; False or
        None, none (an unusable directory too). The report's ``gear_cache``: hits, misses.
    parallel : bool or None, default None
        None: a worker is forked beside the teeth where that helps (a second core, the fork
        start method; :mod:`cadgen.pipeline.beside`). False: every stage in this process,
        for a caller that already keeps every core busy (``cadgen batch``, a design per
        core). The files are the same either way.

    Raises
    ------
    TypeError
        Before anything runs, a ``parallel`` that is not True, False or None.
    cadgen.export.atomic.OutputDirError
        Before any stage runs, when ``output_root`` cannot take the outputs (a file, a
        read-only or virtual filesystem, an existing ``<output_root>/<name>`` file).
    cadgen.params.ParameterError
        Before any stage runs, when a problem validation found belongs to a stage
        the scene runs (see :func:`stage_warnings`); of other stages, warnings. Also when
        no effect of the scene applies to the design (``scene.effects``,
        ``nothing_to_build``).
    """
    if parallel is not None and not isinstance(parallel, bool):
        raise TypeError(f"parallel must be True, False or None, not {parallel!r}")
    if output_root is not None:
        from cadgen.export.atomic import check_output_root

        check_output_root(output_root, name=params.name)

    checked = check_build(params, effects=effects, case=case, preset=preset)
    params, set_aside = checked.params, checked.set_aside
    run = _Build(params, checked.stages, steps, progress)
    run.warnings = checked.warnings
    run.effects, run.case, run.cache, run.parallel = checked.effects, checked.case, cache, parallel
    run.preset = {"name": checked.preset, "knobs": {
        path: {"value": value, "from": source} for path, (value, source) in checked.knobs.items()}}
    with _fewer_collections():
        run.run(STAGE_FUNCTIONS)
        from cadgen.report.content import assemble_report

        report = assemble_report(run, set_aside)
        run.report = report
        if output_root is None:
            return BuildResult(params.name, report, None)
        return _write(run, Path(output_root) / params.name)


@contextlib.contextmanager
def _fewer_collections(threshold: int = 20000):
    """Run the cyclic garbage collector less often during a build (and in the worker forked
    from it): a build makes millions of short-lived objects and few cycles, and the default
    (a young collection every 700 allocations) cost 5 % of a full build's time, for 15 MB
    less memory at most. The thresholds are put back after."""
    import gc

    before = gc.get_threshold()
    gc.set_threshold(max(before[0], threshold), max(before[1], 20), max(before[2], 50))
    try:
        yield
    finally:
        gc.set_threshold(*before)


def _write(run, final: Path) -> BuildResult:
    from cadgen.export.atomic import staged_directory
    from cadgen.pipeline.writers import writers_for

    report = run.report
    files = []
    writers = writers_for(run)
    progress = run.progress
    progress.started(WRITE_STAGE, steps=len(writers) + bool(run.figures) + 1
                     + ("report" in run.effects), detail=str(final))
    start = time.perf_counter()
    try:
        with staged_directory(final) as staging:
            for writer in writers:
                written = [str(path) for path in writer(staging)]
                files += written
                progress.step(WRITE_STAGE, _group(written))
            if run.figures:
                (staging / "plots").mkdir(exist_ok=True)
                for name, data in run.figures.items():
                    (staging / "plots" / name).write_bytes(data)
                    files.append(f"plots/{name}")
                progress.step(WRITE_STAGE, _group([f"plots/{n}" for n in run.figures]))
            files.append("report.json")
            if "report" in run.effects:
                from cadgen.pipeline.writers import animation_of
                from cadgen.report.html import render_html

                from cadgen.pipeline.gear_cache import view_glb

                glb = staging / "solids" / "assembly.glb"   # the 3D view shows the file written
                glb = glb.read_bytes() if glb.is_file() else None
                (staging / "report.html").write_text(render_html(
                    report, run.figures, animation=animation_of(run), assembly_glb=glb,
                    assembly_view=view_glb(glb, getattr(run, "cache", None)) if glb else None),
                    encoding="utf-8")
                files.append("report.html")
                progress.step(WRITE_STAGE, "report.html")
            report["files"] = sorted(files)
            (staging / "report.json").write_text(
                json.dumps(report, indent=2, default=_jsonable) + "\n", encoding="utf-8")
            progress.step(WRITE_STAGE, "report.json")
    except Exception as error:
        progress.finished(WRITE_STAGE, "failed", time.perf_counter() - start,
                          detail=f"{type(error).__name__}: {error}")
        raise
    progress.finished(WRITE_STAGE, "ok", time.perf_counter() - start,
                      detail=f"{len(files)} file{'s' * (len(files) != 1)} in {final}")
    return BuildResult(run.params.name, report, final, sorted(files))


def _group(paths) -> str:
    """A step's files in a few words: ``gears/ (7 files)``, ``cam.dxf``."""
    if len(paths) == 1:
        return paths[0]
    folders = sorted({p.split("/")[0] + "/" if "/" in p else p for p in paths})
    return f"{', '.join(folders)} ({len(paths)} file{'s' * (len(paths) != 1)})"


def _jsonable(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")

# ----------------------------------------------------------------------------------------------
# The earlier entry point

AnalysisResult = BuildResult


def run_analysis(params, output_root: Path | str | None = Path("outputs"),
                 steps_per_revolution: int | None = None, plots: bool = True,
                 gears: bool = True, cam: bool = True, solids: bool = True,
                 sweeps: bool = False) -> BuildResult:
    """Analyse one validated design; write ``<output_root>/<name>/`` atomically.

    ``gears`` cuts, checks and meshes every gear and writes their DXF files;
    ``cam`` designs the duckbill cam (planting) and writes cam.dxf; ``solids``
    builds every part and writes the STL files and the assembly; ``sweeps`` runs
    the FCL arm-interference and ground-clearance sweeps; ``plots`` draws the
    pictures and the HTML report. With ``output_root=None`` nothing is written.
    """
    effects = ["metrics", "curves"]
    if gears:
        effects += ["teeth", "meshing", "dxf"]
    if cam and params.mechanism == "planting":
        effects += ["cam", "dxf"]
    if solids:
        effects += ["solids", "stl"]
    if sweeps:
        effects += ["arm_interference", "ground_clearance"]
    if plots:
        effects += ["plots", "report"]
    return build(params, output_root, effects=list(dict.fromkeys(effects)),
                 steps=steps_per_revolution)
