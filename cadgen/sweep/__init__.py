"""The sweep of the solids through a revolution: certified least distance and interference.

Five modules, one concept each:

- :mod:`cadgen.sweep.scene`: part instances, their poses and reach (the Lipschitz
  bound's geometric factor), and the scene interfaces a search asks of an engine;
- :mod:`cadgen.sweep.search`: the certified search over poses, engine-agnostic;
- :mod:`cadgen.sweep.pairwise`: the same search pair of parts by pair, each with
  its own speed bounds, climbing from cheap lower bounds to exact distances only
  where the certificate needs them;
- :mod:`cadgen.sweep.proxies`: convex-hull lower bounds of a distance, and the
  certificates that make them exact (numpy only);
- :mod:`cadgen.sweep.fcl`: the python-fcl adapter (:class:`FclScene`).

The public names below are imported on first use (PEP 562): importing fcl is
slow, and ``import cadgen.sweep`` must not pay for it nor for numpy.
"""

from __future__ import annotations

from importlib import import_module

_EXPORTS = {
    "Proximity": "cadgen.sweep.scene",
    "SweepScene": "cadgen.sweep.scene",
    "PairScene": "cadgen.sweep.scene",
    "instance_pose": "cadgen.sweep.scene",
    "part_reach": "cadgen.sweep.scene",
    "FclScene": "cadgen.sweep.fcl",
    "INTERFERENCE_XTOL": "cadgen.sweep.search",
    "INTERFERENCE_RESOLUTION": "cadgen.sweep.search",
    "MAX_EVALUATIONS": "cadgen.sweep.search",
    "SweepResult": "cadgen.sweep.search",
    "certified_distance": "cadgen.sweep.search",
    "plain_scan": "cadgen.sweep.search",
}

__all__ = list(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'cadgen.sweep' has no attribute {name!r}")
    value = getattr(import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
