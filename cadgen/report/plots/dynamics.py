"""Figures of the dynamics: input torque and power, mesh forces, bearing loads, shaking force.

Drawn from report.json's ``dynamics`` section (plain lists), so the figures show exactly
the numbers the report gives; the events (each arm's catch, soil entry, lowest point, exit)
are marked on the carrier-angle axis.
"""

from __future__ import annotations

import numpy as np

from cadgen.report.plots.base import _event_ticks, _figure, _legend_below, _png

__all__ = ["dynamics_figure_jobs", "torque_and_power", "mesh_forces", "bearing_loads",
           "shaking_polar"]


#: The planting mechanism's carrier-angle axis (a section may name its own).
PLANTING_ANGLE_LABEL = "carrier angle (deg, 0 = arm 1 catching)"


def _label(section: dict) -> str:
    return section.get("carrier_angle_label", PLANTING_ANGLE_LABEL)


def _events(events, section: dict | None = None) -> dict:
    """``{label: carrier angle deg}`` of both arms' events (arm 2 half a turn later), or the
    section's own ``events_deg`` (the pricking mechanism's dead centre, soil entry and exit)."""
    if section is not None and "events_deg" in section:
        return dict(section["events_deg"])
    if events is None:
        return {"catch 1": 0.0, "catch 2": 180.0}
    out = {}
    for arm, shift in ((1, 0.0), (2, 180.0)):
        out[f"catch {arm}"] = shift
        for name in ("entry", "lowest", "exit"):
            out[f"{name} {arm}"] = (np.degrees(getattr(events, name)) + shift) % 360.0
    return out


def _mark(axes, events: dict, label: bool) -> None:
    for angle in events.values():
        axes.axvline(angle, color="0.6", lw=0.7, ls="-.")
    if label:
        _event_ticks(axes, events, rotation=45, fontsize=6)


def torque_and_power(section: dict, events) -> bytes:
    """Input torque (top) and power (bottom) over the carrier angle, with peak, RMS, mean."""
    angle = np.asarray(section["carrier_angle_deg"])
    torque = np.asarray(section["input_torque_nm"])
    power = np.asarray(section["input_power_w"])
    stats = section["summary"]
    figure, (top, bottom) = _figure(8.0, 6.5, nrows=2, sharex=True)
    marks = _events(events, section)
    top.plot(angle, torque, color="tab:blue", label="input torque (N m)")
    for value, style, name in ((stats["input_torque_nm"]["rms"], ":", "RMS"),
                               (stats["input_torque_nm"]["mean"], "--", "mean")):
        top.axhline(value, color="tab:blue", ls=style, lw=0.8, label=f"{name} {value:.3g} N m")
    bottom.plot(angle, power, color="tab:red", label="input power (W)")
    bottom.axhline(stats["input_power_w"]["mean"], color="tab:red", ls="--", lw=0.8,
                   label=f"mean {stats['input_power_w']['mean']:.3g} W")
    top.set_ylabel("input torque (N m)")
    bottom.set_ylabel("input power (W)")
    bottom.set_xlabel(_label(section))
    _mark(top, marks, True)
    _mark(bottom, marks, False)
    for axes in (top, bottom):
        axes.grid(alpha=0.3)
        axes.set_xlim(0, 360)
    top.set_title(f"Drive at {section['carrier_speed_rpm']:g} r/min (input shaft "
                  f"{section['input_speed_rpm']:g} r/min), load case {section['load_case']}, "
                  f"{section['mass_properties_source']} masses", fontsize=9)
    handles, labels = [], []
    for axes in (top, bottom):
        h, lab = axes.get_legend_handles_labels()
        handles += h
        labels += lab
    _legend_below(figure, handles, labels, ncols=3, fontsize=7)
    return _png(figure)


def _curves(axes, angle, curves: dict, ylabel: str) -> None:
    for name, values in curves.items():
        axes.plot(angle, values, lw=0.9, label=name)
    axes.set_ylabel(ylabel)
    axes.grid(alpha=0.3)
    axes.set_xlim(0, 360)


def mesh_forces(section: dict, events) -> bytes:
    """Every mesh's normal force over the carrier angle (arm 1 and the drive)."""
    angle = np.asarray(section["carrier_angle_deg"])
    forces = {name: values for name, values in section["mesh_normal_force_n"].items()
              if "(arm 2)" not in name}
    figure, axes = _figure(8.0, 5.5)
    _curves(axes, angle, forces, "normal force along the line of action (N)")
    _mark(axes, _events(events, section), True)
    axes.set_xlabel(_label(section))
    axes.set_title("Gear mesh forces (arm 1's train and the drive; arm 2's are half a turn "
                   "later)" if "bodies" not in section else "Gear mesh forces", fontsize=9)
    _legend_below(figure, *axes.get_legend_handles_labels(), ncols=3, fontsize=6)
    return _png(figure)


def bearing_loads(section: dict, events) -> bytes:
    """Every pin's resultant bearing force over the carrier angle (arm 1 and the machine)."""
    angle = np.asarray(section["carrier_angle_deg"])
    forces = {name: values for name, values in section["bearing_force_n"].items()
              if not name.endswith(" 2")}
    figure, axes = _figure(8.0, 5.5)
    _curves(axes, angle, forces, "bearing force, planar resultant (N)")
    _mark(axes, _events(events, section), True)
    axes.set_xlabel(_label(section))
    axes.set_title("Bearing loads: each shaft's two bearings together"
                   + (" (arm 1 and the machine)" if "bodies" not in section else ""), fontsize=9)
    _legend_below(figure, *axes.get_legend_handles_labels(), ncols=3, fontsize=7)
    return _png(figure)


def shaking_polar(section: dict) -> bytes:
    """The shaking force on the frame as a polar curve (its tip over a carrier turn)."""
    force = np.asarray(section["shaking_force_n"])
    figure, axes = _figure(6.0, 6.2)
    closed = np.vstack([force, force[:1]])
    axes.plot(closed[:, 0], closed[:, 1], color="tab:purple",
              label="shaking force on the frame (N)")
    axes.plot([0], [0], "k+")
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_xlabel("x, forward (N)")
    axes.set_ylabel("y, up (N)")
    axes.grid(alpha=0.3)
    axes.set_title(f"Shaking force over a carrier turn (peak "
                   f"{section['summary']['shaking_force_peak_n']:.3g} N, moment about O peak "
                   f"{section['summary']['shaking_moment_peak_nm']:.3g} N m)", fontsize=9)
    _legend_below(figure, *axes.get_legend_handles_labels(), ncols=1, fontsize=7)
    return _png(figure)


def dynamics_figure_jobs(section: dict, events) -> dict:
    """``{file name: callable -> PNG bytes}`` of the dynamics figures."""
    return {"dynamics-torque.png": lambda: torque_and_power(section, events),
            "dynamics-meshes.png": lambda: mesh_forces(section, events),
            "dynamics-bearings.png": lambda: bearing_loads(section, events),
            "dynamics-shaking.png": lambda: shaking_polar(section)}
