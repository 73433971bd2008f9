"""cadgen: from a mechanism parameter file to kinematics, metrics and manufacturable parts.

The public names below are imported on first use (PEP 562), so ``import cadgen``
and ``cadgen --help`` do not pay for pydantic, numpy or the geometry engines.
"""

from __future__ import annotations

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("cadgen")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0.0.0+unknown"

_EXPORTS = {
    "ParameterError": "cadgen.params",
    "PlantingParameters": "cadgen.params",
    "DesignParameters": "cadgen.params",
    "MECHANISM_KINDS": "cadgen.params",
    "load_params": "cadgen.params",
    "validate_text": "cadgen.params",
    "validate_data": "cadgen.params",
    "run_analysis": "cadgen.analyze",
    "write_bytes_atomic": "cadgen.atomic",
    "write_text_atomic": "cadgen.atomic",
    "staged_directory": "cadgen.atomic",
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'cadgen' has no attribute {name!r}")
    value = getattr(import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
