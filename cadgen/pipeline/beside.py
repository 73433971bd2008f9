"""The worker forked beside the teeth: the sweeps on a gearless assembly, and the figures that
show no gear, while the building process cuts the gears.

On a machine with a second core and the fork start method, :func:`start_beside` forks one
worker when the teeth stage begins. The worker inherits every value computed so far (nothing
is pickled on the way in), builds and meshes the gearless parts (the assembly module's
``GEARLESS_KINDS``; whenever parts follow, even in a scene without sweeps or figures) and
sends their meshes back at once, runs the FCL sweeps on them, then draws figures that show
no gear; its results come back pickled (meshes, sweep records and values, PNG bytes). The
building process cuts the teeth, builds the parts with the gears, takes the worker's meshes
(drawing gear pairs' figures while they are not there yet) for the assembly view and the
solids' files (:func:`plots_beside`), then shares the rest: the worker's gearless figures and
the gear pairs' are taken one at a time from counters both processes hold, whoever is free
first, so neither waits on the other's last figures; then it collects the worker's results
(:func:`collect`). What is computed is the same either way, file for file
(tests/test_beside.py); its progress events are relayed through a pipe
(:class:`cadgen.pipeline.progress.StageProgress`), marked ``beside``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from cadgen.pipeline.build import (STAGE_NEEDS, SWEEP_STAGES, StageRecord, _gearless_parts,
                                   _run_stage)

__all__ = ["gearless_kinds", "start_beside", "collect", "plots_beside"]


_BESIDE: dict = {}


def gearless_kinds(mechanism: str) -> frozenset:
    """The part kinds a mechanism's assembly builds the same with or without the gears (its
    solids module's ``GEARLESS_KINDS``): the worker's meshes of these are the build's."""
    from importlib import import_module

    return import_module(f"cadgen.solids.{mechanism}").GEARLESS_KINDS


@dataclass
class _Beside:
    """The forked worker's tasks (its gearless parts' meshes, its sweeps, its figures, then
    the gear pairs' figures from data sent after the teeth) and the sweep stages it runs."""

    executor: object        # the one worker's (its tasks run in order)
    meshes: object          # future: {part name: (vertices, faces)} of the gearless parts
    solids: object          # future: {"stages": {stage: (record, value)}} of the sweeps
    figures: object         # future: {"figures": ..., "seconds": ...}
    sweeps: tuple
    taken: object           # shared counter: the next gear pair's figure to draw, either side
    figure_pool: object     # shared counter: the next gearless figure to draw, either side
    pool_key: object        # shared: the worker's list of those figures (its crc32), -1 before
    pairs: object = None    # future of the last task: {"figures": ..., "seconds": ...}

    def finish(self, pairs: dict | None = None):
        """Send the last task (the pairs' figures to draw, or none): it closes the worker's
        progress pipe, and the worker ends after it."""
        from cadgen.processes import sigint_deferred

        if self.pairs is None:
            with sigint_deferred():   # the task queued whole (see start_beside)
                self.pairs = self.executor.submit(_beside_pairs, pairs or {})
            self.executor.shutdown(wait=False)
        return self.pairs

    def stop(self) -> None:
        """Abandon the worker (the build was interrupted, or failed): kill it now, rather
        than let it finish its tasks while the interrupted build ends, or hold up the
        process's exit (whose pool thread waits for them)."""
        from cadgen.processes import stop_pool

        stop_pool(self.executor)

    def done(self) -> bool:
        return self.pairs is not None and self.pairs.done()


def _shows_gears(figure: str) -> bool:
    """A figure that shows the gears, cut after the fork: the gear pairs' are drawn by the
    worker from data sent to it; the assembly view, which needs every part's mesh, here.
    The dynamics' figures too: the dynamics run after the fork (on the solids' masses), so
    only this process has them."""
    return figure == "assembly.png" or figure.startswith(("gears-", "dynamics-"))


def start_beside(run, functions):
    """Fork the worker beside the teeth (sweeps and gearless figures), or None: nothing for it
    to do, no second core, no fork, the build told not to (``parallel=False``), or a failed
    stage before."""
    import multiprocessing

    from cadgen.pipeline.figures import _can_fork

    # every sweep holds the housings, the one swept kind the gears may change (the shafts'
    # spin is bounded whatever their keyseats' angle)
    sweeps = tuple(s for s in SWEEP_STAGES if s in run.stages
                   and "housing" in gearless_kinds(run.params.mechanism))
    figures = "plots" in run.stages
    # the gearless parts are meshed there whenever parts follow: a scene of solids without
    # sweeps or figures once left the second core idle and took longer than one with them
    parts = "parts" in run.stages and bool(gearless_kinds(run.params.mechanism))
    if not (sweeps or figures or parts) or "teeth" not in run.stages \
            or run.parallel is False or not _can_fork() \
            or any(r.status != "ok" for r in run.records):
        return None
    from cadgen.processes import process_pool, sigint_deferred

    # what both processes need, imported once before the fork: this process needs it anyway
    # (its parts, its gear figures), so only the worker's time is saved
    if "parts" in run.stages:
        import importlib

        importlib.import_module("trimesh")   # a third of a second (scipy.spatial, networkx)
    if figures:
        from cadgen.pipeline.figures import preload

        preload()
    ends = run.progress.pipe()
    context = multiprocessing.get_context("fork")
    taken, pool, pool_key = context.Value("i", 0), context.Value("i", 0), context.Value("q", -1)
    _BESIDE.update(run=run, functions=functions, sweeps=sweeps, figures=figures, parts=parts,
                   events=ends[1] if ends else None, taken=taken, pool=pool, pool_key=pool_key)
    try:
        # started and queued whole, interrupts held back: a worker started but not yet known
        # to its pool (or a task half queued) left the pool's thread waiting for ever, and
        # the process's exit with it; the worker dies with this thread (see process_pool)
        with sigint_deferred():
            executor = process_pool(1, context)
            meshes = executor.submit(_beside_parts)     # forks the worker here
            solids = executor.submit(_beside_sweeps)    # the same worker, tasks in order
            figures = executor.submit(_beside_figures)
            # the run holds it from here: stopped if the build is interrupted (Run.run)
            run._beside = _Beside(executor, meshes, solids, figures, sweeps, taken, pool,
                                  pool_key)
    finally:
        _BESIDE.clear()             # the forked worker has its own copy
        if ends:
            run.progress.relay(ends[0])
            ends[1].close()         # the worker's copy is the last: its end is the relay's
    return run._beside


def _beside_parts() -> dict:
    """In the forked worker, first: the gearless parts, every one meshed (the sweeps need
    most; the building process all, for the assembly view and the solids' files), sent back
    before the sweeps; made whenever parts follow the teeth, sweeps or not.
    ``{part name: (vertices, faces)}``, empty if the parts failed (their record is then the
    worker's, and the sweeps are skipped).
    """
    run, events, progress = _BESIDE["run"], _BESIDE.get("events"), _BESIDE["run"].progress
    if events is not None:
        progress.forward(events)
    if not _BESIDE["parts"]:
        return {}
    try:
        progress.started("parts", detail="the gearless ones, beside the teeth", beside=True)
        start = time.perf_counter()
        record, parts = _run_stage(run, "parts", {"parts": _gearless_parts})
        meshes = {}
        if record.status == "ok":
            kinds = gearless_kinds(run.params.mechanism)
            # meshed within the stage's time: the sweeps would mesh most of them anyway
            meshes = {part.name: (part.mesh.vertices, part.mesh.faces)
                      for part in parts.assembly.parts if part.kind in kinds}
            record.seconds = time.perf_counter() - start
            if _BESIDE["sweeps"]:
                # the sweeps run on them, and the housing figures drawn here show them: only
                # where the housings are gearless (else this side's housings are not the
                # build's: the pricking gear case is drawn round the gears)
                run.values["parts"] = parts
                run.records.append(record)
        _BESIDE["parts_record"] = record
        progress.finished("parts", record.status, record.seconds,
                          detail=record.message or "the gearless ones, beside the teeth",
                          beside=True)
        return meshes
    except BaseException:
        _BESIDE["failed"] = True    # the next tasks compute nothing
        raise


def _beside_sweeps() -> dict:
    """In the forked worker, second: each sweep on the gearless parts.
    ``{"stages": {stage: (record, value)}}``."""
    run, functions, sweeps = _BESIDE["run"], _BESIDE["functions"], _BESIDE["sweeps"]
    progress, parts_record = run.progress, _BESIDE.get("parts_record")
    if _BESIDE.get("failed"):
        return {"stages": {}}       # the parts' exception is the one collected
    try:
        out = {}
        for stage in sweeps:
            if parts_record.status != "ok":
                record = StageRecord(stage, "skipped",
                                     message="needs parts, which did not complete")
                progress.finished(stage, "skipped", 0.0, detail=record.message, beside=True)
                out[stage] = (record, None)
                continue
            progress.started(stage, beside=True)
            record, value = _run_stage(run, stage, functions)
            record.message = record.message or "ran beside the teeth, in a second process"
            progress.finished(stage, record.status, record.seconds, detail=record.message,
                              beside=True)
            out[stage] = (record, value)
            run.records.append(record)
            if record.status == "ok":
                run.values[stage] = value
        return {"stages": out}
    except BaseException:
        _BESIDE["failed"] = True
        raise


def _beside_figures() -> dict:
    """In the forked worker, second: the figures that show no gear, the pooled ones
    (:func:`pooled_figures`) taken one at a time with the building process, which joins in
    once its own parts and assembly view are done; then the clearance figure (only this side
    has the sweeps). ``{"figures": {name: PNG bytes}, "seconds": float}``.
    """
    run, progress = _BESIDE["run"], _BESIDE["run"].progress
    if _BESIDE.get("failed"):
        return {"figures": {}, "seconds": 0.0}
    try:
        figures, start = {}, time.perf_counter()
        if "plots" in run.stages:
            from cadgen.pipeline.figures import figure_jobs

            jobs = {name: draw for name, draw in figure_jobs(run).items()
                    if not _shows_gears(name)}
            # how many this side draws is known only at the end (steps 0: not known)
            progress.started("plots", detail="figures", beside=True)
            pooled = pooled_figures(jobs)
            _BESIDE["pool_key"].value = _list_key(pooled)
            figures = _draw_from(_BESIDE["pool"], pooled, lambda name: jobs[name](),
                                 lambda name: progress.step("plots", name, steps=0, beside=True))
            for name in jobs.keys() - set(pooled):
                figures[name] = jobs[name]()
                progress.step("plots", name, steps=0, beside=True)
        _BESIDE["drawn"] = time.perf_counter() - start
        return {"figures": figures, "seconds": time.perf_counter() - start}
    except BaseException:
        _BESIDE["failed"] = True
        _BESIDE["pool_key"].value = -1     # the building process draws what is left
        raise


#: Drawing time of the gearless figures that take longest (CPU seconds, paper design): they
#: go first in the pool, so the short ones even out the two processes' ends.
_SLOW_FIGURES = {"cam-follower.png": 0.11, "housing-gearbox1.png": 0.11,
                 "housing-gearbox2.png": 0.10}


def pooled_figures(jobs) -> list:
    """The gearless figures either process may draw, slowest first: every figure of
    ``jobs`` but the gear pairs', the assembly view and the clearance figure (the sweeps'
    results are the worker's until collected). Both processes list them from their own
    runs; they share the pool only when the lists agree (:func:`_list_key`)."""
    names = [name for name in jobs if not _shows_gears(name) and name != "clearance.png"]
    return sorted(names, key=lambda name: -_SLOW_FIGURES.get(name, 0.0))


def _list_key(names) -> int:
    """A number naming a list of figures (crc32 of the names, in order)."""
    import zlib

    return zlib.crc32("\n".join(names).encode())


def _draw_pooled(run, beside, drawn) -> dict:
    """Here, the pooled figures the worker has not taken yet, when it has listed the same
    figures as this process (else none: the worker draws them all)."""
    from cadgen.pipeline.figures import figure_jobs

    jobs = figure_jobs(run)
    pooled = pooled_figures(jobs)
    if not pooled or beside.pool_key.value != _list_key(pooled):
        return {}
    return _draw_from(beside.figure_pool, pooled, lambda name: jobs[name](), drawn)


def _beside_pairs(pairs: dict) -> dict:
    """In the forked worker, last: the gear pairs' figures from their data
    (:func:`cadgen.report.plots.parts.pair_figure_data`, sent after the teeth); then the
    progress pipe is closed. ``{"figures": {name: PNG bytes}, "seconds": float}``."""
    run, events = _BESIDE["run"], _BESIDE.get("events")
    progress = run.progress
    try:
        figures, start = {}, time.perf_counter()
        if "plots" in run.stages and not _BESIDE.get("failed"):
            seconds = _BESIDE.get("drawn", 0.0)   # its figures before these
            # how many this side draws is known only at the end (steps 0: not known)
            figures = _draw_taken(pairs, _BESIDE["taken"], lambda name: progress.step(
                "plots", name, steps=0, beside=True))
            progress.finished("plots", "ok", time.perf_counter() - start + seconds,
                              detail="figures", beside=True)
        return {"figures": figures, "seconds": time.perf_counter() - start}
    finally:
        if events is not None:
            events.close()          # the relay's end of file


def take_meshes(run, beside) -> int:
    """Give this build's parts the worker's meshes of the same parts (:func:`gearless_kinds`)
    where this process has not made them: the same triangles, not made twice. Waits for the
    worker's first task (it meshes them first of all). Returns how many were taken."""
    if run.status("parts") != "ok":
        return 0
    meshes = beside.meshes.result()
    if not meshes:
        return 0
    from cadgen.solids.extrude import part_mesh

    kinds = gearless_kinds(run.params.mechanism)
    taken = 0
    for part in run.values["parts"].assembly.parts:
        if part.kind in kinds and part._mesh is None and part.name in meshes:
            part._mesh = part_mesh(*meshes[part.name], part.name)   # checked in the worker
            taken += 1
    return taken


def _draw_taken(pairs: dict, counter, drawn, until=None) -> dict:
    """The gear pairs' figures neither process has taken yet (:func:`_draw_from`)."""
    from cadgen.report.plots.parts import draw_pair_figure

    return _draw_from(counter, list(pairs), lambda name: draw_pair_figure(pairs[name]), drawn,
                      until)


def _draw_from(counter, names: list, draw, drawn, until=None) -> dict:
    """Draw the figures of ``names`` that neither process has taken yet, taking them one at a
    time from ``counter`` (shared by both): ``draw(name)`` makes one's PNG, ``drawn(name)`` is
    called after each; none more once ``until()`` is true. Returns ``{name: PNG bytes}`` of
    those drawn here."""
    figures = {}
    while not (until is not None and until()) \
            and (index := _take(counter, len(names))) is not None:
        figures[names[index]] = draw(names[index])
        drawn(names[index])
    return figures


def _take(counter, count: int):
    """The next index below ``count`` from a counter both processes share, or None."""
    with counter.get_lock():
        index = counter.value
        if index >= count:
            return None
        counter.value = index + 1
    return index


def collect(run, beside) -> dict:
    """The worker's results: its sweep stages recorded here (as if run here), its figures."""
    beside.finish()
    last = beside.pairs.result()
    take_meshes(run, beside)    # first: the worker's first task's exception, if it raised
    outcome = {**beside.solids.result(), **beside.figures.result()}
    outcome["figures"] = {**outcome["figures"], **last["figures"]}
    outcome["seconds"] += last["seconds"]
    run.progress.join()         # the worker's events, all delivered
    for stage in beside.sweeps:
        failed = [need for need in STAGE_NEEDS[stage] if run.status(need) != "ok"]
        if failed:
            record, value = StageRecord(stage, "skipped", message=(
                f"needs {', '.join(failed)}, which did not complete")), None
        else:
            record, value = outcome["stages"][stage]
        if stage not in run.progress.finished_stages():   # the worker said nothing
            run.progress.finished(stage, record.status, record.seconds,
                                  detail=record.message, beside=True)
        run.records.append(record)
        if record.status == "ok":
            run.values[stage] = value
    return outcome


def plots_beside(run, beside):
    """Stage ``plots`` with the worker: draw the figures that show gears here, then take the
    worker's (and its sweeps); one record, the two processes' drawing times added."""
    from cadgen.pipeline.figures import figure_jobs

    start = time.perf_counter()
    pairs = {}
    if run.status("teeth") == "ok" and run.values["teeth"].stages:
        from cadgen.report.plots.parts import pair_figure_datas

        pairs = pair_figure_datas(run.values["teeth"])
    beside.finish(pairs)        # the worker draws them after its own figures
    jobs = {name: draw for name, draw in figure_jobs(run).items()
            if _shows_gears(name) and name not in pairs}
    run.progress.started("plots")
    step = lambda name: run.progress.step("plots", name)   # noqa: E731
    # the assembly view and the solids' files need every part's mesh: the gearless ones are
    # the worker's first task (it meshes them for its sweeps); the gear pairs' figures until
    # they are here
    mine = _draw_taken(pairs, beside.taken, step, until=beside.meshes.done)
    take_meshes(run, beside)
    for name, draw in jobs.items():
        mine[name] = draw()
        step(name)
    seconds = time.perf_counter() - start
    # first what only this process can make for the writing (the solids' report and files,
    # the gear files), while the worker draws; then the figures either side may draw, so
    # that both end together, and the writing after has little left to do
    from cadgen.pipeline.writers import prepare

    prepare(run)
    begun = time.perf_counter()
    mine.update(_draw_pooled(run, beside, step))
    mine.update(_draw_taken(pairs, beside.taken, step))   # the pairs' the worker has not taken
    seconds += time.perf_counter() - begun
    outcome = collect(run, beside)
    theirs = outcome["figures"]
    every = figure_jobs(run)     # now with the sweeps' figure
    # any figure the worker could not draw (its gearless parts failed): drawn here
    for name, draw in every.items():
        if name not in mine and name not in theirs:
            begun = time.perf_counter()
            mine[name] = draw()
            seconds += time.perf_counter() - begun
            run.progress.step("plots", name)
    figures = {**mine, **theirs}
    run.figures = {name: figures[name] for name in every if name in figures}
    # the stage's time: both processes' drawing (the work), each said in the message
    record = StageRecord("plots", "ok", seconds + outcome["seconds"],
                         f"{len(theirs)} of {len(run.figures)} figures drawn beside the teeth, "
                         f"in a second process ({seconds:.2f} s here, "
                         f"{outcome['seconds']:.2f} s there)")
    run.progress.finished("plots", "ok", record.seconds, detail=record.message)
    return record, run.figures
