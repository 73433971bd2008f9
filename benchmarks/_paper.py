"""The paper's planting design built up to its solids, and its two sweep scenes (shared by the
benchmarks that time the sweeps)."""

from __future__ import annotations

import math
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PARAMS = REPO / "params" / "xin2024-planter.toml"
_Z = (0.0, 0.0, 1.0)


def sweep_cases():
    """``[(label, scene factory, lipschitz, acceleration, upper)]`` with the build's own bounds."""
    from cadgen.pipeline.build import STAGE_FUNCTIONS, _Build
    from cadgen.pipeline.clearances import _arm_bounds, arm_groups
    from cadgen.params import load_params
    from cadgen.sweep.fcl import FclScene
    from cadgen.sweep.scene import part_reach

    params = load_params(PARAMS)
    run = _Build(params, ["kinematics", "metrics", "cam", "drivetrain", "parts"], None)
    run.effects, run.case = ["solids"], "field"
    run.run(STAGE_FUNCTIONS)
    mechanism, assembly = run.values["kinematics"], run.values["parts"].assembly
    parts = {part.name: part for part in assembly.parts}
    speed, acceleration = _arm_bounds(mechanism, parts, run.values["cam"])
    rc = mechanism.carrier_radii["C"]
    halves = ("base", "cover")
    ground_speed = max(max(part_reach(parts[f"gearbox1-{h}"], axis=_Z) for h in halves),
                       rc + max(part_reach(parts[f"gearbox2-{h}"], axis=_Z) for h in halves))
    arm1, arm2 = arm_groups(assembly)
    housings = ([f"gearbox1-{h}" for h in halves]
                + [f"gearbox2-{h}-arm{k}" for h in halves for k in (1, 2)])
    return [
        ("arm to arm (blades included)",
         lambda: FclScene(assembly, arm1, arm2),
         2 * speed, 2 * acceleration, math.pi),
        ("housings to ground",
         lambda: FclScene(assembly, housings, ["ground"]),
         ground_speed, ground_speed, 2 * math.pi),
    ]
