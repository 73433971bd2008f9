"""Starting parameter files (``cadgen new planting|pricking NAME``), from the bundled designs.

The two examples ship as package data in ``cadgen/params/examples/`` (copies of
``params/xin2024-planter.toml`` and ``params/kernel-b.toml``, kept identical by a test):
the planting start is the paper's optimised design, the pricking start kernel-b, whose
four pitch curves are all convex (its gears can be cut). The written file is the
example, every comment kept, with its ``name`` replaced and a header saying where it
came from.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from cadgen.params._tables import NAME_MAX_LENGTH, NAME_PATTERN
from cadgen.params.loading import ParameterError
from kinematics.errors import Problem

__all__ = ["TEMPLATES", "template_text", "write_template"]

#: Mechanism kind -> the bundled example a new file starts from.
TEMPLATES = {"planting": "xin2024-planter.toml", "pricking": "kernel-b.toml"}

_NAME_LINE = re.compile(r'^name = "(?P<name>[^"]*)"(?P<pad> *)(?P<comment>#.*)?$', re.MULTILINE)


def _example_text(kind: str) -> str:
    import importlib.resources

    if kind not in TEMPLATES:
        raise ParameterError([Problem("mechanism", "unknown_kind",
                                      f"no starting file for {kind!r}: choose "
                                      f"{' or '.join(TEMPLATES)}")])
    return (importlib.resources.files("cadgen.params") / "examples" / TEMPLATES[kind]).read_text(
        encoding="utf-8")


def _check_name(name: str) -> None:
    if not re.fullmatch(NAME_PATTERN, name) or len(name) > NAME_MAX_LENGTH:
        raise ParameterError([Problem(
            "name", "bad_name",
            f"design name {name!r} must be 1 to {NAME_MAX_LENGTH} letters, digits, '.', '_' "
            f"or '-', starting with a letter or digit (it becomes a folder name)")])


def template_text(kind: str, name: str, path: str | os.PathLike | None = None) -> str:
    """The text of a commented starting file for a ``kind`` mechanism named ``name``.

    Parameters
    ----------
    kind : {"planting", "pricking"}
    name : str
        The design name (``name = ...``; also its output folder).
    path : str or path-like, optional
        Where the file will be written; named in its "Check it with" line
        (default ``NAME.toml``).

    Raises
    ------
    ParameterError
        An unknown kind or a name the parameter files do not accept.
    """
    text = _example_text(kind)
    _check_name(name)
    example = TEMPLATES[kind].removesuffix(".toml")
    path = f"{name}.toml" if path is None else os.fspath(path)

    def rename(match: re.Match) -> str:
        line = f'name = "{name}"'
        comment = (match["comment"] or "").replace(f"outputs/{example}/", f"outputs/{name}/")
        return line + (" " * max(1, 28 - len(line)) + comment if comment else "")

    text, count = _NAME_LINE.subn(rename, text, count=1)
    if count != 1:  # the bundled example lost its name line: a packaging bug
        raise RuntimeError(f"the bundled example {TEMPLATES[kind]} has no 'name = ...' line")
    text = text.replace(f"cadgen validate params/{example}.toml", f"cadgen validate {path}")
    header = (f"# Starting file for the {kind} design {name!r}, written by `cadgen new {kind} "
              f"{name}` from\n# the bundled example {example!r}: change the values below, "
              f"then build it with\n#   cadgen build {path}\n#\n")
    return header + text


def write_template(kind: str, name: str, path: str | os.PathLike | None = None) -> Path:
    """Write :func:`template_text` to ``path`` (default ``NAME.toml``); the path written.

    Raises
    ------
    FileExistsError
        ``path`` exists (it is never overwritten).
    ParameterError
        An unknown kind or a bad name (nothing written).
    """
    path = Path(f"{name}.toml" if path is None else path)
    text = template_text(kind, name, path)
    with open(path, "x", encoding="utf-8") as stream:  # "x": refuse an existing file, atomically
        stream.write(text)
    return path
