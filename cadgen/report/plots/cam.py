"""Plots of the duckbill cam: follower motion and blade opening over the carrier angle, the contour."""

from __future__ import annotations

import numpy as np

from cadgen.report.plots.base import _event_ticks, _figure, _fill, _legend_below, _png

__all__ = ["cam_figures", "cam_figure_jobs"]

_EVENT_STYLE = {"entry": "tab:brown", "lowest": "k", "exit": "tab:brown",
                "seedling_cleared": "tab:green"}


def follower_motion(design) -> bytes:
    """Roller lift and lever angle (top, each on its own axis), blade opening and mouth
    (bottom, each on its own axis) vs carrier angle; events named above, every line labelled."""
    import matplotlib.patches as patches

    phi = np.linspace(0.0, 2 * np.pi, 1441)
    lam, lift, beta = design.profile.follower_at_carrier(phi, design.cam_angle)
    figure, (top, bottom) = _figure(8.0, 6.5, nrows=2, sharex=True)
    degrees = np.degrees(phi)
    top.plot(degrees, lift, color="tab:blue", label="roller lift (mm, left axis)")
    top.set_ylabel("roller lift (mm)", color="tab:blue")
    lever = top.twinx()
    lever.plot(degrees, np.degrees(lam), color="tab:purple", ls="--",
               label="lever angle (deg, right axis)")
    lever.set_ylabel("lever angle (deg)", color="tab:purple")
    bottom.plot(degrees, np.degrees(beta), color="tab:red", label="blade opening (deg, left axis)")
    bottom.set_ylabel("blade opening (deg)", color="tab:red")
    mouth = design.linkage.mouth_width(beta)
    twin = bottom.twinx()
    twin.plot(degrees, mouth, color="tab:orange", ls=":", label="mouth width (mm, right axis)")
    twin.axhline(design.linkage.required_mouth, color="tab:orange", lw=0.8, alpha=0.6,
                 label=f"required mouth {design.linkage.required_mouth:g} mm (right axis)")
    twin.set_ylabel("mouth width (mm)", color="tab:orange")
    bottom.set_xlabel("carrier angle (deg, 0 = catching)")
    events = {name.replace("_", " "): np.degrees(angle)
              for name, angle in design.timing.events.items() if name != "catching"}
    for name, angle in design.timing.events.items():
        if name == "catching":
            continue
        for axes in (top, bottom):
            axes.axvline(np.degrees(angle), color=_EVENT_STYLE.get(name, "0.5"), lw=0.8, ls="-.")
    _event_ticks(top, events, rotation=30)
    for start, end in (design.timing.opening, design.timing.closing):
        top.axvspan(np.degrees(start), np.degrees(end), color="0.85", zorder=0)
    handles, labels = [], []
    for axes in (top, lever, bottom, twin):
        h, lab = axes.get_legend_handles_labels()
        handles += h
        labels += lab
    handles.append(patches.Patch(color="0.85"))
    labels.append("cam opening, closing (shaded)")
    _legend_below(figure, handles, labels, ncols=3, fontsize=7)
    top.set_title("Duckbill cam: closed through catching and transport, open from the lowest "
                  "point\nuntil the seedling is cleared (dash-dot lines: events named above)",
                  fontsize=9)
    for axes in (top, bottom):
        axes.grid(alpha=0.3)
        axes.set_xlim(0, 360)
    return _png(figure)


def contour(design, points: int) -> bytes:
    """The cam contour with its pitch curve, base circle and the checks' worst places."""
    profile, check = design.profile, design.check
    figure, ax = _figure(6.5, 7.2)
    working = profile.working_profile(points)
    pitch = profile.pitch_curve(points)
    _fill(ax, working[:, 0], working[:, 1], color="0.8", label="cam (working profile)")
    ax.plot(*np.vstack([working, working[:1]]).T, color="k", lw=0.8)
    ax.plot(*np.vstack([pitch, pitch[:1]]).T, color="tab:blue", ls="--", lw=0.8,
            label="pitch curve (roller centre)")
    import matplotlib.patches as patches

    for theta, colour, label in ((check.pressure_angle_at, "tab:red", "largest pressure angle"),
                                 (check.pitch_radius_at, "tab:purple", "smallest convex radius")):
        centre = profile.pitch_point(theta)[0][0]
        ax.add_patch(patches.Circle(centre, profile.roller_radius, fill=False, color=colour,
                                    label=label))
    ax.plot([0], [0], "k+", ms=12)
    ax.set_aspect("equal")
    ax.set_title(f"Cam: pressure angle max {np.degrees(check.pressure_angle_max):.1f} deg, "
                 f"smallest convex pitch radius {check.pitch_radius_convex_min:.2f} mm "
                 f"(roller {profile.roller_radius:g} mm)", fontsize=9)
    ax.set_xlabel("x (mm, cam frame)")
    ax.set_ylabel("y (mm)")
    _legend_below(figure, ncols=2)
    ax.grid(alpha=0.3)
    return _png(figure)


def cam_figure_jobs(design, points: int) -> dict:
    """``{file name: callable -> PNG bytes}`` of the cam's two pictures."""
    return {"cam-follower.png": lambda: follower_motion(design),
            "cam-contour.png": lambda: contour(design, points)}


def cam_figures(design, points: int) -> dict:
    return {name: draw() for name, draw in cam_figure_jobs(design, points).items()}
