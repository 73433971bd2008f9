"""A whole batch (:func:`run_batch`): local processes or a Dask cluster."""

from __future__ import annotations

import contextlib
import gc
import math
import os
import pickle
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path

from cadgen.batch.grid import DesignJob
from cadgen.batch.isolated import _clean_staging, run_design_isolated
from cadgen.batch.single import (DEFAULT_BUILD, Build, _exception_failure, _is_default_build,
                                 _summary, run_design)
from cadgen.batch.summary import _order
from cadgen.processes import sigint_deferred

__all__ = ["run_batch"]


#: A local worker's state (see :func:`_worker_start`): its interrupt handler, whether it runs a
#: design, the queue on which it says which design it starts (read by the batch's
#: process, see :func:`_run_local`), the batch's process (its parent) and whether that
#: has died.
_WORKER = {"interrupts": None, "busy": False, "starts": None, "parent": None,
           "orphaned": False}
#: Seconds between looks at the local workers' starts while waiting for results.
_START_POLL_SECONDS = 0.1
#: What a worker tells on the starts queue, instead of a design's number, once its handler
#: is in place: before that it holds no design and may be killed outright (_stop_workers).
_READY = -1


def _worker_start(starts=None, parent: int | None = None) -> None:
    """Initializer of a local worker: Ctrl-C stops its design, cleanly, without a traceback.

    The terminal sends SIGINT to the whole process group, the workers included, and the
    batch's process passes an interrupt on to its workers (one sent to it alone stops
    them too). A busy worker raises KeyboardInterrupt in its job (which kills its
    design's process group and removes its staging folder, see
    :func:`run_design_isolated`), raised again if a library swallowed it
    (:class:`cadgen.processes.Interrupts`); an idle one only remembers it and starts no
    further design (a design already queued to it is refused); a process forked from
    the worker ends quietly. The batch's own process reports the interrupt once. The
    worker was started with SIGINT blocked (:func:`cadgen.processes.sigint_deferred`): a
    Ctrl-C that came while it was still importing waits for this handler, and is handled
    as soon as it is unblocked here. SIGTERM and SIGHUP are taken as SIGINT.

    The worker dies with the batch's process ``parent``: it is sent SIGTERM when that
    ends, however (:func:`cadgen.processes.process_pool`), and then ends at once if idle;
    if busy, it stops its design as on Ctrl-C (its process group killed, its staging
    folder removed) and then ends (:func:`_orphan_check`).
    """
    from cadgen.processes import Interrupts, release_deferred_sigint

    _WORKER["starts"] = starts
    _WORKER["parent"] = parent
    _WORKER["interrupts"] = Interrupts(active=lambda: _WORKER["busy"],
                                       on_signal=_orphan_check).install()
    release_deferred_sigint()
    if starts is not None:   # (after the release: an interrupt that came is taken by now)
        starts.put((os.getpid(), _READY))


def _orphan_check(signum: int) -> None:
    """In a worker's interrupt handler: has the batch's process died (the signal is its
    parent-death signal, or came after)? Then an idle worker ends now; a busy one is
    interrupted (its design stopped and cleaned up), ends after (:func:`_run_job`), and is
    killed if that takes longer than :data:`cadgen.processes.ORPHAN_GRACE_SECONDS`."""
    from cadgen.processes import EXIT_ORPHANED, end_after, orphaned

    parent = _WORKER["parent"]
    if parent is None or not orphaned(parent) or _WORKER["orphaned"]:
        return
    if not _WORKER["busy"]:
        os._exit(EXIT_ORPHANED)
    _WORKER["orphaned"] = True
    end_after()


def _interrupted() -> bool:
    interrupts = _WORKER["interrupts"]
    return interrupts is not None and interrupts.seen


def _run_job(job, output_root, build, build_kwargs, timeout, isolate, number=None) -> dict:
    """What a worker runs for one design (the ``number``-th submitted, told on starting)."""
    if _interrupted():
        raise KeyboardInterrupt(f"interrupted before {job.name} started")
    _WORKER["busy"] = True
    if _WORKER["starts"] is not None and number is not None:
        _WORKER["starts"].put((os.getpid(), number))   # SimpleQueue: at once, no feeder thread
    try:
        if isolate:
            return run_design_isolated(job, output_root, build, build_kwargs, timeout)
        return run_design(job, output_root, build, build_kwargs)
    finally:
        _WORKER["busy"] = False
        if _WORKER["orphaned"]:   # its design stopped and cleaned: nobody waits for more
            from cadgen.processes import EXIT_ORPHANED

            os._exit(EXIT_ORPHANED)


# --------------------------------------------------------------------------- executors


def _collect(futures: Mapping, finished: Iterable, on_result) -> list[dict]:
    """Summaries of ``futures`` (future -> job) in the order ``finished`` yields them."""
    summaries = []
    for future in finished:
        try:
            with sigint_deferred():   # (the future's lock: see _completed)
                summary = future.result()
        except Exception as exc:  # the job did not return: BrokenProcessPool, KilledWorker
            summary = _summary(futures[future], time.perf_counter(),
                               failure=_exception_failure(exc, "worker_error"))
        if hasattr(future, "release"):
            future.release()  # Dask: let the cluster forget the result
        summaries.append(summary)
        if on_result is not None:
            on_result(summary)
    return summaries


def _completed(futures, submitted, starts, on_start, ready: set):
    """``futures`` as they complete; meanwhile ``on_start(name)`` (if given) for each design
    a worker starts (told on ``starts`` as ``(worker pid, number submitted)``), and the pid
    of each worker that tells it is ready added to ``ready``.

    In the order things happened: a design's start before its result, and the result of
    the design a worker ran before the start of its next (a worker tells a start only
    after returning its previous result, which may still be on its way here: it is waited
    for, briefly, so the line never shows a worker running two designs).
    """
    from concurrent.futures import FIRST_COMPLETED, wait

    pending, told = set(futures), set()
    running = {}    # worker pid -> the future of the design it runs
    while pending:
        # Ctrl-C is held back while this thread holds the pool's locks: wait() takes every
        # pending future's lock in a loop, and an interrupt raised halfway through leaves
        # some held for good (the pool's manager thread then blocks on one, and so does the
        # interpreter's exit, which joins it); the interrupt comes as the block ends
        with sigint_deferred():
            done, pending = wait(pending, timeout=_START_POLL_SECONDS,
                                 return_when=FIRST_COMPLETED)
            started = _drain(starts, ready)
        for pid, number in started:
            previous = running.get(pid)
            if previous is not None and previous not in told:
                with sigint_deferred():
                    wait([previous])
                pending.discard(previous)
                done.discard(previous)
                told.add(previous)
                yield previous
            running[pid] = submitted[number]
            if on_start is not None:
                on_start(futures[submitted[number]].name)
        for future in done:
            told.add(future)
            yield future


def _drain(starts, ready: set) -> list[tuple[int, int]]:
    """The ``(worker pid, design number)`` starts told on ``starts`` since last asked; each
    worker that tells it is ready is added to ``ready`` instead."""
    started = []
    while not starts.empty():
        pid, number = starts.get()
        if number == _READY:
            ready.add(pid)
        else:
            started.append((pid, number))
    return started


def _run_local(jobs, output_root, task, workers, on_result, on_start=None):
    import multiprocessing
    import signal

    from cadgen.processes import process_pool

    # spawn: one start method on every platform, safe when the parent holds threads (a
    # Dask client); each worker pays its imports once and forks each design from there.
    context = multiprocessing.get_context("spawn")
    if os.name == "posix":
        from multiprocessing import resource_tracker

        # started first: starting it unblocks SIGINT in this thread (its own guard), which
        # would end the block below as soon as the pool made its first semaphore
        resource_tracker.ensure_running()
    pool, starts, futures, submitted, ready = None, None, {}, [], set()
    try:
        # the workers are started by submit(), with SIGINT held back until their handler is in
        # place (a Ctrl-C while one still imports would print its traceback), and the pool's
        # semaphores made whole (one half made would leak); this process's own Ctrl-C is
        # delivered as the block ends
        with sigint_deferred():
            starts = context.SimpleQueue()
            # each worker dies with this process (SIGTERM: it stops its design and removes
            # its staging folder first, see _worker_start)
            pool = process_pool(max(1, min(workers, len(jobs))), context,
                                initializer=_worker_start, initargs=(starts, os.getpid()),
                                death_signal=signal.SIGTERM)
            for number, job in enumerate(jobs):
                submitted.append(pool.submit(_run_job, job, output_root, *task, number=number))
                futures[submitted[-1]] = job
        summaries = _collect(futures, _completed(futures, submitted, starts, on_start, ready),
                             on_result)
    except BaseException:
        # Cancelled here, not only through shutdown(cancel_futures=True): the pool's
        # manager thread cancels through a weak reference to the pool, which may be gone
        # by the time it looks, and then every queued design would still be built.
        for future in futures:
            future.cancel()
        if pool is not None:
            _stop_workers(pool, starts, ready)
        # The pool's semaphores are finalised here, in an except clause, where no interrupt
        # is raised again (cadgen.processes.Interrupts), not as the exception leaves this
        # frame: a repeated interrupt landing between a semaphore's unlinking and its
        # unregistering made the resource tracker warn of a leak at exit.
        pool = starts = None
        gc.collect()
        raise
    pool.shutdown()
    return summaries


#: Seconds the local workers have, once interrupted, to stop their designs and end.
_STOP_GRACE_SECONDS = 5.0


def _stop_workers(pool, starts, ready: set, grace: float = _STOP_GRACE_SECONDS) -> None:
    """Interrupt every worker of ``pool`` and wait for it to end (SIGKILL after ``grace``).

    A busy worker kills its design's process group and removes its staging folder (see
    :func:`_worker_start`); an idle one ends with the pool. A worker that has not told
    ``starts`` it is ready (still importing, SIGINT held back) holds no design and never
    will (it takes the interrupt sent here before it tells), so it is killed at once
    rather than waited for. Waiting for the others means none is left unpickling its
    pool's semaphores after this process has removed them (which printed a
    FileNotFoundError traceback from each and broke the pool), and every child is reaped.
    """
    import signal

    processes = list((getattr(pool, "_processes", None) or {}).values())
    for process in processes:
        with contextlib.suppress(OSError, ValueError):
            os.kill(process.pid, signal.SIGINT)
    with contextlib.suppress(OSError, EOFError, ValueError):
        _drain(starts, ready)
    for process in processes:
        if process.pid not in ready:
            with contextlib.suppress(OSError, ValueError):
                process.kill()
    pool.shutdown(wait=False, cancel_futures=True)
    deadline = time.monotonic() + grace
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AssertionError):
            process.join(max(0.0, deadline - time.monotonic()))
            if process.exitcode is None:
                process.kill()   # its design's process sees the lifeline end and kills its group
                process.join()


def _run_dask(jobs, output_root, task, scheduler, on_result):
    import uuid

    try:
        from dask.distributed import Client, as_completed as dask_completed
    except ImportError:
        raise ImportError("a Dask scheduler needs dask.distributed: "
                          "pip install 'cadgen[dask]'") from None
    batch = uuid.uuid4().hex[:8]  # keys unique across batches sharing a cluster
    with Client(scheduler) as client:
        futures = {client.submit(_run_job, job, output_root, *task,
                                 key=f"cadgen-{job.name}-{batch}-{number}", pure=False): job
                   for number, job in enumerate(jobs)}
        try:
            return _collect(futures, dask_completed(list(futures)), on_result)
        except BaseException:
            client.cancel(list(futures))
            raise


def run_batch(jobs: Sequence[DesignJob], output_root: str | os.PathLike = "outputs", *,
              workers: int | None = None, scheduler: str | None = None,
              build: Build | None = None, build_kwargs: Mapping | None = None,
              on_result: Callable[[dict], None] | None = None, timeout: float | None = None,
              isolate: bool = True,
              on_start: Callable[[str], None] | None = None) -> list[dict]:
    """Build every design, in local processes or on a Dask cluster.

    Parameters
    ----------
    jobs : sequence of DesignJob
        Pass them through :func:`guard_names` first if names may repeat.
    output_root : str or path-like, default "outputs"
        Made absolute here, so workers with another working directory write the same
        folders. On a Dask cluster of several machines it must be a shared filesystem
        (and so must the parameter files).
    workers : int, optional
        Local worker processes (default ``os.cpu_count()``); ignored with a scheduler.
    scheduler : str, optional
        A Dask scheduler address (``tcp://host:8786``): one ``client.submit`` per design.
        Needs ``dask[distributed]`` here and ``cadgen`` installed on the workers.
    build : callable or str, optional
        See :func:`run_design`. A callable must pickle by reference (a module-level
        function) for local processes; Dask's cloudpickle also takes closures.
    build_kwargs : mapping, optional
        Extra keyword arguments of the build. With the default build, local processes and a
        design on every core (``workers`` and the designs at least the cores), each build
        runs in its one process (``parallel=False`` unless given here).
    on_result : callable, optional
        Called with each summary as its design finishes (in finishing order).
    on_start : callable, optional
        Local processes: called with a design's name when a worker starts it (in this
        process and thread, as on_result; a start is told before that design's result,
        within 0.1 s of it). Not called on a Dask cluster, whose tasks do not say when
        they start.
    timeout : float, optional
        Seconds each design may take (in its own process, start included): a design
        still running then is killed and reported with code ``timeout``.
    isolate : bool, default True
        Each design in a process of its own (:func:`run_design_isolated`): a design
        that crashes it costs only itself (``worker_died``). False runs each design in
        the worker itself (saves the process, see the package docstring; no timeout; a
        crash takes the worker and, locally, every unfinished design).

    Returns
    -------
    list of dict
        One summary per job (see :func:`run_design`), ordered by name, then source.

    Raises
    ------
    ValueError
        A timeout that is not a positive number, or one without ``isolate``.

    Notes
    -----
    Local workers are spawned, not forked (safe beside a Dask client's threads), so a
    script calling this needs ``if __name__ == "__main__":``. When every design is done,
    staging folders of these designs' names left under ``output_root`` are removed.
    Interrupted (Ctrl-C), local workers kill their designs' processes; a Dask cluster
    cannot stop tasks already running, so those designs finish (within their time limit).
    """
    if timeout is not None and not (isinstance(timeout, (int, float)) and 0 < timeout < math.inf):
        raise ValueError(f"timeout must be a positive number of seconds, not {timeout!r}")
    if timeout is not None and not isolate:
        raise ValueError("a timeout needs each design in its own process (isolate=True)")
    if not jobs:
        return []
    root = str(Path(output_root).resolve())
    build = DEFAULT_BUILD if build is None else build
    if not scheduler:
        try:
            pickle.dumps(build)
        except Exception as exc:
            raise TypeError(f"the build {build!r} cannot be sent to worker processes ({exc}); "
                            "give a module-level function or 'module:function'") from None
    build_kwargs = dict(build_kwargs or {})
    workers = workers or os.cpu_count() or 1
    if not scheduler and _is_default_build(build) \
            and min(workers, len(jobs)) >= (os.cpu_count() or 1):
        # a design on every core: a build's own worker beside its teeth (the second core's
        # use for one design) would only take time from the others (measured, 12 designs of
        # the paper's on 2 cores, imports warmed: 18.2 -> 16.6 s, the same files)
        build_kwargs.setdefault("parallel", False)
    task = (build, build_kwargs, timeout, bool(isolate))
    try:
        if scheduler:
            summaries = _run_dask(jobs, root, task, scheduler, on_result)
        else:
            summaries = _run_local(jobs, root, task, workers, on_result, on_start)
    finally:   # interrupted too: what a killed design left
        _clean_staging(root, {job.name for job in jobs})
    return sorted(summaries, key=_order)
