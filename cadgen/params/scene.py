"""The scene: the operating case and the effects a build evaluates (the optional ``[scene]`` table).

A build runs exactly the stages its effects need (see :mod:`cadgen.pipeline.build`); a
scene asking only for ``metrics`` generates no teeth, builds no solids and never
imports fcl. Left out, the scene is the field run with every effect.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BeforeValidator, Field, field_validator

from cadgen.params._tables import _list_to_tuple, _no_repeats, _Table

__all__ = ["EFFECTS", "CASES", "Effect", "SceneParameters"]

EFFECTS = ("metrics", "curves", "teeth", "meshing", "cam", "solids", "arm_interference",
           "ground_clearance", "dxf", "stl", "plots", "report")
"""Every effect a scene may ask for, in the order a build reports them."""

CASES = ("field", "bench")
"""``field``: a field run (plant spacings or forward speed, inclination, soil surface);
``bench``: an idle run on the bench, relative motion only (no soil: no hole metrics, no ground
clearance)."""

Effect = Literal["metrics", "curves", "teeth", "meshing", "cam", "solids", "arm_interference",
                 "ground_clearance", "dxf", "stl", "plots", "report"]


class SceneParameters(_Table):
    """The operating case and the effects to evaluate."""

    case: Literal["field", "bench"] = Field("field", description='"field" or "bench"')
    effects: Annotated[tuple[Effect, ...], BeforeValidator(_list_to_tuple)] = Field(
        EFFECTS, min_length=1, description="effects to evaluate (default: every one)")

    preset: Literal["draft", "standard", "fine"] = Field(
        "standard", description='accuracy preset: "draft", "standard" or "fine" (see cadgen.params.presets)')

    @field_validator("effects")
    @classmethod
    def _each_once(cls, effects: tuple) -> tuple:
        return _no_repeats(effects, "effect")
