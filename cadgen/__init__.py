"""cadgen: from a mechanism parameter file to kinematics, metrics and manufacturable parts.

The public API: what a script, the command line, the studio and the optimiser use.
Everything else is internal and may move. The names below are imported on first use
(PEP 562), so ``import cadgen`` and ``cadgen --help`` do not pay for pydantic, numpy or
the geometry engines::

    import cadgen

    params = cadgen.load_params("params/xin2024-planter.toml")   # ParameterError: every problem
    evaluation = cadgen.evaluate(params)                          # metrics, nothing written
    for metric in evaluation.metrics:
        print(metric.label, metric.value, metric.passed)
    result = cadgen.build(params, output_root="outputs")          # the files, atomically
    print(result.summary_text())
    raise SystemExit(result.exit_code)
"""

from __future__ import annotations

from importlib import import_module

_EXPORTS = {
    # errors: every error raised on purpose is a MechanismError; design and parameter
    # errors are also ValueError, convergence failures ArithmeticError
    "MechanismError": "kinematics.errors",
    "DesignError": "kinematics.errors",
    "ConvergenceError": "kinematics.errors",
    "Problem": "kinematics.errors",
    "ParameterError": "cadgen.params",
    "OutputDirError": "cadgen.export.atomic",
    # parameter files
    "load_params": "cadgen.params",
    "validate_text": "cadgen.params",
    "validate_data": "cadgen.params",
    "stage_problems": "cadgen.params",
    "PlantingParameters": "cadgen.params",
    "DesignParameters": "cadgen.params",
    "MECHANISM_KINDS": "cadgen.params",
    "STEPS_PER_REVOLUTION_RANGE": "cadgen.params",
    "EFFECTS": "cadgen.params.scene",
    # starting files from the bundled designs (cadgen new)
    "TEMPLATES": "cadgen.params.templates",
    "template_text": "cadgen.params.templates",
    "write_template": "cadgen.params.templates",
    # evaluating a design (nothing written) and building it (files written)
    "evaluate": "cadgen.design",
    "build": "cadgen.pipeline.build",
    "check_build": "cadgen.pipeline.plan",
    "BuildPlan": "cadgen.pipeline.plan",
    "BuildResult": "cadgen.pipeline.build",
    "check_output_root": "cadgen.export.atomic",
    "run_analysis": "cadgen.pipeline.build",
    # a build's progress as it runs: the events, and the printer the command line uses
    "ProgressEvent": "cadgen.pipeline.progress",
    "ProgressPrinter": "cadgen.report.progress",
    # the cache of cut gears (cadgen build --no-cache, cadgen cache clear|info)
    "cache_directory": "cadgen.pipeline.gear_cache",
    "clear_cache": "cadgen.pipeline.gear_cache",
    "cache_info": "cadgen.pipeline.gear_cache",
    # many designs
    "run_batch": "cadgen.batch",
    "expand_grid": "cadgen.batch",
    "file_jobs": "cadgen.batch",
    "add_batch_arguments": "cadgen.batch",
    # the optimiser: a study file's search, certified (cadgen optimize)
    "Study": "cadgen.optimize.study",
    "StudyError": "cadgen.optimize.study",
    "load_study": "cadgen.optimize.study",
    "DesignProblem": "cadgen.optimize.problem",
    "make_problem": "cadgen.optimize.problem",
    "optimize_study": "cadgen.optimize.run",
    "OptimizeResult": "cadgen.optimize.run",
    "OptimizeProgress": "cadgen.optimize.run",
    "OptimizePrinter": "cadgen.optimize.progress",
    "write_optimize_outputs": "cadgen.optimize.outputs",
    "optimize_summary": "cadgen.optimize.outputs",
    # the studio: the design page in the browser (cadgen studio)
    "run_studio": "cadgen.studio.run",
    "StudioPortError": "cadgen.studio.run",
    # writing files atomically
    "write_bytes_atomic": "cadgen.export.atomic",
    "write_text_atomic": "cadgen.export.atomic",
    "staged_directory": "cadgen.export.atomic",
}

__all__ = ["__version__", *_EXPORTS]


def _version() -> str:
    # importlib.metadata costs 35 ms to import: read it only when the version is asked for
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("cadgen")
    except PackageNotFoundError:  # running from a source tree that was never installed
        return "0.0.0+unknown"


def __getattr__(name: str):
    if name == "__version__":
        globals()["__version__"] = value = _version()
        return value
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'cadgen' has no attribute {name!r}")
    value = getattr(import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
