"""One design in a process of its own: a time limit, and a crash that costs only itself.

:func:`run_design_isolated` runs :func:`~cadgen.batch.single.run_design` in a child
process. From a single-threaded process (a local worker) the child is forked; elsewhere
(a Dask worker: threads, and daemonic, so multiprocessing may not start children there)
it is a new interpreter. The child leads its own process group and watches a pipe from
its job; its job waits for it with the time limit, then SIGKILLs the group (the child
and every worker its build forked) and removes the staging folders a killed build left.
At the pipe's end (the job's process died) the child kills its group itself
(:func:`cadgen.processes.watch_lifeline`).
"""

from __future__ import annotations

import contextlib
import importlib
import os
import pickle
import re
import shutil
import signal
import sys
import tempfile
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from cadgen.batch.grid import DesignJob
from cadgen.batch.single import (Build, _exception_failure, _is_default_build, _resolve_build,
                                 _summary, run_design)
from cadgen.processes import EXIT_ORPHANED, watch_lifeline

__all__ = ["run_design_isolated"]


#: What cadgen.export.atomic.staged_directory leaves beside ``<name>`` if its process is killed:
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


def _job_gone() -> None:
    """At the lifeline's end (the job is gone): kill this process's group.

    Only the job holds the pipe's write end and it never writes, so its end comes when
    the job closes it after this process ended, or when the job's own process dies (a
    killed local worker, a Dask worker restarted). Then the design's process and the
    workers its build forked must not run on unwatched. (A local worker that dies with
    the batch's process first stops its design and removes its staging folder.)
    """
    if hasattr(os, "killpg") and os.getpgrp() == os.getpid():
        os.killpg(os.getpid(), signal.SIGKILL)
    os._exit(EXIT_ORPHANED)


def _child_setup(lifeline: int) -> None:
    """First thing in a design's process: its own process group, a lifeline watcher, and
    Python tracebacks on a segfault (to stderr)."""
    import faulthandler
    import warnings

    if hasattr(os, "setsid"):
        with contextlib.suppress(OSError):  # a spawned child is a session leader already
            os.setsid()
    faulthandler.enable()
    # The build forks its own workers with the watcher thread present: it holds no lock
    # (it waits in os.read), so the forked worker is safe; Python 3.12 would warn anyway.
    warnings.filterwarnings("ignore", r".*multi-threaded, use of fork\(\)", DeprecationWarning)
    watch_lifeline(lifeline, _job_gone)


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
         "    from cadgen.batch.isolated import _spawned\n"
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


def _warm(build: Build | None, job: DesignJob | None = None,
          build_kwargs: Mapping | None = None) -> None:
    """Import the parameter schema and the build once here, not in every forked design; for
    the default build, what the design's scene imports too (:func:`cadgen.pipeline.warm.warm`,
    done once: the next designs find them loaded)."""
    with contextlib.suppress(Exception):  # the design's process reports it
        importlib.import_module("cadgen.params")
        _resolve_build(build)
        if not _is_default_build(build) or job is None or job.blocked_by:
            return
        from cadgen.params import load_params, validate_data
        from cadgen.pipeline.warm import warm

        params = (load_params(job.path) if job.path is not None
                  else validate_data(job.data, job.source))
        kwargs = build_kwargs or {}
        warm(params, effects=kwargs.get("effects"), case=kwargs.get("case"))


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

        _warm(build, job, build_kwargs)
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
        """Let go of the lifeline (the process has ended) and the process's handles."""
        os.close(self.job_end)
        if hasattr(self.process, "exitcode"):
            with contextlib.suppress(ValueError):  # (still running: only after an error here)
                self.process.close()
        elif self.sentinel is not None:
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
    daemonic) it is a new interpreter running ``cadgen.batch.isolated._spawned``, which costs
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
