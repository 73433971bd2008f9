"""The checks a build runs beyond the targets, on one design: what makes best.toml build clean.

The screen and ``certify`` judge the targets (and the duckbill's linkage, which validation
attaches to the parameters). A build also runs checks of its own stages that no target
names: the duckbill cam (stage ``cam``: pressure angle, the roller against the contour's
curvature) and the drivetrain (stage ``drivetrain``: shaft strength, key pressure,
bearing life, ~2 ms on a solved mechanism). A design meeting every target may still fail
one (a longer planter arm loads the drive more: ``key_overloaded``), and its best.toml
would not build clean. :func:`build_checks` runs them exactly, as ``cadgen build`` does:
``cadgen.build(effects=["metrics", "cam"])`` with nothing written, then the drivetrain on
the same solved mechanism.

Used twice by the run (:mod:`cadgen.optimize.run`): on every certified design, and, during
the search, on the incumbents (the best screened-feasible design of each objective in each
generation, once per design). What they say is kept (:class:`BuildKnowledge`) and turned
into one more constraint, ``build:checks``, on every screened design: violated near a
design the checks failed. So the search moves off a region the screen cannot see, at the
cost of one or two exact checks per generation.
"""

from __future__ import annotations

import numpy as np

__all__ = ["build_checks", "BuildKnowledge", "BUILD_LABEL", "NEIGHBOURHOOD"]

#: The constraint column the run adds for these checks (0: passed or not checked yet).
BUILD_LABEL = "build:checks"


def build_checks(problem, x) -> dict:
    """Every check a metrics + cam + drivetrain build runs on the design ``x`` (n,).

    Returns
    -------
    dict
        ``{"build_failures": [one sentence each], "stage_problems": [problem dicts],
        "problems": [problem dicts of a file the validation refuses]}``; empty lists: the
        build of this design passes (every target too).
    """
    import cadgen
    from cadgen.design import build_mechanism, pricking_design
    from cadgen.machine.drivetrain import drivetrain

    try:
        params = cadgen.validate_data(problem.tables_at(np.asarray(x, dtype=float)))
    except cadgen.ParameterError as error:
        return {"build_failures": [], "stage_problems": [],
                "problems": [p.as_dict() for p in error.problems]}
    stage = [p.as_dict() for p in cadgen.stage_problems(params)]
    effects = ["metrics", "cam"] if params.mechanism == "planting" else ["metrics"]
    try:
        report = cadgen.build(params, output_root=None, effects=effects, cache=False).report
        failures = list(report.get("failures", []))
    except cadgen.MechanismError as error:   # the stage refused the design (its problems)
        failures = [str(p) for p in getattr(error, "problems", ())] or [str(error)]
    design = (build_mechanism(params) if params.mechanism == "planting"
              else pricking_design(params))
    failures += [f"machine: [{p.code}] {p.message}" for p in drivetrain(params, design).problems]
    return {"build_failures": failures, "stage_problems": stage, "problems": []}


#: A screened design within this distance of a design the checks failed, and nearer to it
#: than to any design they passed, is taken to fail too (distance in the search box scaled
#: to the unit cube). The checks' refusals are regions (a key overloaded from some arm
#: length on), so each failure rules out its neighbourhood, and the passes nearby keep the
#: boundary where the checks put it.
NEIGHBOURHOOD = 0.05


class BuildKnowledge:
    """What the build checks said so far, as a constraint on screened designs.

    Parameters
    ----------
    lower, upper : (n,) float
        The search box (for the scaled distance).
    radius : float
        :data:`NEIGHBOURHOOD`.
    """

    def __init__(self, lower, upper, radius: float = NEIGHBOURHOOD):
        self.lower = np.asarray(lower, dtype=float)
        self.span = np.where(np.asarray(upper, dtype=float) > self.lower,
                             np.asarray(upper, dtype=float) - self.lower, 1.0)
        self.radius = float(radius)
        self.failed = np.empty((0, len(self.lower)))
        self.passed = np.empty((0, len(self.lower)))

    def add(self, x, passes: bool) -> None:
        point = ((np.asarray(x, dtype=float) - self.lower) / self.span)[None, :]
        if passes:
            self.passed = np.vstack([self.passed, point])
        else:
            self.failed = np.vstack([self.failed, point])

    def settled(self, x) -> bool:
        """Is ``x`` within half the neighbourhood of a design the checks passed, and nearer
        to it than to any they failed? Then checking it would most likely tell nothing new
        (the run's incumbents creep by small steps once the search has converged)."""
        if not len(self.passed):
            return False
        scaled = (np.asarray(x, dtype=float) - self.lower) / self.span
        to_passed = float(np.min(np.linalg.norm(self.passed - scaled, axis=1)))
        to_failed = (float(np.min(np.linalg.norm(self.failed - scaled, axis=1)))
                     if len(self.failed) else np.inf)
        return to_passed < 0.5 * self.radius and to_passed < to_failed

    def flags(self, X) -> np.ndarray:
        """(N,) float: 1.0 where a design of ``X`` (N, n) is taken to fail the checks, else 0."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if not len(self.failed):
            return np.zeros(len(X))
        scaled = (X - self.lower) / self.span
        to_failed = np.min(np.linalg.norm(scaled[:, None, :] - self.failed[None], axis=2), axis=1)
        to_passed = (np.min(np.linalg.norm(scaled[:, None, :] - self.passed[None], axis=2),
                            axis=1) if len(self.passed) else np.full(len(X), np.inf))
        return ((to_failed < self.radius) & (to_failed < to_passed)).astype(float)
