"""Command line: ``cadgen validate``, ``cadgen build`` (alias ``analyze``) and ``cadgen batch``.

Exit codes: 0 success, 1 a design that was built but misses a target or fails a
check (the report says which), 2 a parameter file or design with problems
(nothing is written; also argparse's code for a bad command line). numpy, scipy, matplotlib and pydantic are imported
inside the commands only, so ``cadgen --help`` starts fast.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_CHECKS_FAILED", "EXIT_PROBLEMS"]

EXIT_OK = 0
EXIT_CHECKS_FAILED = 1
EXIT_PROBLEMS = 2


def _version() -> str:
    from cadgen import __version__

    return __version__


def _steps(text: str) -> int:
    """argparse type of ``--steps``: an integer in the range the parameter file allows."""
    from cadgen.params import STEPS_PER_REVOLUTION_RANGE

    low, high = STEPS_PER_REVOLUTION_RANGE
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"must be between {low} and {high}, got {value}")
    return value


def _cmd_validate(args: argparse.Namespace) -> int:
    from cadgen.params import ParameterError, load_params
    from kinematics.errors import MechanismError

    status = EXIT_OK
    for file in args.files:
        try:
            load_params(file)
        except ParameterError as exc:
            status = EXIT_PROBLEMS
            for problem in exc.problems:
                print(f"{file}: {problem}")
        except MechanismError as exc:
            # A check that could not finish (e.g. a convergence failure) is still a
            # verdict on this file, not a crash of the whole batch.
            status = EXIT_PROBLEMS
            print(f"{file}: {exc} [{type(exc).__name__}]")
        else:
            print(f"{file}: ok")
    return status


def _effects(text: str) -> list:
    """argparse type of ``--effects``: comma-separated effect names, each known."""
    from cadgen.params.scene import EFFECTS

    effects = [e.strip() for e in text.split(",") if e.strip()]
    unknown = [e for e in effects if e not in EFFECTS]
    if unknown or not effects:
        raise argparse.ArgumentTypeError(
            f"unknown effect(s) {', '.join(unknown) or '(none given)'}; choose from "
            f"{', '.join(EFFECTS)}")
    return list(dict.fromkeys(effects))


def _cmd_build(args: argparse.Namespace) -> int:
    from cadgen.params import ParameterError, load_params
    from kinematics.errors import MechanismError

    try:
        params = load_params(args.file)
    except ParameterError as exc:
        for problem in exc.problems:
            print(f"{args.file}: {problem}", file=sys.stderr)
        return EXIT_PROBLEMS
    except MechanismError as exc:
        print(f"{args.file}: {exc}", file=sys.stderr)
        return EXIT_PROBLEMS

    import cadgen.build

    try:
        result = cadgen.build.build(params, output_root=Path(args.output_dir),
                                    effects=args.effects, case=args.case, steps=args.steps,
                                    preset=args.preset)
    except MechanismError as exc:   # stages report their own failures; this is anything else
        print(f"{args.file}: {exc}", file=sys.stderr)
        return EXIT_PROBLEMS
    print(result.summary_text())
    return result.exit_code


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
    command.set_defaults(handler=_cmd_build)


def build_parser() -> argparse.ArgumentParser:
    """The ``cadgen`` argument parser with its subcommands."""
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
                   "(the report says which), 2 when the file or the design has problems "
                   "(nothing written).")
    for name, help_text in (("build", "build one design: metrics, gears, cam, solids, sweeps, "
                                      "files and report, as its scene asks"),
                            ("analyze", "the same as build (the earlier name)")):
        _add_build_arguments(commands.add_parser(name, help=help_text, description=description))

    from cadgen.batch import add_batch_arguments

    batch = commands.add_parser(
        "batch", help="build many designs (files or a parameter grid), locally or on Dask",
        description="Build many designs, from parameter files or a grid over one design's "
        "parameters, in local processes or on a Dask cluster; keep going past failing "
        "designs; write a summary CSV and HTML table; exit 1 if any design failed.")
    add_batch_arguments(batch)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when omitted.

    Returns
    -------
    int
        The exit status (``EXIT_OK`` or ``EXIT_PROBLEMS``).
    """
    args = build_parser().parse_args(argv)
    return args.handler(args)
