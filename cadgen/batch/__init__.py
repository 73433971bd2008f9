"""Batch builds: many designs (parameter files or a parameter grid), local processes or Dask.

A batch is a list of :class:`DesignJob` records, made from parameter files
(:func:`file_jobs`) or from a grid file over one design's parameters
(:func:`expand_grid`; the format is in :mod:`cadgen.batch.grid`). :func:`run_batch`
runs every design in local processes (:class:`concurrent.futures.ProcessPoolExecutor`)
or on a Dask cluster and returns one small picklable summary dict per design, ordered
by design name; :func:`write_summary` writes ``batch-summary.csv`` and
``batch-summary.html`` under the output root. The command line (``cadgen batch``) is
:func:`add_batch_arguments` plus :func:`main_batch`::

    cadgen batch FILE ... [--grid GRID] [--output-dir DIR] [--workers N]
                 [--scheduler ADDRESS] [--timeout SECONDS | --in-process] [--strict]
                 [--no-cache]

Faults
------
A design's fault never stops the batch and never costs another design its outputs. In
the summary (``failure_code`` in the CSV) a design that

- is invalid or fails in its build (a ParameterError, a DesignError, any exception)
  has its problem's code and message, or ``exception`` with the traceback;
- is still running after ``--timeout`` seconds is killed: ``timeout``, the message
  naming the limit;
- kills its process (a segfault, ``os._exit``, a signal, the out-of-memory killer):
  ``worker_died``, with the exit code or the signal;
- could not be run at all (its worker itself died; Dask's KilledWorker): ``worker_error``.

How: each design runs in a process of its own (:mod:`cadgen.batch.isolated`), which its
job (in a local worker, or a Dask worker's thread) waits for, at most the time limit. In
a local worker, which has a single thread, the design's process is forked from it (the
imports are done once per worker); in a Dask worker, which has threads and is a daemonic
process, it is a new interpreter (``subprocess``). The design's process leads its own
process group, so the job's SIGKILL to the group also ends the workers the build forks
(its sweeps and figures); and it watches a pipe from its job, killing its group when the
job's process dies, so nothing runs on unwatched. The build writes its folder atomically
(:func:`cadgen.export.atomic.staged_directory`: a hidden ``.<name>.staging-XXXXXXXX`` folder
renamed into place at the end), so a failed or killed design leaves ``<name>/`` as it
was, a previous build's folder included; after a kill or a death its job removes the
staging folders the build left (and puts back a previous folder set aside for the swap),
and :func:`run_batch` sweeps once more for the batch's design names when all are done.
The local workers die with the batch's process, however it ends (killed too): each is
sent SIGTERM as it dies (:func:`cadgen.processes.process_pool`), stops its design as on
Ctrl-C (its group killed, its staging folder removed) and ends.
One window is left: a design killed in the instant after its new folder was renamed in
and before its process reported is reported ``timeout`` with its new outputs complete in
place.

Cost, measured on a metrics-only build (0.13 s in the worker itself): a design's process
forked from a local worker adds about 0.08 s per design (the build's first-use work is
not shared between designs); a new interpreter on a Dask worker adds about 0.55 s
(importing cadgen, numpy, pydantic). ``run_batch(isolate=False)`` (``--in-process``)
runs each design in the worker itself: no process to start, but no timeout, and a design
that kills its process takes the worker: locally that breaks the pool and every
unfinished design is reported ``worker_error``. On Dask, in-process builds cannot fork
their own workers (a Dask worker is a daemonic process), so the default build with
sweeps or figures fails there unless the workers run with
``distributed.worker.daemon: false``.

On Dask a design that dies costs only its own process: the Dask worker lives on and the
design is reported ``worker_died`` at once, not retried (a crash is the design's own and
would repeat), and a timeout is not retried either. If a Dask worker process itself dies
(killed, restarted by its nanny), the processes of its designs kill themselves, and
distributed runs those tasks again on another worker, up to
``distributed.scheduler.allowed-failures`` times (3 by default): the design is built
again from scratch (its folder is atomic), or reported ``worker_error`` (KilledWorker)
past that limit.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

from cadgen.batch.grid import DesignJob, GridError, expand_grid, file_jobs, guard_names
from cadgen.batch.isolated import run_design_isolated
from cadgen.batch.run import run_batch
from cadgen.batch.single import DEFAULT_BUILD, run_design
from cadgen.batch.summary import (
    EXIT_FAILED,
    EXIT_OK,
    EXIT_PROBLEMS,
    SUMMARY_CSV,
    SUMMARY_HTML,
    Progress,
    _clock,
    _reason,
    _why_not,
    batch_exit_code,
    summary_csv,
    summary_html,
    write_summary,
)

__all__ = [
    "DEFAULT_BUILD", "SUMMARY_CSV", "SUMMARY_HTML", "EXIT_OK", "EXIT_FAILED", "EXIT_PROBLEMS",
    "DesignJob", "GridError", "file_jobs", "expand_grid", "guard_names", "run_design",
    "run_design_isolated", "run_batch", "summary_csv", "summary_html", "write_summary",
    "batch_exit_code", "Progress", "add_batch_arguments", "main_batch",
]


# --------------------------------------------------------------------------- command line


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not 0 < value < math.inf:
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, got {text}")
    return value


def add_batch_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Add the ``cadgen batch`` arguments to ``parser`` (a subcommand's parser) and return it.

    ``FILE ...``, ``--grid GRID`` (repeatable), ``--output-dir DIR``, ``--workers N``,
    ``--scheduler ADDRESS``, ``--timeout SECONDS`` or ``--in-process``, ``--strict``,
    ``--no-cache`` (each design's build then neither reads nor fills the gear cache; on
    Dask, each worker machine has its own cache directory); also sets the default
    ``handler=main_batch``.
    """
    parser.add_argument("files", nargs="*", metavar="FILE", help="TOML parameter file")
    parser.add_argument("--grid", action="append", default=[], metavar="GRID",
                        help="TOML grid file: a base parameter file and values to vary "
                             "(the Cartesian product is built); may be repeated")
    parser.add_argument("--output-dir", metavar="DIR", default="outputs",
                        help="root of the output folders and of batch-summary.csv/.html "
                             "(default: %(default)s)")
    parser.add_argument("--workers", metavar="N", type=_positive_int, default=None,
                        help=f"local worker processes (default: the number of CPUs, "
                             f"{os.cpu_count()} here); ignored with --scheduler")
    parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                        help="run on the Dask cluster of this scheduler (tcp://host:8786) "
                             "instead of local processes; needs the 'dask' extra")
    faults = parser.add_mutually_exclusive_group()
    faults.add_argument("--timeout", metavar="SECONDS", type=_seconds, default=None,
                        help="stop a design still running after SECONDS (its process is "
                             "killed, its output folder left as it was) and report it failed "
                             "with code 'timeout' (default: no limit)")
    faults.add_argument("--in-process", action="store_true",
                        help="build each design inside its worker, not in a process of its "
                             "own: saves starting one per design, but allows no --timeout, "
                             "and a design that crashes its process takes the worker (and, "
                             "with local processes, every unfinished design) with it")
    parser.add_argument("--strict", action="store_true",
                        help="also exit 1 if a design misses one of its targets")
    parser.add_argument("--no-cache", action="store_true",
                        help="cut every gear, neither reading nor filling the gear cache")
    parser.set_defaults(handler=main_batch)
    return parser


def _unusable_files(files) -> list[str]:
    """One line per FILE that is not there, or is plainly not a parameter file (a grid or a
    study: the line names the command that reads it). A parameter file with problems is a
    design that fails in the batch; these are mistakes of the command line."""
    from pathlib import Path

    from cadgen.params.side_files import read_toml_file, wrong_kind_of_file

    lines = []
    for file in files:
        data, _, problems = read_toml_file(Path(file), "")
        if data is None:
            problems = [p for p in problems if p.code in ("file_not_found", "not_readable")]
        else:
            problems = wrong_kind_of_file(data, "parameter")
        lines += [f"{file}: {problem}" for problem in problems]
    return lines


def main_batch(args: argparse.Namespace) -> int:
    """Run ``cadgen batch`` (``args`` from :func:`add_batch_arguments`): build every design,
    write the summary, print where it is.

    Returns
    -------
    int
        :data:`EXIT_OK` (0) every design built (with ``--strict``: and met its targets);
        :data:`EXIT_FAILED` (1) otherwise; :data:`EXIT_PROBLEMS` (2) if nothing ran (a
        bad grid file, no designs, no Dask). Progress goes to stderr; the closing
        counts and the summary paths to stdout.
    """
    missing = _unusable_files(args.files)
    if missing:   # a command line that names no design to build: nothing runs or is written
        for line in missing:
            print(line, file=sys.stderr)
        return EXIT_PROBLEMS
    jobs = file_jobs(args.files)
    for grid in args.grid:
        try:
            jobs += expand_grid(grid)
        except GridError as exc:
            for problem in exc.problems:
                print(f"{grid}: {problem}", file=sys.stderr)
            return EXIT_PROBLEMS
    if not jobs:
        print("cadgen batch: no designs: give parameter files or --grid GRID", file=sys.stderr)
        return EXIT_PROBLEMS
    jobs = guard_names(jobs)

    progress = Progress(len(jobs))
    start = time.perf_counter()
    try:
        summaries = run_batch(jobs, args.output_dir, workers=args.workers,
                              scheduler=args.scheduler, on_result=progress.update,
                              on_start=progress.started,
                              timeout=getattr(args, "timeout", None),
                              isolate=not getattr(args, "in_process", False),
                              # only when asked: a custom build need not take ``cache``
                              build_kwargs={"cache": False} if getattr(args, "no_cache", False)
                              else None)
    except (ImportError, OSError) as exc:  # no dask, or the scheduler cannot be reached
        print(f"cadgen batch: {exc}", file=sys.stderr)
        return EXIT_PROBLEMS
    finally:
        progress.close()
    csv_path, html_path = write_summary(summaries, args.output_dir)

    built = sum(s["ok"] for s in summaries)
    not_passed = sum(s["ok"] and s["passed"] is False for s in summaries)
    took, plural = _clock(time.perf_counter() - start), "s" * (len(summaries) != 1)
    print(f"{len(summaries)} design{plural} in {took}: {built} built, "
          f"{len(summaries) - built} failed, {not_passed} built but did not pass")
    for s in summaries:
        if not s["ok"]:
            print(f"  failed {s['name']} ({s['source']}): {_reason(s)}")
        elif s["passed"] is False:
            print(f"  did not pass {s['name']}: {_why_not(s)}")
    print(f"summary: {csv_path}\n         {html_path}")
    return batch_exit_code(summaries, args.strict)
