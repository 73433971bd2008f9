"""Plots of the planting mechanism (matplotlib, Agg backend; imported only when plots are asked for)."""

from __future__ import annotations

import numpy as np

__all__ = ["planting_figures", "planting_figure_jobs"]

from cadgen.report.plots.base import _event_ticks, _figure, _legend_below, _png  # noqa: E402


def _events_deg(evaluation, soil: bool = True):
    """The events to mark (rad): soil entry, lowest point, exit; a bench run (no soil) has
    only the lowest point."""
    ev = evaluation.events
    if not soil:
        return {"lowest": ev.lowest}
    return {"entry": ev.entry, "lowest": ev.lowest, "exit": ev.exit}


def relative_path(mechanism, evaluation, phi, soil: bool = True):
    figure, ax = _figure(5.5, 8.0)
    # the model's arm 2 is arm 1 half a turn on (kinematics.planting): one loop, drawn once
    # (drawn for each, arm 1's lay hidden under arm 2's with both in the legend)
    tip = mechanism.motion(phi, "N").position
    ax.plot(tip[:, 0], tip[:, 1], color="0.2", lw=1.2,
            label="tip N, both arms (half a turn apart)")
    for arm, colour in ((0, "tab:blue"), (1, "tab:orange")):
        pose = mechanism.positions(np.array([0.0]), arm=arm, points=("C", "E", "P1", "N"))
        line = np.vstack([pose[k][0] for k in ("C", "E", "P1", "N")])
        ax.plot([0.0, line[0, 0]], [0.0, line[0, 1]], color="0.5", lw=2)
        ax.plot(line[:, 0], line[:, 1], "-o", color=colour, lw=2.2, ms=4, alpha=0.8,
                label=f"arm {arm + 1}")
    for circle in evaluation.housing_circles:
        if circle.gearbox != "gearbox2":
            continue
        centre = mechanism.motion(np.array([0.0]), circle.point).position[0]
        ax.add_patch(__import__("matplotlib.patches", fromlist=["Circle"]).Circle(
            centre, circle.radius, fill=False, ls=":", color="0.4"))
    if soil:
        ax.axhline(evaluation.events.soil_level, color="saddlebrown", lw=1.5,
                   label="soil surface")
    ax.plot([], [], ":", color="0.4", label="gearbox 2 housing circles")
    ax.plot([], [], "-o", color="0.5", ms=4, label="carrier O-C, arm C-E-P1-N")
    ax.plot([0], [0], "k+", ms=12)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm, forward travel)")
    ax.set_ylabel("y (mm)")
    ax.set_title("Relative tip path (bench idle run),\nboth arms at the catching pose", fontsize=10)
    _legend_below(figure, ncols=2)
    ax.grid(alpha=0.3)
    return _png(figure)


def absolute_paths(mechanism, evaluation, phi):
    figure, ax = _figure(5.8, 8.0)
    tip = mechanism.motion(phi, "N").position
    for hole in evaluation.holes:
        x = tip[:, 0] + hole.spacing / np.pi * phi
        ax.plot(x, tip[:, 1], lw=1.2, label=f"S = {hole.spacing:g} mm (hole width {hole.width:.1f} mm)")
        ev = evaluation.events
        marks = np.array([ev.entry, ev.exit])
        pts = mechanism.motion(marks, "N").position
        ax.plot(pts[:, 0] + hole.spacing / np.pi * marks, pts[:, 1], "k|", ms=10)
    ax.axhline(evaluation.events.soil_level, color="saddlebrown", lw=1.5, label="soil surface")
    ax.set_aspect("equal")
    ax.set_xlabel("X (mm, forward travel)")
    ax.set_ylabel("Y (mm)")
    ax.set_title("Absolute tip paths over one carrier revolution\n(| = soil entry, exit)",
                 fontsize=10)
    _legend_below(figure, ncols=1)
    ax.grid(alpha=0.3)
    return _png(figure)


def attitude(mechanism, evaluation, phi, soil: bool = True):
    figure, ax = _figure()
    ax.plot(np.degrees(phi), np.degrees(mechanism.attitude(phi)), lw=1.4, color="tab:blue",
            label="attitude Psi")
    events = _events_deg(evaluation, soil)
    colours = ("tab:orange", "tab:green", "tab:red") if soil else ("tab:green",)
    for (name, angle), colour in zip(events.items(), colours):
        value = np.degrees(mechanism.attitude(np.array([angle]))[0])
        ax.plot(np.degrees(angle), value, "o", color=colour,
                label=f"{name}: {value:.2f} deg at phi = {np.degrees(angle):.1f} deg")
    _event_ticks(ax, {name: np.degrees(angle) for name, angle in events.items()})
    ax.set_xlim(0, 360)
    ax.set_xlabel("carrier angle phi (deg)")
    ax.set_ylabel("planter attitude Psi (deg, 0 = upright)")
    ax.set_title("Planter attitude")
    ax.grid(alpha=0.3)
    _legend_below(figure, ncols=2)
    return _png(figure)


def velocity(mechanism, evaluation, phi, soil: bool = True):
    figure, ax = _figure()
    omega = 2 * np.pi * evaluation.carrier_speed_rpm / 60.0
    v = mechanism.motion(phi, "N").velocity * omega
    ax.plot(np.degrees(phi), np.hypot(v[:, 0], v[:, 1]), lw=1.4, label="relative speed |v|")
    for hole in evaluation.holes if soil else ():    # no forward travel on a bench
        drift = hole.spacing / np.pi * omega
        ax.plot(np.degrees(phi), np.hypot(v[:, 0] + drift, v[:, 1]), lw=1.0,
                label=f"absolute speed, S = {hole.spacing:g} mm")
    events = {name: np.degrees(angle) for name, angle in _events_deg(evaluation, soil).items()}
    for angle in events.values():
        ax.axvline(angle, color="0.6", ls=":")
    _event_ticks(ax, events)
    ax.set_xlim(0, 360)
    ax.set_xlabel("carrier angle phi (deg)")
    ax.set_ylabel(f"tip speed (mm/s at {evaluation.carrier_speed_rpm:g} r/min)")
    ax.set_title("Tip speed (dotted: soil entry, lowest point, exit)" if soil else
                 "Tip speed on the bench (dotted: lowest point)")
    _legend_below(figure, ncols=2)
    ax.grid(alpha=0.3)
    return _png(figure)


def pitch_curves(mechanism, evaluation, samples=1440):
    figure, ax = _figure(8.0, 4.4)
    t = np.linspace(0.0, 2 * np.pi, samples + 1)
    a = mechanism.centre_distance
    r1 = mechanism.pitch_curve.radius(t)
    # central gear: polar angle t in its own frame, contact direction towards D at start
    ax.plot(r1 * np.cos(t), r1 * np.sin(t), lw=1.5, label="central gear r1(t)")
    # intermediate gear (centre at distance a): radius a - r1(t) at polar angle pi - F(t)
    angle = np.pi - mechanism.intermediate_rotation(t)
    rho = a - r1
    ax.plot(a + rho * np.cos(angle), rho * np.sin(angle), lw=1.5, label="intermediate gear a - r1(t)")
    ax.plot([0, a], [0, 0], "k+", ms=10)
    ax.plot([r1[0]], [0], "ro", ms=4, label="contact at the catching position")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"Non-circular pair: a = {a:.4f} mm, module {evaluation.module:.3f} mm")
    _legend_below(figure, ncols=3)
    ax.grid(alpha=0.3)
    return _png(figure)


def planting_figure_jobs(mechanism, evaluation, samples: int = 1441, *,
                         soil: bool = True) -> dict:
    """``{file name: callable -> PNG bytes}`` of every plot of a planting design.

    ``soil=False`` (a bench run, whose report leaves out what needs soil): no absolute
    paths, and no soil line, soil entry and exit or absolute speeds on the others.
    """
    phi = np.linspace(0.0, 2 * np.pi, samples)
    jobs = {
        "relative_path.png": lambda: relative_path(mechanism, evaluation, phi, soil),
        "absolute_paths.png": lambda: absolute_paths(mechanism, evaluation, phi),
        "attitude.png": lambda: attitude(mechanism, evaluation, phi, soil),
        "tip_velocity.png": lambda: velocity(mechanism, evaluation, phi, soil),
        "pitch_curves.png": lambda: pitch_curves(mechanism, evaluation),
    }
    if not soil:
        del jobs["absolute_paths.png"]
    return jobs


def planting_figures(mechanism, evaluation, samples: int = 1441) -> dict:
    """PNG bytes of every plot of a planting design, keyed by file name."""
    return {name: draw() for name, draw in
            planting_figure_jobs(mechanism, evaluation, samples).items()}
