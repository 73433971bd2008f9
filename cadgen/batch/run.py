"""Running designs: one design (:func:`run_design`), in a process of its own with a time
limit (:func:`run_design_isolated`), and a whole batch (:func:`run_batch`) in local
processes or on a Dask cluster. See the package docstring for how faults are reported.
"""

from __future__ import annotations

import contextlib
import importlib
import math
import numbers
import os
import pickle
import re
import shutil
import signal
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from kinematics.errors import DesignError, MechanismError

from .grid import DesignJob
from .summary import _order

__all__ = ["DEFAULT_BUILD", "run_design", "run_design_isolated", "run_batch"]

DEFAULT_BUILD = "cadgen.build:build"
"""The build each design runs unless told otherwise: ``"module:function"``, called as
``build(params, output_root=Path, **build_kwargs)``; it returns an object with
``report`` (dict) and ``output_dir`` (and optionally ``files``), or the report dict."""

_TRACEBACK_LINES = 30
_ORPHANED = 70  # exit code of a design's process whose job went away (see _watch_lifeline)

Build = Callable[..., Any] | str


# --------------------------------------------------------------------------- one design


def _resolve_build(build: Build | None) -> Callable[..., Any]:
    build = DEFAULT_BUILD if build is None else build
    if callable(build):
        return build
    module, _, name = str(build).partition(":")
    if not module or not name:
        raise ValueError(f"build must be a callable or 'module:function', not {build!r}")
    return getattr(importlib.import_module(module), name)


def _snake(name: str) -> str:
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def _number(value: Any) -> float | int | None:
    """A plain Python number (numpy scalars would print as ``np.float64(...)``)."""
    if value is None:
        return None
    return int(value) if isinstance(value, numbers.Integral) else float(value)


def _flag(value: Any) -> bool | None:
    return None if value is None else bool(value)


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
        exception), ``files`` (written, relative to ``output_dir``), ``seconds`` and
        ``output_dir`` (str or None).
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
                    output_dir=None if output_dir is None else str(output_dir))


# --------------------------------------------------------------------------- a process per design

#: What cadgen.atomic.staged_directory leaves beside ``<name>`` if its process is killed:
#: ``.<name>.staging-XXXXXXXX`` (outputs being written) and ``.<name>.old-XXXXXXXX`` (the
#: previous outputs, set aside for the swap). The suffix is tempfile.mkdtemp's.
_STAGED = re.compile(r"\.(?P<name>.+)\.(?P<kind>staging|old)-[a-z0-9_]{8}")


def _clean_staging(output_root: str | os.PathLike, names: Iterable[str]) -> list[str]:
    """Remove what killed builds of ``names`` left under ``output_root``; the names removed.

    A staging folder is deleted. A set-aside previous folder is put back if the kill came
    between the swap's two renames (``<name>`` missing), else deleted. Nothing else is
    touched: other designs' folders and staging, files, other names.
    """
    wanted = set(names)
    try:
        entries = sorted(os.scandir(output_root), key=lambda entry: entry.name)
    except OSError:
        return []
    removed = []
    for entry in entries:
        match = _STAGED.fullmatch(entry.name)
        if not match or match["name"] not in wanted or not entry.is_dir(follow_symlinks=False):
            continue
        if match["kind"] == "old":
            final = Path(output_root) / match["name"]
            kept = Path(entry.path) / match["name"]
            if kept.is_dir() and not os.path.lexists(final):
                with contextlib.suppress(OSError):
                    os.replace(kept, final)
        shutil.rmtree(entry.path, ignore_errors=True)
        removed.append(entry.name)
    return removed


def _put_result(path: str, outcome: tuple) -> None:
    """In the design's process: leave ``outcome`` for its job (renamed in: never half read)."""
    with open(path + ".tmp", "wb") as stream:
        pickle.dump(outcome, stream, protocol=pickle.HIGHEST_PROTOCOL)
    os.replace(path + ".tmp", path)


def _watch_lifeline(fd: int) -> None:
    """Block on the lifeline pipe; at its end (the job is gone) kill this process's group.

    Only the job holds the pipe's write end and it never writes, so the read returns at
    end-of-file: when the job closes it after this process ended, or when the job's own
    process dies (a killed local worker, a Dask worker restarted). Then the design's
    process and the workers its build forked must not run on unwatched.
    """
    try:
        while os.read(fd, 512):
            pass
    except OSError:
        pass
    if hasattr(os, "killpg") and os.getpgrp() == os.getpid():
        os.killpg(os.getpid(), signal.SIGKILL)
    os._exit(_ORPHANED)


def _child_setup(lifeline: int) -> None:
    """First thing in a design's process: its own process group, a lifeline watcher, and
    Python tracebacks on a segfault (to stderr)."""
    import faulthandler
    import threading
    import warnings

    if hasattr(os, "setsid"):
        with contextlib.suppress(OSError):  # a spawned child is a session leader already
            os.setsid()
    faulthandler.enable()
    # The build forks its own workers with the watcher thread present: it holds no lock
    # (it waits in os.read), so the forked worker is safe; Python 3.12 would warn anyway.
    warnings.filterwarnings("ignore", r".*multi-threaded, use of fork\(\)", DeprecationWarning)
    threading.Thread(target=_watch_lifeline, args=(lifeline,), name="cadgen-lifeline",
                     daemon=True).start()


def _in_child(job, output_root, build, build_kwargs, result_path) -> None:
    start = time.perf_counter()
    try:
        outcome = ("summary", run_design(job, output_root, build, build_kwargs))
    except BaseException as exc:  # SystemExit, KeyboardInterrupt from the build
        outcome = ("summary", _summary(job, start, failure=_exception_failure(exc, "exception")))
    _put_result(result_path, outcome)


def _forked(job, output_root, build, build_kwargs, result_path, lifeline, job_end) -> None:
    """The design's process, forked from its (single-threaded) local worker."""
    os.close(job_end)
    _child_setup(lifeline)
    _in_child(job, output_root, build, build_kwargs, result_path)


#: The spawned design's process: the job's sys.path first (a build given as a function
#: must import as it did there), then the job itself.
_BOOT = ("import pickle, sys\n"
         "with open(sys.argv[1], 'rb') as stream:\n"
         "    sys.path[:] = pickle.load(stream)\n"
         "    from cadgen.batch.run import _spawned\n"
         "    _spawned(stream, sys.argv[2])\n")


def _spawned(stream, result_path: str) -> None:
    """The design's process, a new interpreter (stdin is the lifeline)."""
    _child_setup(0)
    try:
        job, output_root, build, build_kwargs = pickle.load(stream)
    except BaseException as exc:  # e.g. the build's module cannot be imported here
        _put_result(result_path, ("failure", _exception_failure(exc, "worker_error")))
        return
    _in_child(job, output_root, build, build_kwargs, result_path)


def _dumps(value: Any) -> bytes:
    try:
        return pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as exc:
        error = exc
    try:
        import cloudpickle  # Dask's: a closure it shipped goes on to the design's process
    except ImportError:
        raise error from None
    return cloudpickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)


def _can_fork() -> bool:
    """Fork the design's process from this one? Only from a process with a single thread
    that may have children: a local worker, not a Dask worker (threads, daemonic)."""
    import multiprocessing
    import threading

    return ("fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1
            and not multiprocessing.current_process().daemon)


def _warm(build: Build | None) -> None:
    """Import the parameter schema and the build once here, not in every forked design."""
    with contextlib.suppress(Exception):  # the design's process reports it
        import cadgen.params  # noqa: F401
        _resolve_build(build)


class _Child:
    """A design's process as its job sees it: started, waited for with a limit, killed
    with its process group, reaped."""

    def __init__(self, job, output_root, build, build_kwargs, scratch: str):
        self.result = os.path.join(scratch, "result.pickle")
        self.sentinel = None
        lifeline, self.job_end = os.pipe()
        try:
            if _can_fork():
                self._fork(job, output_root, build, build_kwargs, lifeline)
            else:
                self._spawn(job, output_root, build, build_kwargs, lifeline, scratch)
        except BaseException:
            os.close(self.job_end)
            raise
        finally:
            os.close(lifeline)

    def _fork(self, job, output_root, build, build_kwargs, lifeline):
        import multiprocessing

        _warm(build)
        self.process = multiprocessing.get_context("fork").Process(
            target=_forked, name=f"cadgen-{job.name}", daemon=False,
            args=(job, output_root, build, build_kwargs, self.result, lifeline, self.job_end))
        self.process.start()
        self.pid, self.sentinel = self.process.pid, self.process.sentinel

    def _spawn(self, job, output_root, build, build_kwargs, lifeline, scratch):
        import subprocess

        payload = os.path.join(scratch, "job.pickle")
        with open(payload, "wb") as stream:
            pickle.dump(list(sys.path), stream)
            stream.write(_dumps((job, output_root, build, build_kwargs)))
        flags = getattr(subprocess, "_args_from_interpreter_flags", list)()
        group = ({"start_new_session": True} if os.name == "posix" else
                 {"creationflags": getattr(subprocess, "CREATE_NEW_PROCESS_GROUP", 0)})
        self.process = subprocess.Popen([sys.executable, *flags, "-c", _BOOT, payload,
                                         self.result], stdin=lifeline, **group)
        self.pid = self.process.pid
        with contextlib.suppress(AttributeError, OSError):  # Linux 5.3+: exit seen, not reaped
            self.sentinel = os.pidfd_open(self.pid)

    def wait(self, timeout: float | None) -> bool:
        """Wait for the process to end (at most ``timeout`` s); has it?"""
        if self.sentinel is not None:
            from multiprocessing.connection import wait

            return bool(wait([self.sentinel], timeout))
        import subprocess

        try:
            self.process.wait(timeout)  # (reaps it: see kill)
        except subprocess.TimeoutExpired:
            return False
        return True

    def kill(self) -> None:
        """SIGKILL the process group: the design's process and every worker its build forked.

        Called whether or not the process ended, before it is reaped where that can be
        done (a fork, a pidfd), so the group's id cannot have been reused.
        """
        if hasattr(os, "killpg"):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self.pid, signal.SIGKILL)
        with contextlib.suppress(OSError):  # before its setsid (or without killpg)
            self.process.kill()

    def reap(self) -> int:
        """Wait for the (ended or killed) process; its exit code (negative: the signal)."""
        if hasattr(self.process, "exitcode"):
            self.process.join()
            return self.process.exitcode
        return self.process.wait()

    def close(self) -> None:
        os.close(self.job_end)
        if not hasattr(self.process, "exitcode") and self.sentinel is not None:
            os.close(self.sentinel)


def _take_result(path: str) -> tuple | None:
    try:
        with open(path, "rb") as stream:
            return pickle.load(stream)
    except (OSError, EOFError, pickle.UnpicklingError):
        return None


def _death(code: int) -> str:
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = "a signal"
        return f"its process was killed by {name} (signal {-code}) before it gave a result"
    return f"its process exited with code {code} before it gave a result"


def run_design_isolated(job: DesignJob, output_root: str | os.PathLike,
                        build: Build | None = None, build_kwargs: Mapping | None = None,
                        timeout: float | None = None) -> dict:
    """:func:`run_design` in a process of its own, killed if it runs out of time or dies.

    Parameters
    ----------
    job, output_root, build, build_kwargs
        As for :func:`run_design`.
    timeout : float, optional
        Seconds the design's process may run (its start included); no limit if None.

    Returns
    -------
    dict
        The design's summary (see :func:`run_design`), or one whose ``failure`` has
        code ``timeout`` (``failure["timeout"]`` the limit), ``worker_died`` (the process
        ended without a result: a segfault, ``os._exit``, a signal; ``failure["exit_code"]``
        its exit code, negative for a signal) or ``worker_error`` (the process could not
        start, or could not load the job). Never raises for a design's fault.

    Notes
    -----
    From a process with a single thread (a local worker) the design's process is forked:
    cheap, the imports already done. Elsewhere (a Dask worker has threads, and is
    daemonic) it is a new interpreter running ``cadgen.batch.run._spawned``, which costs
    the imports each time. Either way it leads its own process group, so a kill
    (SIGKILL to the group) also takes the workers the build forks, and it watches a pipe
    from its job, so it kills its group if the job's process dies. After a kill or a
    death, the staging folders the build left are removed (the previous outputs, if
    set aside, are put back): ``<output_root>/<name>`` is as it was before.
    """
    start = time.perf_counter()
    scratch = tempfile.mkdtemp(prefix="cadgen-design-")
    child = None
    try:
        child = _Child(job, output_root, build, build_kwargs, scratch)
        finished = child.wait(timeout)
        child.kill()  # on time: whatever the build left running; late: all of it
        code = child.reap()
        outcome = _take_result(child.result)
    except BaseException as exc:  # an interrupt (Ctrl-C), or this machinery failed
        if child is not None:
            child.kill()
            child.reap()
            _clean_staging(output_root, [job.name])
        if not isinstance(exc, Exception):
            raise
        return _summary(job, start, failure=_exception_failure(exc, "worker_error"))
    finally:
        if child is not None:
            child.close()
        shutil.rmtree(scratch, ignore_errors=True)
    if outcome is not None:  # (one that finished as its time ran out keeps its result)
        kind, value = outcome
        return value if kind == "summary" else _summary(job, start, failure=value)
    _clean_staging(output_root, [job.name])
    if not finished:
        return _summary(job, start, failure={
            "code": "timeout", "exception": None, "problems": [], "timeout": timeout,
            "message": f"no result within the time limit of {timeout:g} s: its process was "
                       "killed and its output folder left as it was"})
    return _summary(job, start, failure={
        "code": "worker_died", "message": _death(code), "exception": None, "problems": [],
        "exit_code": code})


def _run_job(job, output_root, build, build_kwargs, timeout, isolate) -> dict:
    """What a worker runs for one design."""
    if isolate:
        return run_design_isolated(job, output_root, build, build_kwargs, timeout)
    return run_design(job, output_root, build, build_kwargs)


# --------------------------------------------------------------------------- executors


def _collect(futures: Mapping, finished: Iterable, on_result) -> list[dict]:
    """Summaries of ``futures`` (future -> job) in the order ``finished`` yields them."""
    summaries = []
    for future in finished:
        try:
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


def _run_local(jobs, output_root, task, workers, on_result):
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # spawn: one start method on every platform, safe when the parent holds threads (a
    # Dask client); each worker pays its imports once and forks each design from there.
    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(max_workers=max(1, min(workers, len(jobs))), mp_context=context)
    try:
        futures = {pool.submit(_run_job, job, output_root, *task): job for job in jobs}
        summaries = _collect(futures, as_completed(futures), on_result)
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    return summaries


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
              isolate: bool = True) -> list[dict]:
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
        Extra keyword arguments of the build.
    on_result : callable, optional
        Called with each summary as its design finishes (in finishing order).
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
    task = (build, dict(build_kwargs or {}), timeout, bool(isolate))
    if scheduler:
        summaries = _run_dask(jobs, root, task, scheduler, on_result)
    else:
        summaries = _run_local(jobs, root, task, workers or os.cpu_count() or 1, on_result)
    _clean_staging(root, {job.name for job in jobs})
    return sorted(summaries, key=_order)
