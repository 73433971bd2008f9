"""cadgen: from a mechanism parameter file to kinematics, metrics and manufacturable parts.

The public names below are imported on first use (PEP 562), so ``import cadgen``
and ``cadgen --help`` do not pay for pydantic, numpy or the geometry engines.
"""

from __future__ import annotations

from importlib import import_module

_EXPORTS = {
    "ParameterError": "cadgen.params",
    "PlantingParameters": "cadgen.params",
    "DesignParameters": "cadgen.params",
    "MECHANISM_KINDS": "cadgen.params",
    "load_params": "cadgen.params",
    "validate_text": "cadgen.params",
    "validate_data": "cadgen.params",
    "run_analysis": "cadgen.pipeline.analyze",
    "write_bytes_atomic": "cadgen.export.atomic",
    "write_text_atomic": "cadgen.export.atomic",
    "staged_directory": "cadgen.export.atomic",
    "build": "cadgen.pipeline.build",
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
