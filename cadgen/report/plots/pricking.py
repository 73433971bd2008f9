"""Plots of a pricking-mechanism design (matplotlib, Agg; imported only when plots are asked for)."""

from __future__ import annotations

import numpy as np

from cadgen.report.plots.base import _figure, _legend_below, _png, _suptitle
from kinematics.planar import unit as _unit

__all__ = ["pricking_figures"]


def loop(design):
    figure, ax = _figure(7.5, 6.5)
    curve, link, motion = design.curve, design.linkage, design.motion
    centre = np.asarray(link.centre)
    u = np.linspace(0.0, curve.period, 1500)
    path = curve(u)
    ax.plot(path[:, 0], path[:, 1], lw=1.6, label=f"tip loop (degree {curve.degree})")
    ax.plot(curve.points[:, 0], curve.points[:, 1], "ko", ms=4, label="type-value points Q")
    for k, point in enumerate(curve.points):
        # the label pushed outwards from the loop's centroid, off the curve
        away = point - path.mean(axis=0)
        away = 11 * away / max(float(np.hypot(*away)), 1e-9)
        ax.annotate(f"Q{k + 1}", point, textcoords="offset points", xytext=tuple(away),
                    ha="center", va="center", fontsize=8,
                    bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8})
    angles = np.linspace(-np.pi, np.pi, 720)
    for radius, style, label in ((link.l + 2 * link.a, "--", "reach l + 2a"),
                                 (link.l - 2 * link.a, ":", "reach l - 2a")):
        ring = centre + radius * _unit(angles)
        ax.plot(ring[:, 0], ring[:, 1], style, color="0.6", lw=0.8, label=label)
    for u_dead, marker, label in ((link.u_max, "r^", "dead centre R max"),
                                  (link.u_min, "rv", "dead centre R min")):
        ax.plot(*curve(u_dead), marker, ms=8, label=label)
    # the linkage at the lowest point of the loop
    v = np.linspace(0.0, motion.period, 2000, endpoint=False)
    low = v[np.argmin(curve(motion.u(v))[:, 1])]
    phi1, phi2 = float(motion.phi1(low)), float(motion.phi2(low))
    a_point = centre + link.a * _unit(phi1)
    b_point = centre + 2 * link.a * _unit(phi1)
    d_point = b_point + link.l * _unit(phi2)
    chain = np.vstack([centre, a_point, b_point, d_point])
    ax.plot(chain[:, 0], chain[:, 1], "-o", color="tab:green", lw=2, ms=4,
            label="O-A-B-D at the lowest point")
    ax.plot(*centre, "k+", ms=12)
    ax.set_aspect("equal")
    bottom = min(path[:, 1].min(), centre[1]) - 20
    top = max(path[:, 1].max(), centre[1]) + 20
    ax.set_ylim(bottom, top)
    ax.set_xlim(path[:, 0].min() - 60, path[:, 0].max() + 60)
    ax.set_xlabel("x (mm, forward travel)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"Tip loop, a = {link.a:.3f} mm, l = {link.l:.3f} mm, carrier "
                 f"{design.carrier_sense}", fontsize=10)
    _legend_below(figure, ncols=3)
    ax.grid(alpha=0.3)
    return _png(figure)


def pitch_curves(design):
    # the layout keeps each title clear of the tick labels of the plot above
    figure, axes = _figure(9.0, 8.5, nrows=2, ncols=2)
    for ax, gear in zip(axes.ravel(), design.gears):
        radius, angle = gear.table["radius"], gear.table["body_angle"]
        xy = np.c_[radius * np.cos(angle), radius * np.sin(angle)]
        closed = np.vstack([xy, xy[:1]])
        ax.plot(closed[:, 0], closed[:, 1], lw=1.4, color="tab:blue")
        carrier = np.degrees(design.motion.sense * (gear.table["carrier_angle"]
                                                    - design.motion.phi1_start))
        for stretch in gear.concave_stretches:
            low, high = sorted(stretch["carrier_deg"])
            mask = (carrier >= low - 0.5) & (carrier <= high + 0.5)
            ax.plot(xy[mask, 0], xy[mask, 1], ".", color="red", ms=3)
        ax.plot(0, 0, "k+", ms=10)
        state = "convex" if gear.convex else "CONCAVE (red)"
        ax.set_title(f"{gear.name} (stage {gear.stage}, {gear.role}): {state}\n"
                     f"perimeter {gear.perimeter:.2f} mm, max pressure-angle dev. "
                     f"{gear.pressure_angle_deviation_max_deg:.1f} deg", fontsize=9)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=8)
        ax.grid(alpha=0.3)
    _suptitle(figure, f"Pitch curves: teeth {design.teeth[0]} / {design.teeth[1]}, modules "
                      f"{design.modules[0]:.3f} / {design.modules[1]:.3f} mm, "
                      f"scale {design.scale:.4f}")
    return _png(figure)


def ratio(design):
    figure, ax = _figure()
    stage_1 = design.gears[0].table["radius"] / design.gears[1].table["radius"]
    stage_2 = design.gears[2].table["radius"] / design.gears[3].table["radius"]
    progress = np.degrees(design.motion.sense * (design.grid["carrier_angle"]
                                                 - design.motion.phi1_start))
    ax.plot(progress, stage_1 * stage_2, lw=1.6, label="total i = 1 - dphi2/dphi1")
    ax.plot(progress, stage_1, lw=1.0, label=f"stage 1, i1 = K i^w (w = {design.exponent:.3f})")
    ax.plot(progress, stage_2, lw=1.0, label="stage 2, i2 = i / i1")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("carrier progress from the outer dead centre (deg)")
    ax.set_ylabel("ratio (planet relative to carrier)")
    ax.set_title("Transmission ratios along the loop")
    ax.set_xlim(progress.min(), progress.max())
    _legend_below(figure, ncols=2)
    ax.grid(alpha=0.3)
    return _png(figure)


def field_paths(design, field, params):
    from kinematics.pricking_field import _FieldModel

    figure, ax = _figure(9.0, 4.6)
    model = _FieldModel(design, params.field.carrier_speed_rpm, params.field.forward_speed)
    v = np.linspace(0.0, 2 * design.motion.period, 3000)
    x = model.absolute_x(v)
    y = model.tip(v)[:, 1]
    for result in field:
        c = np.cos(np.radians(result.inclination_deg))
        line, = ax.plot(x, y * c, lw=1.2, label=f"theta = {result.inclination_deg:g} deg: entry "
                        f"{result.entry_angle_deg:.1f}, exit {result.exit_angle_deg:.1f} deg, "
                        f"mouth {result.hole_mouth:.1f} mm")
        ax.axhline(result.surface_level * c, color=line.get_color(), ls=":", lw=0.8)
        # the needle (tip to root) at entry and exit, projected into the hole's plane
        for s in (result.entry_parameter, result.exit_parameter):
            s = np.array([s, s + design.motion.period])
            tip, root = model.tip(s), model.root(s)
            shift = model.absolute_x(s) - tip[:, 0]
            for k in range(2):
                ax.plot([tip[k, 0] + shift[k], root[k, 0] + shift[k]],
                        [tip[k, 1] * c, root[k, 1] * c], color=line.get_color(), lw=2.2,
                        alpha=0.6)
    ax.set_xlabel("X (mm, forward travel)")
    ax.set_ylabel("Y in the hole's vertical plane (mm)")
    ax.set_title("Absolute needle-tip paths and needle postures at entry and exit\n"
                 "per inclination (dotted: soil surface)", fontsize=10)
    ax.set_aspect("equal")
    ax.margins(x=0.02, y=0.1)   # room above the needles' roots
    _legend_below(figure, ncols=1)
    ax.grid(alpha=0.3)
    return _png(figure)


def pricking_figure_jobs(params, design, field, *, soil: bool = True) -> dict:
    """``{file name: callable -> PNG bytes}`` of every plot of a pricking design; a bench run
    (``soil=False``, whose report leaves out what needs soil) has no field paths."""
    jobs = {"loop.png": lambda: loop(design), "pitch_curves.png": lambda: pitch_curves(design),
            "ratio.png": lambda: ratio(design)}
    if soil:
        jobs["field_paths.png"] = lambda: field_paths(design, field, params)
    return jobs


def pricking_figures(params, design, field) -> dict:
    """PNG bytes of every plot of a pricking design, keyed by file name."""
    return {name: draw() for name, draw in pricking_figure_jobs(params, design, field).items()}
