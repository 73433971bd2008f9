"""``cadgen optimize``: search a design's free parameters for one that meets every target.

A study file (:mod:`~cadgen.optimize.study`) names a base design, the free parameters and
their bounds, the objectives and a budget. Each mechanism kind is a design problem
(:mod:`~cadgen.optimize.problem`): the planting screen (vectorised over a population,
:mod:`~cadgen.optimize.planting`) and the pricking points (:mod:`~cadgen.optimize.pricking`).
:mod:`~cadgen.optimize.run` runs pymoo over it (screen), then re-evaluates the final
designs by the exact path of ``cadgen build`` (certify); :mod:`~cadgen.optimize.outputs`
writes best.toml, the Pareto table, the plots and optimize.html.

Modules are imported on use: importing this package loads neither numpy nor pymoo.
"""

from __future__ import annotations

from importlib import import_module

_EXPORTS = {
    "Study": "cadgen.optimize.study",
    "StudyError": "cadgen.optimize.study",
    "load_study": "cadgen.optimize.study",
    "DesignProblem": "cadgen.optimize.problem",
    "make_problem": "cadgen.optimize.problem",
    "PopulationEvaluator": "cadgen.optimize.problem",
    "optimize_study": "cadgen.optimize.run",
    "OptimizeResult": "cadgen.optimize.run",
    "write_outputs": "cadgen.optimize.outputs",
    "OptimizePrinter": "cadgen.optimize.progress",
}

__all__ = list(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'cadgen.optimize' has no attribute {name!r}")
    value = getattr(import_module(module), name)
    globals()[name] = value
    return value
