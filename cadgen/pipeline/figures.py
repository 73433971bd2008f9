"""The pictures of a build: one PNG per view of what its stages made (matplotlib, Agg).

Where the platform can fork, the figures are shared with a forked worker, each
process taking the next one not yet drawn: the worker inherits every computed
result, so nothing is pickled on the way in, only PNG bytes on the way back (the
fork costs about 0.03 s; sixteen figures take 0.5 s instead of 0.8 s on two cores).
The bytes are the same either way (each figure is drawn on its own).
"""

from __future__ import annotations

import gc
import multiprocessing
import os

import numpy as np

__all__ = ["build_figures", "figure_jobs", "preload"]

def figure_jobs(run) -> dict:
    """``{file name: callable -> PNG bytes}`` for every stage that ran."""
    ok = {r.stage for r in run.records if r.status == "ok"}
    values, params = run.values, run.params
    jobs = {}
    if params.mechanism == "pricking":
        if {"kinematics", "metrics"} <= ok:
            from cadgen.report.plots.pricking import pricking_figure_jobs

            jobs.update(pricking_figure_jobs(params, values["kinematics"], values["metrics"],
                                             soil=run.soil))
    elif "metrics" in ok:
        from cadgen.report.plots.planting import planting_figure_jobs

        jobs.update(planting_figure_jobs(values["kinematics"], values["metrics"],
                                          soil=run.soil))
    if "teeth" in ok and values["teeth"].stages:
        from cadgen.report.plots.parts import pair_figure_jobs

        jobs.update(pair_figure_jobs(values["teeth"]))
    if "cam" in ok:
        from cadgen.report.plots.cam import cam_figure_jobs

        jobs.update(cam_figure_jobs(values["cam"], params.cam.profile_points))
    if "parts" in ok:
        from cadgen.report.plots.housings import housing_figure_jobs

        jobs["assembly.png"] = lambda: _assembly(run)
        jobs.update(housing_figure_jobs(values["parts"].housings, values.get("drivetrain")))
    if "dynamics" in ok:
        from cadgen.dynamics import dynamics_report
        from cadgen.report.plots.dynamics import dynamics_figure_jobs

        events = values["metrics"].events if (run.soil and "metrics" in ok
                                              and params.mechanism != "pricking") else None
        jobs.update(dynamics_figure_jobs(dynamics_report(values["dynamics"], params), events))
    sweeps = {key: values[key] for key in ("arm_interference", "ground_clearance") if key in ok}
    if sweeps:
        from cadgen.report.plots.parts import clearance_figure

        # the pricking assembly turns from the outer (R max) dead centre, the planting one
        # from the catching position
        origin = ("carrier turn after the outer (R max) dead centre (deg)"
                  if params.mechanism == "pricking" else "carrier angle (deg, 0 = catching)")
        jobs["clearance.png"] = lambda: clearance_figure(sweeps, angle_label=origin)
    return {name: _collector_paused(draw) for name, draw in jobs.items()}


def _collector_paused(draw):
    """``draw`` with the build's objects out of the garbage collector's sight.

    A figure makes tens of thousands of small objects, so the collector runs often, and each
    full pass walks every object the process holds (the build's meshes, curves, ...; a
    study's or a batch's more). Frozen (an O(1) move to a generation the collector skips,
    undone after), only the figure's own objects are walked, whoever draws it (the stage, a
    forked worker): 2 % of the paper design's figures in a build of 100 000 objects, 5 %
    at 160 000.
    """
    def paused():
        gc.freeze()
        try:
            return draw()
        finally:
            gc.unfreeze()

    return paused


def build_figures(run, *, parallel: bool | None = None) -> dict:
    """Draw every figure of a run (shared with a forked worker where that helps).

    Each figure drawn is a step of stage ``plots`` on ``run.progress`` (when the run has one).
    """
    jobs = figure_jobs(run)
    progress = getattr(run, "progress", None)
    if parallel is None:
        parallel = _can_fork() and len(jobs) >= 4
    if not parallel:
        figures = {}
        for name, draw in jobs.items():
            figures[name] = draw()
            if progress is not None:
                progress.step("plots", name, steps=len(jobs))
    else:
        figures = _draw_in_two(jobs, progress)
    run.figures = {name: figures[name] for name in jobs}   # the jobs' order, whoever drew
    return run.figures


def _can_fork() -> bool:
    """A second core, the fork start method, and a process allowed children (a daemonic one,
    such as a Dask worker's, is not)."""
    return ((os.cpu_count() or 1) > 1 and "fork" in multiprocessing.get_all_start_methods()
            and not multiprocessing.current_process().daemon)


def preload() -> None:
    """Import what drawing needs (matplotlib's Agg figure, a quarter of a second) and open the
    figures' font, so that a process forked after this draws without doing it again."""
    import importlib

    from cadgen.report.plots.base import DPI
    from cadgen.report.plots.layout import text_metrics

    importlib.import_module("matplotlib.figure")     # the axes, lines, collections, ...
    text_metrics("0", 10.0, DPI)     # the Agg renderer, the font found and opened


def _draw_in_two(jobs: dict, progress=None) -> dict:
    """Draw ``jobs`` in this process and a forked worker, each taking the next figure not yet
    taken (a shared counter), so that neither waits for the other however the costs fall."""
    from cadgen.processes import process_pool, sigint_deferred, stop_pool

    preload()                                   # once, before the fork, for both
    context = multiprocessing.get_context("fork")
    names = list(jobs)
    ends = progress.pipe() if progress is not None else None
    _WORKER.clear()
    _WORKER.update(jobs=jobs, names=names, taken=context.Value("i", 0), progress=progress,
                   events=ends[1] if ends else None)
    pool = None
    try:
        # started whole, the worker dying with this thread (see cadgen.processes.lifeline)
        with sigint_deferred():
            pool = process_pool(1, context)
            future = pool.submit(_draw_worker_jobs)   # forks the worker here
        if ends:
            progress.relay(ends[0])
            ends[1].close()
        figures = _draw_untaken(progress)
        figures.update(future.result())
        pool.shutdown()
        if progress is not None:
            progress.join()
    except BaseException:
        stop_pool(pool)     # interrupted: the worker's figures are not waited for
        raise
    finally:
        _WORKER.clear()
    return figures


#: What the forked worker needs, set just before it is forked (it inherits them): the jobs,
#: their names, the shared count of figures taken, the build's progress and the pipe to it.
_WORKER: dict = {}


def _draw_untaken(progress) -> dict:
    """Draw figures until none is left untaken (in either process)."""
    jobs, names, taken = _WORKER["jobs"], _WORKER["names"], _WORKER["taken"]
    figures = {}
    while True:
        with taken.get_lock():
            index = taken.value
            taken.value += 1
        if index >= len(names):
            return figures
        figures[names[index]] = jobs[names[index]]()
        if progress is not None:
            progress.step("plots", names[index], steps=len(names))


def _draw_worker_jobs() -> dict:
    progress, events = _WORKER.get("progress"), _WORKER.get("events")
    if events is not None:
        progress.forward(events)
    try:
        return _draw_untaken(progress if events is not None else None)
    finally:
        if events is not None:
            events.close()


def _assembly(run) -> bytes:
    from cadgen.report.plots.parts import assembly_view

    outcome, params, values = run.values["parts"], run.params, run.values
    angle = outcome.carrier_angle
    if params.mechanism == "pricking":
        design, field = values["kinematics"], values["metrics"]
        loop = design.motion.tip(np.linspace(0, design.motion.period, 721))
        return assembly_view(outcome.assembly, angle, paths=[(loop, "needle-tip loop")],
                             soil_level=field[0].surface_level if run.soil else None,
                             title=f"Solids {np.degrees(angle):g} deg of carrier turn after the "
                                   "outer dead centre (front view, in the mechanism plane)")
    mechanism = values["kinematics"]
    tip = mechanism.motion(np.linspace(0, 2 * np.pi, 721), "N").position
    return assembly_view(outcome.assembly, angle, paths=[(tip, "tip path N (relative)")],
                         soil_level=values["metrics"].events.soil_level if run.soil else None,
                         title=f"Solids at carrier angle {np.degrees(angle):g} deg (front view)")
