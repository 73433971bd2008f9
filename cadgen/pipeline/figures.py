"""The pictures of a build: one PNG per view of what its stages made (matplotlib, Agg).

Drawing is the slowest part of a full build on a small machine (a dozen
figures). Where the platform can fork, half of the figures are drawn in a forked
worker while this process draws the rest: the worker inherits every computed
result, so nothing is pickled on the way in, only PNG bytes on the way back.
The bytes are the same either way (each figure is drawn on its own).
"""

from __future__ import annotations

import multiprocessing
import os

import numpy as np

__all__ = ["build_figures", "figure_jobs"]

#: Jobs the forked worker draws, set just before it is forked (it inherits them).
_WORKER_JOBS: dict = {}


def figure_jobs(run) -> dict:
    """``{file name: callable -> PNG bytes}`` for every stage that ran."""
    ok = {r.stage for r in run.records if r.status == "ok"}
    values, params = run.values, run.params
    jobs = {}
    if params.mechanism == "pricking":
        if {"kinematics", "metrics"} <= ok:
            from cadgen.report.plots.pricking import pricking_figure_jobs

            jobs.update(pricking_figure_jobs(params, values["kinematics"], values["metrics"]))
    elif "metrics" in ok:
        from cadgen.report.plots.planting import planting_figure_jobs

        jobs.update(planting_figure_jobs(values["kinematics"], values["metrics"]))
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
    sweeps = {key: values[key] for key in ("arm_interference", "ground_clearance") if key in ok}
    if sweeps:
        from cadgen.report.plots.parts import clearance_figure

        # the pricking assembly turns from the outer (R max) dead centre, the planting one
        # from the catching position
        origin = ("carrier turn after the outer (R max) dead centre (deg)"
                  if params.mechanism == "pricking" else "carrier angle (deg, 0 = catching)")
        jobs["clearance.png"] = lambda: clearance_figure(sweeps, angle_label=origin)
    return jobs


def build_figures(run, *, parallel: bool | None = None) -> dict:
    """Draw every figure of a run (half of them in a forked worker where that helps).

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


def _draw_in_two(jobs: dict, progress=None) -> dict:
    from concurrent.futures import ProcessPoolExecutor

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401  (imported once, before the fork, for both)

    names = list(jobs)
    theirs = names[1::2]
    ends = progress.pipe() if progress is not None else None
    _WORKER_JOBS.clear()
    _WORKER_JOBS.update({name: jobs[name] for name in theirs})
    _WORKER_PROGRESS.update(progress=progress, events=ends[1] if ends else None,
                            steps=len(names))
    try:
        with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:
            future = pool.submit(_draw_worker_jobs)   # forks the worker here
            if ends:
                progress.relay(ends[0])
                ends[1].close()
            figures = {}
            for name in names[0::2]:
                figures[name] = jobs[name]()
                if progress is not None:
                    progress.step("plots", name, steps=len(names))
            figures.update(future.result())
        if progress is not None:
            progress.join()
    finally:
        _WORKER_JOBS.clear()
        _WORKER_PROGRESS.clear()
    return figures


#: The build's progress and the pipe to it, for the forked worker (as :data:`_WORKER_JOBS`).
_WORKER_PROGRESS: dict = {}


def _draw_worker_jobs() -> dict:
    progress, events = _WORKER_PROGRESS.get("progress"), _WORKER_PROGRESS.get("events")
    if events is not None:
        progress.forward(events)
    figures = {}
    try:
        for name, draw in _WORKER_JOBS.items():
            figures[name] = draw()
            if events is not None:
                progress.step("plots", name, steps=_WORKER_PROGRESS["steps"])
    finally:
        if events is not None:
            events.close()
    return figures


def _assembly(run) -> bytes:
    from cadgen.report.plots.parts import assembly_view

    outcome, params, values = run.values["parts"], run.params, run.values
    angle = outcome.carrier_angle
    if params.mechanism == "pricking":
        design, field = values["kinematics"], values["metrics"]
        loop = design.motion.tip(np.linspace(0, design.motion.period, 721))
        return assembly_view(outcome.assembly, angle, paths=[(loop, "needle-tip loop")],
                             soil_level=field[0].surface_level,
                             title=f"Solids {np.degrees(angle):g} deg of carrier turn after the "
                                   "outer dead centre (front view, in the mechanism plane)")
    mechanism = values["kinematics"]
    tip = mechanism.motion(np.linspace(0, 2 * np.pi, 721), "N").position
    return assembly_view(outcome.assembly, angle, paths=[(tip, "tip path N (relative)")],
                         soil_level=values["metrics"].events.soil_level,
                         title=f"Solids at carrier angle {np.degrees(angle):g} deg (front view)")
