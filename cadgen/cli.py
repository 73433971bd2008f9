"""Command line: ``cadgen validate`` and ``cadgen analyze``.

Exit codes: 0 success, 2 a parameter file or design with problems (also argparse's
code for a bad command line). numpy, scipy, matplotlib and pydantic are imported
inside the commands only, so ``cadgen --help`` starts fast.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_PROBLEMS"]

EXIT_OK = 0
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


def _cmd_analyze(args: argparse.Namespace) -> int:
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

    from cadgen.analyze import run_analysis

    try:
        result = run_analysis(
            params, output_root=Path(args.output_dir), steps_per_revolution=args.steps
        )
    except MechanismError as exc:
        print(f"{args.file}: {exc}", file=sys.stderr)
        return EXIT_PROBLEMS
    print(result.summary_text())
    return EXIT_OK


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

    analyze = commands.add_parser(
        "analyze",
        help="compute the kinematics and design metrics of one design",
        description="Compute the kinematics and design metrics of one design and write "
        "them under OUTPUT_DIR/<name>/. Exit 2 if the file or the design has problems.",
    )
    analyze.add_argument("file", metavar="FILE", help="TOML parameter file")
    analyze.add_argument(
        "--output-dir",
        metavar="DIR",
        default="outputs",
        help="root of the output folders (default: %(default)s)",
    )
    analyze.add_argument(
        "--steps",
        metavar="N",
        type=_steps,
        default=None,
        help="steps per revolution, overriding [resolution] steps_per_revolution",
    )
    analyze.set_defaults(handler=_cmd_analyze)
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
