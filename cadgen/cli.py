"""Command line: ``cadgen validate``, ``cadgen build`` (alias ``analyze``), ``cadgen batch``,
``cadgen optimize`` (search a study's free parameters), ``cadgen new`` (a starting
parameter file), ``cadgen cache clear|info`` (the gear cache) and ``cadgen studio`` (the
design page in the browser).

Exit codes (every command):

- 0: success;
- 1: a design that was built but misses a target or fails a check (the report says
  which); ``batch``: a design failed (with ``--strict``, also one that missed a target);
- 2: a parameter file or design with problems, or an output directory that cannot be
  used (checked before any work; nothing is written); also argparse's code for a bad
  command line;
- 3 (:data:`EXIT_INTERNAL`): an unexpected exception, a bug: one line on stderr
  (``cadgen: internal error: ...``) with the path of a file holding the traceback, the
  versions and the command line (in ``$CADGEN_CRASH_DIR``, else the temporary directory);
- 130 (:data:`EXIT_INTERRUPTED`): interrupted (Ctrl-C): one line, ``cadgen:
  interrupted``; outputs are staged, so no half-written folder is left; SIGTERM and
  SIGHUP stop a command the same way, with 143 and 129 (128 + the signal's number) and
  the line ``cadgen: terminated by SIGTERM`` (``SIGHUP``). Every process the command
  started ends with it, however it ends (:mod:`cadgen.processes.lifeline`);
- 141 (:data:`EXIT_BROKEN_PIPE`): the reader of the output went away (``| head``), quietly.

Every error is one line on stderr, never a traceback. numpy, scipy, matplotlib and
pydantic are imported inside the commands only, so ``cadgen --help`` starts fast.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

# the one-line report and crash file of a bug, shared with the studio's server and builds
from cadgen.crash import CRASH_DIR_VARIABLE, one_line as _one_line
from cadgen.crash import write_crash_file as _write_crash_file
from cadgen.processes import INTERRUPT_SIGNALS as _INTERRUPT_SIGNALS
from cadgen.processes import Interrupts as _Interrupts
from cadgen.processes import interrupted_status as _interrupted_status

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_CHECKS_FAILED", "EXIT_PROBLEMS",
           "EXIT_INTERNAL", "EXIT_INTERRUPTED", "EXIT_BROKEN_PIPE", "CRASH_DIR_VARIABLE"]

EXIT_OK = 0
EXIT_CHECKS_FAILED = 1
EXIT_PROBLEMS = 2
#: An unexpected exception (a bug): never 1, which means "targets missed".
EXIT_INTERNAL = 3
#: Interrupted by Ctrl-C (128 + SIGINT, the shell's convention).
EXIT_INTERRUPTED = 130
#: The reader of the output went away (128 + SIGPIPE, the shell's convention).
EXIT_BROKEN_PIPE = 141
#: Seconds an interrupted command's exit waits for its threads (a process pool's manager
#: thread) before it ends without them (see :func:`entry`).
INTERRUPTED_EXIT_SECONDS = 1.0


def _version() -> str:
    from cadgen import __version__

    return __version__


def _steps(text: str) -> int:
    """argparse type of ``--steps``: an integer in the range the parameter file allows."""
    from cadgen import STEPS_PER_REVOLUTION_RANGE

    low, high = STEPS_PER_REVOLUTION_RANGE
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"must be between {low} and {high}, got {value}")
    return value


def _cmd_validate(args: argparse.Namespace) -> int:
    """Each file's verdict is its build's: what ``cadgen build FILE`` (the file's own scene)
    refuses is an error here (exit 2), a check of a stage the scene does not run a warning."""
    from cadgen import MechanismError, ParameterError, check_build, load_params

    status = EXIT_OK
    for file in args.files:
        try:
            params = load_params(file)
        except ParameterError as exc:
            status = EXIT_PROBLEMS
            # with errors in the file its scene is unknown: a stage's check is listed as a
            # warning beside them (once the file loads, check_build decides)
            for problem in exc.problems:
                print(f"{file}: {'warning: ' if problem.stage else ''}{problem}")
            continue
        except MechanismError as exc:
            # A check that could not finish (e.g. a convergence failure) is still a
            # verdict on this file, not a crash of the whole batch.
            status = EXIT_PROBLEMS
            print(f"{file}: {exc} [{type(exc).__name__}]")
            continue
        try:
            warnings = check_build(params).warnings
        except ParameterError as exc:   # what its build refuses: errors, as build says them
            status = EXIT_PROBLEMS
            for problem in exc.problems:
                print(f"{file}: {problem}")
            continue
        for problem in warnings:
            print(f"{file}: warning: {problem}")
        print(f"{file}: ok" + (f" ({len(warnings)} warning{'s' * (len(warnings) > 1)})"
                               if warnings else ""))
    return status


def _effects(text: str) -> list:
    """argparse type of ``--effects``: comma-separated effect names, each known."""
    from cadgen import EFFECTS

    effects = [e.strip() for e in text.split(",") if e.strip()]
    unknown = [e for e in effects if e not in EFFECTS]
    if unknown or not effects:
        raise argparse.ArgumentTypeError(
            f"unknown effect(s) {', '.join(unknown) or '(none given)'}; choose from "
            f"{', '.join(EFFECTS)}")
    return list(dict.fromkeys(effects))


def _cmd_build(args: argparse.Namespace) -> int:
    from cadgen import MechanismError, ParameterError, load_params

    try:
        params = load_params(args.file)
    except ParameterError as exc:
        for problem in exc.problems:
            print(f"{args.file}: {problem}", file=sys.stderr)
        return EXIT_PROBLEMS
    except MechanismError as exc:
        print(f"{args.file}: {exc}", file=sys.stderr)
        return EXIT_PROBLEMS

    import cadgen
    from cadgen import OutputDirError, ProgressPrinter

    # the cache is the build's default; passed only when turned off, the one case to ask for
    options = {"cache": False} if getattr(args, "no_cache", False) else {}
    # stages as they start and end, on stderr: stdout keeps the summary
    try:
        with ProgressPrinter(sys.stderr) as printer:
            result = cadgen.build(params, output_root=Path(args.output_dir),
                                  effects=args.effects, case=args.case, steps=args.steps,
                                  preset=args.preset, progress=printer, **options)
    except OutputDirError:
        raise                       # main() says it, the same way for every command
    except MechanismError as exc:   # stages report their own failures; this is anything else
        # one line per problem (a DesignError's message spans several)
        for line in [str(p) for p in getattr(exc, "problems", ())] or [" ".join(str(exc).split())]:
            print(f"{args.file}: {line}", file=sys.stderr)
        return EXIT_PROBLEMS
    print(result.summary_text())
    return result.exit_code


def _whole_number(minimum: int):
    """An argparse type: a whole number at least ``minimum`` (``--workers``, ``--seed``...)."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be at least {minimum}, got {value}")
        return value

    return parse


def _cmd_optimize(args: argparse.Namespace) -> int:
    """``cadgen optimize``: validate the study, search, certify, write; ``--build`` the best."""
    import cadgen
    from cadgen import StudyError, load_study

    try:
        study = load_study(args.study).with_budget(evaluations=args.evaluations, seed=args.seed)
    except StudyError as exc:
        for problem in exc.problems:
            print(f"{args.study}: {problem}", file=sys.stderr)
        return EXIT_PROBLEMS
    from cadgen import OptimizePrinter

    try:
        with OptimizePrinter(sys.stderr) as printer:
            result = cadgen.optimize_study(study, workers=args.workers or os.cpu_count() or 1,
                                           scheduler=args.scheduler, progress=printer)
    except cadgen.MechanismError as exc:   # the scheduler cannot be reached, say
        print(f"cadgen optimize: {_one_line(exc)}", file=sys.stderr)
        return EXIT_PROBLEMS
    folder = cadgen.write_optimize_outputs(result, Path(args.output_dir))
    print(cadgen.optimize_summary(result, folder))
    status = result.exit_code
    if args.build and result.found:
        from cadgen import ProgressPrinter

        best = folder / "best.toml"
        try:
            with ProgressPrinter(sys.stderr) as printer:
                built = cadgen.build(cadgen.load_params(best), output_root=Path(args.output_dir),
                                     progress=printer)
        except cadgen.MechanismError as exc:   # the build refused the design: it fails
            for line in [str(p) for p in getattr(exc, "problems", ())] or [_one_line(exc)]:
                print(f"{best}: {line}", file=sys.stderr)
            return EXIT_CHECKS_FAILED
        print(built.summary_text())
        status = max(status, built.exit_code)
    elif args.build:
        print("--build: nothing built, no design met every target")
    return status


def _add_build_arguments(command: argparse.ArgumentParser) -> None:
    command.add_argument("file", metavar="FILE", help="TOML parameter file")
    command.add_argument("--output-dir", metavar="DIR", default="outputs",
                         help="root of the output folders (default: %(default)s)")
    command.add_argument("--effects", metavar="LIST", type=_effects, default=None,
                         help="comma-separated effects, overriding [scene] effects: metrics, "
                              "curves, teeth, meshing, cam, solids, arm_interference, "
                              "ground_clearance, dxf, stl, plots, report (default: the file's "
                              "scene, or all)")
    command.add_argument("--case", choices=("field", "bench"), default=None,
                         help="operating case, overriding [scene] case")
    command.add_argument("--preset", choices=("draft", "standard", "fine"), default=None,
                         help="accuracy preset for every resolution knob the file leaves out, "
                              "overriding [scene] preset (default: standard)")
    command.add_argument("--steps", metavar="N", type=_steps, default=None,
                         help="steps per revolution, overriding [resolution] steps_per_revolution")
    command.add_argument("--no-cache", action="store_true",
                         help="cut every gear, neither reading nor filling the gear cache "
                              "(see 'cadgen cache info')")
    command.set_defaults(handler=_cmd_build)


def _size(count: int) -> str:
    """Bytes in a unit a person reads: ``812 B``, ``4.2 MB``."""
    if count < 1000:
        return f"{count} B"
    for unit in ("kB", "MB", "GB"):
        count /= 1000
        if count < 1000 or unit == "GB":
            break
    return f"{count:.1f} {unit}"


def _cmd_cache(args: argparse.Namespace) -> int:
    from cadgen import cache_info, clear_cache

    if args.action == "clear":
        removed = clear_cache()
        plural = "y" if removed["entries"] == 1 else "ies"
        print(f"removed {removed['entries']} gear cache entr{plural} "
              f"({_size(removed['bytes'])}) from {removed['directory']}")
        return EXIT_OK
    info = cache_info()
    print(f"directory: {info['directory']}{'' if info['exists'] else ' (not created yet)'}")
    print(f"entries:   {info['entries']}")
    print(f"size:      {_size(info['bytes'])}")
    return EXIT_OK


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The ``cadgen`` argument parser with its subcommands.

    Given the command line ``argv``, the ``batch`` command's own arguments are added only
    when ``batch`` is on it: they come from :mod:`cadgen.batch`, whose import (10 ms, a
    twentieth of a metrics-only build) no other command needs.
    """
    parser = argparse.ArgumentParser(
        prog="cadgen",
        description="CAD and manufacturing pipeline for non-circular-gear planting mechanisms.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    validate = commands.add_parser(
        "validate",
        help="check parameter files and list every problem (writes nothing)",
        description="Check parameter files and list every problem, one per line as "
        "'FILE: path: message [code]'. Exit 0 if all are ok, 2 otherwise. Writes nothing.",
    )
    validate.add_argument("files", nargs="+", metavar="FILE", help="TOML parameter file")
    validate.set_defaults(handler=_cmd_validate)

    description = ("Build one design: run exactly the stages its scene's effects need (all by "
                   "default), write the outputs atomically under OUTPUT_DIR/<name>/ and print "
                   "the summary. Exit 0 when every target and check passes, 1 when some fail "
                   "(the report says which), 2 when the file, the design or the output "
                   "directory has problems (nothing written), 3 on an internal error (a bug: "
                   "its traceback is saved to a file), 130 when interrupted.")
    for name, help_text in (("build", "build one design: metrics, gears, cam, solids, sweeps, "
                                      "files and report, as its scene asks"),
                            ("analyze", "the same as build (the earlier name)")):
        _add_build_arguments(commands.add_parser(name, help=help_text, description=description))

    batch = commands.add_parser(
        "batch", help="build many designs (files or a parameter grid), locally or on Dask",
        description="Build many designs, from parameter files or a grid over one design's "
        "parameters, in local processes or on a Dask cluster; keep going past failing "
        "designs; write a summary CSV and HTML table; exit 1 if any design failed.")
    if argv is None or "batch" in argv:
        from cadgen import add_batch_arguments

        add_batch_arguments(batch)

    optimize = commands.add_parser(
        "optimize", help="search a design's free parameters for one meeting every target",
        description="Search the free parameters a study file names (within their bounds) for "
        "the design meeting every target of the base file with the best objectives: a "
        "vectorised screen over each population (pymoo: a GA for one objective, NSGA-II for "
        "several; feasibility first), then the final designs re-evaluated by the exact "
        "evaluator of 'cadgen build'. Writes OUTPUT_DIR/<name>/: best.toml (a commented "
        "parameter file), optimize.html, optimize.json, convergence.png, and pareto.csv and "
        "pareto.png for several objectives. Progress on stderr. Exit 0 when a design meeting "
        "every target is found and certified, 1 when none is (the least-violating one is "
        "written as least-violating.toml; with --build, also when the build misses a "
        "target), 2 for a study file with problems (every one listed; nothing written), 3 on "
        "an internal error.")
    optimize.add_argument("study", metavar="STUDY", help="TOML study file")
    optimize.add_argument("--workers", metavar="N", type=_whole_number(1), default=None,
                          help=f"local processes screening each population (default: the "
                               f"number of CPUs, {os.cpu_count()} here, as for batch)")
    optimize.add_argument("--scheduler", metavar="ADDRESS", default=None,
                          help="screen on a Dask cluster (tcp://host:8786) instead")
    optimize.add_argument("--build", action="store_true",
                          help="then build best.toml (every effect of its scene) into "
                               "OUTPUT_DIR/<name>-best/ and print its summary")
    optimize.add_argument("--output-dir", metavar="DIR", default="outputs",
                          help="root of the output folders (default: %(default)s)")
    optimize.add_argument("--evaluations", metavar="N", type=_whole_number(1), default=None,
                          help="designs to screen, overriding [budget] evaluations")
    optimize.add_argument("--seed", metavar="N", type=_whole_number(0), default=None,
                          help="random seed, overriding [budget] seed")
    optimize.set_defaults(handler=_cmd_optimize)

    new = commands.add_parser(
        "new", help="write a commented starting parameter file from a bundled design",
        description="Write a commented starting parameter file NAME.toml (or --output FILE) "
        "for a planting mechanism (the paper's design) or a pricking mechanism (kernel-b, "
        "convex gears), with its name set to NAME. Never overwrites a file (exit 2).")
    new.add_argument("kind", choices=("planting", "pricking"), help="mechanism kind")
    new.add_argument("name", metavar="NAME", help="design name (also its output folder)")
    new.add_argument("--output", "-o", metavar="FILE", default=None,
                     help="the file to write (default: NAME.toml)")
    new.set_defaults(handler=_cmd_new)

    cache = commands.add_parser(
        "cache", help="show or clear the cache of cut gears",
        description="The cache of cut gears that makes a second build of the same gears fast "
        "(in the user's cache directory, or $CADGEN_CACHE_DIR). 'info' prints its directory, "
        "entries and size; 'clear' removes every entry and prints what it removed.")
    cache.add_argument("action", choices=("info", "clear"), help="what to do")
    cache.set_defaults(handler=_cmd_cache)

    studio = commands.add_parser(
        "studio", help="design in the browser: live metrics, draggable points, animation",
        description="Start the studio, a local web page to design FILE interactively (the "
        "bundled paper design when FILE is left out): a server on 127.0.0.1 behind a random "
        "token, whose URL is printed and opened in the browser. Ctrl-C stops it (exit 130); "
        "a FILE with problems or a port in use: exit 2.")
    studio.add_argument("file", metavar="FILE", nargs="?", default=None,
                        help="TOML parameter file to open (default: the bundled paper design, "
                             "read-only: save it under a new name)")
    studio.add_argument("--port", metavar="N", type=_port, default=0,
                        help="port to listen on (default: a free one)")
    studio.add_argument("--no-browser", action="store_true",
                        help="print the URL without opening a browser")
    studio.add_argument("--output-dir", metavar="DIR", default="outputs",
                        help="root of the build output folders (default: %(default)s)")
    studio.set_defaults(handler=_cmd_studio)
    return parser


def _port(text: str) -> int:
    """argparse type of ``--port``: 0 (a free port) to 65535."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be between 0 and 65535, got {value}")
    return value


def _cmd_studio(args: argparse.Namespace) -> int:
    """``cadgen studio``: check FILE, bind the port, print the URL, serve until Ctrl-C."""
    import cadgen

    try:
        # uvicorn turns Ctrl-C into a clean shutdown, then raises it again once stopped:
        # main() reports it as "cadgen: interrupted", exit 130
        cadgen.run_studio(args.file, port=args.port, open_browser=not args.no_browser,
                          output_root=Path(args.output_dir),
                          announce=lambda url: print(f"cadgen studio: {url}", flush=True))
    # the except clauses name the classes only when something is raised: run_studio loads
    # numpy single-threaded first, so nothing here may import the parameter models before
    except cadgen.ParameterError as exc:
        for problem in exc.problems:
            print(f"{args.file}: {problem}", file=sys.stderr)
        return EXIT_PROBLEMS
    except cadgen.MechanismError as exc:
        print(f"{args.file}: {_one_line(exc)} [{type(exc).__name__}]", file=sys.stderr)
        return EXIT_PROBLEMS
    except cadgen.StudioPortError as exc:
        print(f"cadgen studio: {exc.strerror}", file=sys.stderr)
        return EXIT_PROBLEMS
    return EXIT_OK


def _cmd_new(args: argparse.Namespace) -> int:
    from cadgen import ParameterError, write_template

    try:
        path = write_template(args.kind, args.name, args.output)
    except ParameterError as exc:
        for problem in exc.problems:
            print(f"cadgen new: {problem}", file=sys.stderr)
        return EXIT_PROBLEMS
    except FileExistsError as exc:
        print(f"cadgen new: {exc.filename or args.output} exists; not overwritten (choose "
              "another NAME or --output FILE)", file=sys.stderr)
        return EXIT_PROBLEMS
    except OSError as exc:
        print(f"cadgen new: cannot write {exc.filename or args.output}: {exc.strerror or exc}",
              file=sys.stderr)
        return EXIT_PROBLEMS
    print(f"wrote {path} ({args.kind}, from the bundled example); next: "
          f"cadgen validate {path} && cadgen build {path}")
    return EXIT_OK


def _internal_error(error: BaseException, argv: Sequence[str]) -> int:
    """Report an unexpected exception on one line, its traceback in a file: EXIT_INTERNAL."""
    try:
        saved = f"traceback saved to {_write_crash_file(error, argv)}"
    except Exception as exc:
        saved = f"the traceback could not be saved: {_one_line(exc, 120)}"
    print(f"cadgen: internal error: {type(error).__name__}: {_one_line(error)} "
          f"(please report it; {saved})", file=sys.stderr)
    return EXIT_INTERNAL


def _check_output_dir(args: argparse.Namespace) -> None:
    """An unusable ``--output-dir`` is an error before any work (build, analyze, batch)."""
    directory = getattr(args, "output_dir", None)
    if directory is not None:
        from cadgen import check_output_root

        check_output_root(directory)


def entry() -> None:
    """The ``cadgen`` script and ``python -m cadgen``: :func:`main`, then a quick exit.

    Tearing the interpreter down after a build (freeing every object of numpy, matplotlib,
    trimesh, ezdxf, module by module) takes a fifth of a second and does nothing a process
    exit does not. So once :func:`main` has returned, the exit handlers have run and the
    output is flushed, the process ends at once, unless a thread or child process is still
    running (then the interpreter waits for it as usual). argparse's own exits (``--help``,
    a bad command line) leave the usual way.
    """
    import atexit
    import threading

    status = main()
    processes = sys.modules.get("multiprocessing")   # never imported: no child to wait for
    shutdown = getattr(threading, "_shutdown", None)
    if status in _STOPPED_STATUSES:
        # Stopped: the command's own cleanup is done (main() returned: no staging folder is
        # left), and what it started is abandoned (it would die with it anyway, see
        # cadgen.processes.lifeline). A thread that does not end is not waited for: a
        # process pool's manager thread reading a result its worker was killed in the
        # middle of sending waits for the rest for ever, and so would the interpreter's
        # exit, which joins it.
        for child in processes.active_children() if processes is not None else ():
            child.kill()
        if not _threads_ended(INTERRUPTED_EXIT_SECONDS):
            _flush_and_exit(status)
    if (processes is not None and processes.active_children()) or shutdown is None:
        raise SystemExit(status)
    # What the interpreter's exit does first: wait for every non-daemon thread to end, to
    # its very end (a process pool's manager thread finalises the pool's semaphores as its
    # last act, after threading.enumerate() has stopped listing it: cut short there, one is
    # unlinked but not unregistered, and the resource tracker warns of a leak), and run
    # the exit handlers threads registered (concurrent.futures' joins its pools' threads)
    shutdown()
    atexit._run_exitfuncs()
    _flush_and_exit(status)


#: The exit statuses of a command stopped by a signal (130, 143, 129).
_STOPPED_STATUSES = frozenset(_interrupted_status(signum) for signum in _INTERRUPT_SIGNALS)


def _threads_ended(seconds: float) -> bool:
    """Wait up to ``seconds`` for every other non-daemon thread to end; have they?"""
    import threading
    import time

    deadline = time.monotonic() + seconds
    for thread in threading.enumerate():
        if thread is not threading.current_thread() and not thread.daemon:
            thread.join(max(0.0, deadline - time.monotonic()))
            if thread.is_alive():
                return False
    return True


def _flush_and_exit(status: int) -> None:
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (BrokenPipeError, OSError, ValueError):   # the reader went away: nothing to say
        pass
    os._exit(status)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when omitted.

    Returns
    -------
    int
        The exit status: ``EXIT_OK``, ``EXIT_CHECKS_FAILED``, ``EXIT_PROBLEMS``,
        ``EXIT_INTERNAL`` (an unexpected exception, saved to a crash file) or
        ``EXIT_INTERRUPTED`` (Ctrl-C; 143 for SIGTERM, 129 for SIGHUP). argparse's own
        exits (``--help``, a bad command line) raise SystemExit as usual.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    from cadgen.math_threads import one_thread_for_commands

    one_thread_for_commands()   # before numpy loads (see cadgen.math_threads)
    with _Interrupts() as interrupts:
        try:
            try:
                args = build_parser(argv).parse_args(argv)
                _check_output_dir(args)
                status = args.handler(args)
            finally:
                # from here on an interrupt is not raised again (cadgen.processes.interrupts);
                # one raised before this line lands in the except clause below
                interrupts.stopping = True
        except KeyboardInterrupt:
            interrupts.seen = True
        except BrokenPipeError:
            # the reader went away (``cadgen build ... | head``): nothing to say, and
            # nowhere to say it; stdout to /dev/null so the interpreter's flush is quiet
            try:
                os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            except (OSError, ValueError):   # stdout is not a file (captured, say)
                pass
            return EXIT_BROKEN_PIPE
        except Exception as error:
            if not interrupts.seen:     # (an error that follows from the interrupt is it)
                from cadgen import OutputDirError

                if isinstance(error, OutputDirError):
                    print(f"cadgen: {error}", file=sys.stderr)
                    return EXIT_PROBLEMS
                return _internal_error(error, argv)
        if interrupts.seen:
            return _stopped(interrupts.signal)
        return status


def _stopped(signum: int | None) -> int:
    """Say on one line that a signal stopped the command; its exit status (128 + its number)."""
    import signal

    signum = signum or signal.SIGINT
    line = ("cadgen: interrupted" if signum == signal.SIGINT
            else f"cadgen: terminated by {signal.Signals(signum).name}")
    try:
        print(line, file=sys.stderr)
    except (OSError, ValueError):   # the terminal is gone (SIGHUP): nowhere to say it
        pass
    return _interrupted_status(signum)
