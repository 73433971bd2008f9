"""Unexpected exceptions: one line for the person, the whole traceback in a file.

The command line (exit 3), the studio's server (a 500 answer) and the studio's build
process report a bug the same way: ``cadgen: internal error: <Type>: <message>
(please report it; traceback saved to <file>)``, the file holding the traceback, the
versions and the command line.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path

__all__ = ["CRASH_DIR_VARIABLE", "MESSAGE_CHARACTERS", "one_line", "write_crash_file"]

#: Environment variable naming the directory of crash files (default: the temporary one).
CRASH_DIR_VARIABLE = "CADGEN_CRASH_DIR"
#: The longest exception message printed on the one line (the crash file has it whole).
MESSAGE_CHARACTERS = 300


def one_line(text, limit: int = MESSAGE_CHARACTERS) -> str:
    """``text`` on one line (whitespace runs to one space), cut to ``limit`` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _version() -> str:
    from cadgen import __version__

    return __version__


def write_crash_file(error: BaseException, argv: Sequence[str]) -> Path:
    """Save the traceback, the versions and the command line; the file's path.

    In ``$CADGEN_CRASH_DIR`` (made if missing) or :func:`tempfile.gettempdir`, named
    ``cadgen-crash-<date>-<time>-<pid>.txt`` (a counter added if that exists).
    Raises OSError when it cannot be written.
    """
    import datetime
    import platform
    import tempfile
    import traceback

    directory = Path(os.environ.get(CRASH_DIR_VARIABLE) or tempfile.gettempdir())
    directory.mkdir(parents=True, exist_ok=True)
    now = datetime.datetime.now()
    stem = f"cadgen-crash-{now:%Y%m%d-%H%M%S}-{os.getpid()}"
    try:
        version = _version()
    except Exception as exc:   # a broken install must not hide the crash being reported
        version = f"unknown ({type(exc).__name__}: {exc})"
    text = (f"cadgen {version} internal error at {now.isoformat(timespec='seconds')}\n"
            f"python {platform.python_version()} ({sys.executable}) on {platform.platform()}\n"
            f"argv: {[sys.argv[0] if sys.argv else 'cadgen', *argv]!r}\n"
            f"working directory: {os.getcwd()}\n\n"
            + "".join(traceback.format_exception(error)))
    for attempt in range(100):
        path = directory / (stem + (f"-{attempt}" if attempt else "") + ".txt")
        try:
            with open(path, "x", encoding="utf-8") as stream:
                stream.write(text)
        except FileExistsError:
            continue
        return path
    raise FileExistsError(f"every crash file name {stem}-*.txt in {directory} is taken")
