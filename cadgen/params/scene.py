"""The scene: the operating case and the effects a build evaluates (the optional ``[scene]`` table).

A build runs exactly the stages its effects need (see :mod:`cadgen.pipeline.build`); a
scene asking only for ``metrics`` generates no teeth, builds no solids and never
imports fcl. Left out, the scene is the field run with every effect. Its accuracy
preset (``draft``, ``standard``, ``fine``) sets every resolution knob the file leaves out.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BeforeValidator, Field, field_validator

from cadgen.params._tables import _list_to_tuple, _no_repeats, _Table

__all__ = ["EFFECTS", "CASES", "Effect", "SceneParameters", "PRESETS", "apply_preset"]


EFFECTS = ("metrics", "curves", "teeth", "meshing", "cam", "solids", "arm_interference",
           "ground_clearance", "dynamics", "dxf", "stl", "plots", "report")
"""Every effect a scene may ask for, in the order a build reports them."""

CASES = ("field", "bench")
"""``field``: a field run (plant spacings or forward speed, inclination, soil surface);
``bench``: an idle run on the bench, relative motion only (no soil: no hole metrics, no ground
clearance)."""

Effect = Literal["metrics", "curves", "teeth", "meshing", "cam", "solids", "arm_interference",
                 "ground_clearance", "dynamics", "dxf", "stl", "plots", "report"]


class SceneParameters(_Table):
    """The operating case and the effects to evaluate."""

    case: Literal["field", "bench"] = Field("field", description='"field" or "bench"')
    effects: Annotated[tuple[Effect, ...], BeforeValidator(_list_to_tuple)] = Field(
        EFFECTS, min_length=1, description="effects to evaluate (default: every one)")

    preset: Literal["draft", "standard", "fine"] = Field(
        "standard", description='accuracy preset: "draft", "standard" or "fine" (see cadgen.params.scene)')

    @field_validator("effects")
    @classmethod
    def _each_once(cls, effects: tuple) -> tuple:
        return _no_repeats(effects, "effect")

# ----------------------------------------------------------------------------------------------
# Accuracy presets: every resolution knob the file leaves out

PRESETS = {
    "draft": {"resolution.steps_per_revolution": 720, "resolution.closure_rtol": 1e-10,
              "resolution.inverse_grid": 360, "resolution.sweep_atol": 1e-3,
              "gears.flank_points": 32, "gears.chord_tolerance": 0.02,
              "solids.segments_per_circle": 48, "cam.profile_points": 1440},
    "standard": {"resolution.steps_per_revolution": 3600, "resolution.closure_rtol": 1e-13,
                 "resolution.inverse_grid": 720, "resolution.sweep_atol": 1e-6,
                 "gears.flank_points": 96, "gears.chord_tolerance": 0.005,
                 "solids.segments_per_circle": 96, "cam.profile_points": 3600},
    "fine": {"resolution.steps_per_revolution": 36000, "resolution.closure_rtol": 1e-15,
             "resolution.inverse_grid": 2880, "resolution.sweep_atol": 1e-9,
             "gears.flank_points": 384, "gears.chord_tolerance": 0.001,
             "solids.segments_per_circle": 256, "cam.profile_points": 14400},
}


def apply_preset(params, name: str):
    """``(params with the preset's knobs, {knob: (value, "preset" | "file")})``.

    Knobs the mechanism kind does not have (``steps_per_revolution`` on the
    pricking mechanism) are skipped; knobs set in the file keep the file's value.
    """
    knobs = PRESETS[name]
    updates: dict = {}
    used = {}
    for path, value in knobs.items():
        table_name, field = path.split(".")
        table = getattr(params, table_name, None)
        if table is None or field not in type(table).model_fields:
            continue
        if field in table.model_fields_set:
            used[path] = (getattr(table, field), "file")
            continue
        updates.setdefault(table_name, {})[field] = value
        used[path] = (value, "preset")
    tables = {name_: getattr(params, name_).model_copy(update=fields)
              for name_, fields in updates.items()}
    return params.model_copy(update=tables), used
