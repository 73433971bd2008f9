"""Which stages a scene runs: the effects' stages and the stages' own needs, the effects that
mean nothing for a design (set aside with the reason), and what a build refuses before any
stage runs (:func:`scene_plan`).

A scene (``[scene]`` in the file, or ``effects``/``case`` given to
:func:`cadgen.pipeline.build.build`) names the effects wanted; :func:`plan` resolves the
stages they need, in run order, and nothing else runs: a scene asking only for ``metrics``
generates no teeth, builds no solids and never imports fcl.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EFFECT_STAGES", "STAGE_NEEDS", "STAGE_ORDER", "NOT_APPLICABLE", "plan",
           "scene_plan", "stage_warnings", "BuildPlan", "check_build"]


#: The stages each effect needs (their own needs are added by :func:`plan`).
EFFECT_STAGES = {
    "metrics": ("metrics",),
    "curves": ("kinematics",),
    "teeth": ("drivetrain", "teeth"),    # every gear bored for its shaft
    "meshing": ("drivetrain", "teeth"),  # the meshing check is part of cutting (tip relief)
    "cam": ("cam",),
    "solids": ("cam", "parts"),       # gears among the solids when "teeth" runs too
    "arm_interference": ("cam", "parts", "arm_interference"),
    "ground_clearance": ("metrics", "parts", "ground_clearance"),
    # the drive's input, the journals and the duckbill's spring are the drivetrain's; the
    # soil level and the seedling's release the metrics' and the cam's; the masses come from
    # the solids when the scene builds them (else estimated), never built for the dynamics
    "dynamics": ("metrics", "cam", "drivetrain", "dynamics"),
    "dxf": (),                 # the cutting files of the teeth and cam that run (both if alone)
    "stl": ("cam", "parts"),
    # the trajectory, attitude and speed figures are drawn from the metrics' events (soil
    # line, holes); the plots stage itself needs only the kinematics, so that the gears'
    # figures are still drawn when the metrics fail
    "plots": ("metrics", "plots"),
    # the report's verdict is the metrics against the targets: asked alone it once ran no
    # stage at all and said PASSED of nothing
    "report": ("metrics",),
}

#: Each stage's own needs, and the order stages run in.
STAGE_NEEDS = {
    "kinematics": (),
    "metrics": ("kinematics",),
    "cam": ("metrics",),
    # the planting drivetrain is sized from its dynamics, which read the soil (metrics) and the
    # cam's spring: every scene that designs it designs the same one
    "drivetrain": ("kinematics", "metrics", "cam"),
    "teeth": ("kinematics",),
    "parts": ("metrics", "drivetrain"),
    "arm_interference": ("parts",),
    "ground_clearance": ("parts",),
    "dynamics": ("kinematics", "drivetrain"),
    "plots": ("kinematics",),
}
STAGE_ORDER = tuple(STAGE_NEEDS)

#: Effects with no meaning for a mechanism kind or an operating case (reported, not run).
NOT_APPLICABLE = {
    ("pricking", "cam"): "the pricking mechanism has no cam",
    ("pricking", "arm_interference"): "the pricking mechanism has a single arm",
    ("bench", "ground_clearance"): "a bench run has no soil",
}


def plan(effects, mechanism: str = "planting", case: str = "field"):
    """Stages to run for ``effects`` (in run order) and the effects set aside with the reason."""
    wanted, set_aside, applicable = set(), {}, set()
    for effect in effects:
        reason = NOT_APPLICABLE.get((mechanism, effect)) or NOT_APPLICABLE.get((case, effect))
        if reason:
            set_aside[effect] = reason
            continue
        applicable.add(effect)
        wanted.update(EFFECT_STAGES[effect])
    # alone among the effects that apply (a cam asked of the pricking mechanism is not there)
    if "dxf" in applicable and not {"teeth", "meshing", "cam", "solids", "stl"} & applicable:
        # asked alone, DXF means every cutting file, the gears bored for their shafts as the
        # teeth effect cuts them (it once cut them without the drivetrain: other bores)
        wanted.update((*EFFECT_STAGES["teeth"], *EFFECT_STAGES["cam"]))
    if mechanism == "pricking":
        wanted.discard("cam")
        wanted.discard("arm_interference")
    if case == "bench":
        wanted.discard("ground_clearance")
    closed = set()
    stack = list(wanted)
    while stack:
        stage = stack.pop()
        if stage not in closed:
            closed.add(stage)
            stack.extend(STAGE_NEEDS[stage])
    if mechanism == "pricking":   # the drivetrain's need of a cam is the planting one's
        closed.discard("cam")
    return [s for s in STAGE_ORDER if s in closed], set_aside


def scene_plan(params, effects, case: str = "field"):
    """``(stages, set_aside, warnings)`` of a scene for a validated design: what
    :func:`build` runs, the effects it sets aside with the reason, and the stage problems
    it keeps as warnings.

    Raises
    ------
    cadgen.params.ParameterError
        What :func:`build` refuses before any stage runs: a problem of a stage the scene
        runs (:func:`stage_warnings`), or no effect of the scene applying to the design.
    """
    stages, set_aside = plan(effects, params.mechanism, case)
    if not stages:
        _nothing_to_build(set_aside)
    return stages, set_aside, stage_warnings(params, stages)


def _nothing_to_build(set_aside: dict) -> None:
    """Refuse a scene none of whose effects applies to the design (a cam asked of the pricking
    mechanism): its build would run no stage and say PASSED of nothing."""
    from cadgen.params import ParameterError
    from kinematics.errors import Problem

    reasons = "; ".join(f"{effect}: {reason}" for effect, reason in set_aside.items())
    raise ParameterError([Problem("scene.effects", "nothing_to_build",
                                  "no effect of the scene applies to this design"
                                  + (f" ({reasons})" if reasons else ""))])


def stage_warnings(params, stages) -> list:
    """The stage problems of ``params`` whose stage is not in ``stages``, as warnings.

    Raises
    ------
    cadgen.params.ParameterError
        With the stage problems whose stage is in ``stages`` (the build cannot run it).
    """
    from cadgen.params import ParameterError, stage_problems

    problems = stage_problems(params)
    refused = [p for p in problems if p.stage in stages]
    if refused:
        raise ParameterError(refused)
    return [p for p in problems if p.stage not in stages]


@dataclass(frozen=True)
class BuildPlan:
    """What a build of a design will do, decided before any stage runs (:func:`check_build`).

    Attributes
    ----------
    params
        The design with its accuracy preset's knobs (those the file leaves out).
    preset : str
    knobs : dict
        ``{knob path: (value, "preset" | "file")}``.
    effects : tuple
    case : str
    stages : list
        The stages it runs, in order.
    set_aside : dict
        ``{effect: reason}``: effects that mean nothing for this design or case.
    warnings : list
        Problems of stages it does not run (a build running them would refuse the design).
    """

    params: object
    preset: str
    knobs: dict
    effects: tuple
    case: str
    stages: list
    set_aside: dict
    warnings: list


def check_build(params, *, effects=None, case=None, preset=None) -> BuildPlan:
    """What :func:`cadgen.build` will do with ``params``: its stages, or its refusal.

    The one decision both ``cadgen build`` and ``cadgen validate`` make: validate answers for
    the file's own scene (``effects``, ``case`` and ``preset`` left None), so a problem that
    refuses the build is an error there too, and one of a stage the scene does not run is a
    warning in both.

    Raises
    ------
    cadgen.params.ParameterError
        What a build refuses before any stage runs: a problem of a stage the scene runs
        (:func:`stage_warnings`), or no effect of the scene applying to the design.
    """
    from cadgen.params.scene import apply_preset

    scene = params.scene
    preset = preset or scene.preset
    params, knobs = apply_preset(params, preset)
    effects = tuple(effects) if effects is not None else scene.effects
    case = case or scene.case
    stages, set_aside, warnings = scene_plan(params, effects, case)
    return BuildPlan(params, preset, knobs, effects, case, stages, set_aside, warnings)
