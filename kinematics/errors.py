"""The project's exception family and the problem record every validator returns.

One base error (:class:`MechanismError`); design and parameter errors are also
``ValueError`` and convergence failures also ``ArithmeticError``, so callers may
catch either the project family or the builtin one (ezdxf's ``DXFValueError`` habit).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Problem", "MechanismError", "DesignError", "ConvergenceError"]


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a design or a parameter file.

    Attributes
    ----------
    path : str
        Dotted field path in the parameter file, e.g. ``"pitch_curve.b1"``;
        ``""`` for the file as a whole.
    code : str
        Short machine-readable kind, e.g. ``"unknown_key"``, ``"pointed_pitch_curve"``.
    message : str
        A sentence for a person: the bad value and why it is bad.
    stage : str, optional
        The build stage the check belongs to (``"cam"`` for the duckbill linkage),
        or None for a problem no build can go past. A build whose scene does not
        run that stage keeps it as a warning.
    """

    path: str
    code: str
    message: str
    stage: str | None = None

    def __str__(self) -> str:
        where = self.path or "<file>"
        stage = f" (stage {self.stage})" if self.stage else ""
        return f"{where}: {self.message} [{self.code}]{stage}"

    def as_dict(self) -> dict:
        """``{"path", "code", "message"}`` plus ``"stage"`` when it has one."""
        out = {"path": self.path, "code": self.code, "message": self.message}
        if self.stage:
            out["stage"] = self.stage
        return out


class MechanismError(Exception):
    """Base of every error this project raises on purpose."""


class DesignError(MechanismError, ValueError):
    """A design (or a parameter file) that cannot be built, with every problem found.

    Parameters
    ----------
    problems : list of Problem
        All problems, not just the first.
    source : str, optional
        The file the design came from, for the message.
    """

    def __init__(self, problems, source: str | None = None):
        self.problems = list(problems)
        self.source = source
        head = f"{source}: " if source else ""
        count = len(self.problems)
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"{head}{count} problem{'s' if count != 1 else ''}\n{lines}")

    @classmethod
    def single(cls, path: str, code: str, message: str) -> "DesignError":
        return cls([Problem(path, code, message)])


class ConvergenceError(MechanismError, ArithmeticError):
    """A numerical method did not reach its stated tolerance (never returned as NaN)."""
