"""The final designs of a search: rounded to shop precision, screened again, certified.

:func:`cadgen.optimize.run.optimize_study` takes the best screened designs (or the front), and
what it certifies is what a workshop is given: each free value rounded to its study's step
(:attr:`cadgen.optimize.study.Study.steps`), the rounded rows screened again, and the exact
evaluator run on those. :class:`FinalDesign` holds one: its variables, the screen's figures
and the exact ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["FinalDesign", "screened_rows", "variable_steps", "rounded"]


@dataclass(eq=False)   # compared by identity: x is an array
class FinalDesign:
    """A certified design: its variables, the screen's figures and the exact ones."""

    x: np.ndarray
    screened: dict          # {"values", "margins", "objectives", "feasible", "violation"}
    exact: dict             # problem.certify(x)
    role: str = ""          # "best", "front", "candidate", "base"

    @property
    def passed(self) -> bool:
        """Every target met by the exact path, no build stage refuses the design, and
        every check of a metrics + cam + drivetrain build passes."""
        return (bool(self.exact.get("passed")) and not self.exact.get("stage_problems")
                and not self.exact.get("build_failures"))

    @property
    def min_margin(self) -> float | None:
        """The exact smallest normalised margin: the problem's ``min_margin`` when it gives
        one (planting leaves out a met ``= 1`` target, whose margin is 0 at best), else the
        smallest exact margin."""
        value = self.exact.get("values", {}).get("min_margin")
        if _is_real(value):
            return float(value)
        margins = [m for m in self.exact.get("margins", {}).values() if _is_real(m)]
        return min(margins) if margins else None

    @property
    def exact_violation(self) -> float:
        """Sum of the negative exact margins (0 when every margin holds); inf if refused."""
        if self.exact.get("problems"):
            return float("inf")
        margins = np.array([m for m in self.exact.get("margins", {}).values()
                            if m is not None and np.isfinite(m)], dtype=float)
        return float(-np.minimum(margins, 0.0).sum()) + 0.0 if margins.size else float("inf")

    def differences(self) -> dict:
        """``exact - screened`` of every value and margin both give."""
        out = {}
        for group in ("values", "margins"):
            screened, exact = self.screened.get(group, {}), self.exact.get(group, {})
            for key in screened:
                a, b = screened[key], exact.get(key)
                if _is_real(a) and _is_real(b):
                    out[f"{group[:-1]}:{key}" if group == "margins" else key] = float(b) - float(a)
        return out


def _is_real(value) -> bool:
    return isinstance(value, (int, float, np.floating)) and not isinstance(value, bool) and \
        np.isfinite(value)


def _natural(value: float, sense: str) -> float:
    return -value if sense == "max" else value


def screened_rows(problem, X: np.ndarray) -> list[dict]:
    """The screen's figures of each row of ``X`` (as :meth:`_Archive.screened` gives them)."""
    screened = problem.evaluate(np.atleast_2d(np.asarray(X, dtype=float)))
    out = []
    for row in range(len(X)):
        G = np.asarray(screened["G"][row], dtype=float)
        F = np.asarray(screened["F"][row], dtype=float)
        out.append({
            "values": {k: float(np.asarray(v)[row]) for k, v in screened["values"].items()},
            "margins": dict(zip(problem.constraint_labels, (-G).tolist())),
            "objectives": {key: _natural(float(f), sense)
                           for (key, sense), f in zip(problem.objectives, F)},
            "feasible": bool(np.asarray(screened["valid"])[row] and np.all(G <= 0.0)),
            "violation": float(np.maximum(G, 0.0).sum())})
    return out


def variable_steps(study, problem) -> np.ndarray:
    """Each variable's rounding step (0: not rounded): the study's steps by free path; a
    pricking study's displacements all take its points' step."""
    steps = getattr(study, "steps", None) or {}
    if getattr(study, "kind", None) == "pricking":
        return np.full(len(problem.variables), steps.get("trajectory.points", 0.0))
    return np.array([steps.get(name, 0.0) for name in problem.variables], dtype=float)


def _decimals(step: float) -> int:
    """The decimals that write ``step`` exactly (0.01 -> 2, 0.25 -> 2, 0.5 -> 1, 2 -> 0)."""
    return next((d for d in range(13) if round(step, d) == step), 12)


def rounded(X: np.ndarray, steps: np.ndarray, lower, upper) -> np.ndarray:
    """The rows of ``X`` with each column rounded to its step within its bounds (a value
    rounded out of them takes the nearest step inside), duplicates after rounding dropped
    (first kept: the order is best first). A step of 0 leaves the column as it is."""
    X = np.array(X, dtype=float, ndmin=2)
    for j, step in enumerate(np.asarray(steps, dtype=float)):
        if step > 0:
            low = math.ceil(lower[j] / step - 1e-9) * step
            high = math.floor(upper[j] / step + 1e-9) * step
            if low > high:   # no step inside the bounds (a study refuses such a step)
                continue
            column = np.clip(np.round(X[:, j] / step) * step, low, high)
            X[:, j] = np.round(column, _decimals(step))   # 188.99, not 188.99000000000001
    _, first = np.unique(X, axis=0, return_index=True)
    return X[np.sort(first)]


# --------------------------------------------------------------------------- selection
