"""The imports a build makes, made ahead by a process that forks builds.

A batch's local worker forks each design's build from itself (:mod:`cadgen.batch.isolated`).
The build imports scipy, shapely, trimesh, manifold3d, fcl, matplotlib and ezdxf as its
stages need them, so every forked design paid them again: about a third of a second of CPU
per design of the paper's. :func:`warm` imports what a design's scene will (its stages and
effects, :func:`cadgen.pipeline.plan.scene_plan`) in the forking process, once; each build
forked after it finds them loaded. Imports only: a build forked after :func:`warm` computes
what one in a fresh interpreter does.

What each stage imports is listed here, beside the stage names; tests/test_warm.py checks
that a build forked after warming for its scene loads no further third-party package, so the
lists cannot fall behind the stages' code unnoticed.
"""

from __future__ import annotations

import importlib

__all__ = ["STAGE_IMPORTS", "EFFECT_IMPORTS", "warm", "warm_all"]

#: The modules each stage imports that take time (third-party packages and the modules of
#: ours that load them); ``{mechanism}`` is the design's mechanism kind.
STAGE_IMPORTS = {
    "teeth": ("scipy.interpolate", "scipy.optimize", "shapely", "cadgen.gears.trains",
              "cadgen.machine.hubs", "cadgen.pipeline.gear_cache", "cadgen.pipeline.beside"),
    "parts": ("trimesh", "manifold3d", "cadgen.solids.{mechanism}", "cadgen.solids.outcome"),
    "arm_interference": ("fcl", "cadgen.pipeline.clearances"),
    "ground_clearance": ("fcl", "cadgen.pipeline.clearances"),
    "dynamics": ("cadgen.dynamics", "cadgen.dynamics.mass", "cadgen.machine.follower"),
    "plots": ("cadgen.report.plots.{mechanism}", "cadgen.report.plots.dynamics", "cadgen.report.plots.parts",
              "cadgen.report.plots.housings", "cadgen.report.plots.cam"),
}

#: The modules the writing of each effect's files imports (the report's writers always).
EFFECT_IMPORTS = {
    "dxf": ("ezdxf", "cadgen.export.dxf", "cadgen.export.train_sheet",
            "cadgen.export.cam_dxf"),
    "stl": ("cadgen.export.meshes",),
    "report": ("cadgen.report.html", "cadgen.report.animation"),
    None: ("cadgen.pipeline.writers", "cadgen.report.content"),
}


def warm(params, *, effects=None, case: str | None = None) -> list:
    """Import what a build of ``params`` will (its scene, or ``effects`` and ``case`` as
    :func:`cadgen.pipeline.build.build` takes them). Returns the modules' names.

    Raises
    ------
    cadgen.params.ParameterError
        A scene the build would refuse (:func:`cadgen.pipeline.plan.scene_plan`).
    ImportError
        A module that cannot be imported (the build would fail on it too).
    """
    from cadgen.pipeline.plan import scene_plan

    effects = tuple(effects) if effects is not None else params.scene.effects
    stages, _, _ = scene_plan(params, effects, case or params.scene.case)
    names = [name.format(mechanism=params.mechanism)
             for group in ([STAGE_IMPORTS.get(stage, ()) for stage in stages]
                           + [EFFECT_IMPORTS.get(effect, ()) for effect in (None, *effects)])
             for name in group]
    return _imported(names, figures="plots" in stages)


def warm_all() -> list:
    """Import what any build may (every stage's and effect's modules, both mechanisms): for
    a process made ready before its design is known (the studio's next build). Returns the
    modules' names."""
    from cadgen.params.loading import MECHANISM_KINDS

    names = [name.format(mechanism=mechanism)
             for group in (*STAGE_IMPORTS.values(), *EFFECT_IMPORTS.values())
             for name in group for mechanism in MECHANISM_KINDS]
    return _imported(names, figures=True)


def _imported(names, *, figures: bool) -> list:
    """Import ``names`` (each once, in order) and, for ``figures``, what drawing needs."""
    names = list(dict.fromkeys(names))
    for name in names:
        importlib.import_module(name)
    if figures:
        from cadgen.pipeline.figures import preload

        preload()   # matplotlib's Agg figure and the figures' font
    return names
