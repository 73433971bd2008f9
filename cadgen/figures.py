"""The pictures of a build: one PNG per view of what its stages made (matplotlib, Agg)."""

from __future__ import annotations

import numpy as np

__all__ = ["build_figures"]


def build_figures(run) -> dict:
    """``{file name: PNG bytes}`` for every stage that ran: paths, gears, cam, solids, sweeps."""
    ok = {r.stage for r in run.records if r.status == "ok"}
    values, params = run.values, run.params
    figures = {}
    if params.mechanism == "pricking":
        if {"kinematics", "metrics"} <= ok:
            from .plots_pricking import pricking_figures

            figures.update(pricking_figures(params, values["kinematics"], values["metrics"]))
    elif "metrics" in ok:
        from .plots import planting_figures

        figures.update(planting_figures(values["kinematics"], values["metrics"]))
    if "teeth" in ok and values["teeth"].stages:
        from .gear_trains import pair_figures

        figures.update(pair_figures(values["teeth"]))
    if "cam" in ok:
        from .plots_cam import cam_figures

        figures.update(cam_figures(values["cam"], params.cam.profile_points))
    if "parts" in ok:
        figures["assembly.png"] = _assembly(run)
    sweeps = {key: values[key] for key in ("arm_interference", "ground_clearance") if key in ok}
    if sweeps:
        from .plots_sweep import clearance_figure

        figures["clearance.png"] = clearance_figure(sweeps)
    run.figures = figures
    return figures


def _assembly(run) -> bytes:
    from .plots_solids import assembly_view

    outcome, params, values = run.values["parts"], run.params, run.values
    angle = outcome.carrier_angle
    if params.mechanism == "pricking":
        design, field = values["kinematics"], values["metrics"]
        loop = design.motion.tip(np.linspace(0, design.motion.period, 721))
        return assembly_view(outcome.assembly, angle, paths=[(loop, "needle-tip loop")],
                             soil_level=field[0].surface_level,
                             title=f"Solids {np.degrees(angle):g} deg of carrier turn after the "
                                   "outer dead centre (front view, in the mechanism plane)")
    mechanism = values["kinematics"]
    tip = mechanism.motion(np.linspace(0, 2 * np.pi, 721), "N").position
    return assembly_view(outcome.assembly, angle, paths=[(tip, "tip path N (relative)")],
                         soil_level=values["metrics"].events.soil_level,
                         title=f"Solids at carrier angle {np.degrees(angle):g} deg (front view)")
