"""Accuracy against time for the planting mechanism's kinematics and metrics.

Run:  python -m benchmarks.accuracy [--output docs/accuracy.md]

Every figure is measured in this run against a converged reference computed in
the same run (refined metrics at 72,000 steps per revolution). Two ways of
getting the metrics are compared at 360, 3,600 and 36,000 steps:

* ``sampled``: the metrics read off the samples (extremes = extreme samples,
  crossings by linear interpolation between samples), the usual habit of a
  spreadsheet or a MATLAB GUI: the peer;
* ``refined``: this project's method (certified minima, Brent roots on the
  continuous model).

The closure quadrature (periodic trapezoid rule) is measured per node count
against the converged centre distance, with the 1-degree rectangle rule as the
paper's peer.

The population screen of ``cadgen optimize`` (its grid samples per revolution) against
the exact path, see :mod:`benchmarks.screen`.

Solids: the mesh resolution (segments per circle, flank points per tooth) against
closed forms and converged references, see :mod:`benchmarks.mesh_resolution`. Teeth
(flank points against a simulated cut), DXF chord tolerance and the sweep tolerance,
see :mod:`benchmarks.knobs`, which also draws ``docs/accuracy.png``: error against time
of every knob, log-log.

Pricking mechanism: the inverse solve is exact along the curve (piecewise
Chebyshev); the resolution knob is the uniform carrier grid on which the pitch
curves are tabulated for manufacture. Its accuracy is measured by rebuilding
the tip loop from those tables alone (forward check) and by the closure of the
integrated ratio.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from kinematics.clearance import _centre_line, _lowest_of_circles, polyline_distance
from cadgen.solids.housings import envelope_circles
from kinematics.evaluation import evaluate_planting
from kinematics.pitch_curves import (LimaconPitchCurve, centre_distance_at_nodes, polar_perimeter,
                                     solve_closure)
from kinematics.planting import PlantingMechanism

PAPER = dict(a1=1.2, b1=27.5, c1=-5.5, d1=30.5, e1=2.66, e2=1.0, f1=8.55, f2=4.24, g1=-6.95, g2=-4.0)
SPACINGS = (150.0, 185.0, 200.0)
DEPTH = 35.0
TEETH = 22
LENGTH_KEYS = ("trajectory_height", "hole_width", "hole_verticality", "arm_distance",
               "ground_clearance")


def mechanism():
    return PlantingMechanism(LimaconPitchCurve(**PAPER), 1.2, 1.1, 36.0, 27.0, 130.0, 190.0)


def refined_metrics(steps):
    m = mechanism()
    result = evaluate_planting(m, teeth=TEETH, depth=DEPTH, spacings=SPACINGS, steps=steps,
                               housing_circles=envelope_circles(m, m.module(TEETH), 6.0))
    return {(k.key, k.spacing): k.value for k in result.metrics if k.key != "soil_penetrations"}


def sampled_metrics(steps):
    """The peer: every metric read off ``steps`` samples per revolution."""
    m = mechanism()
    phi = np.linspace(0, 2 * np.pi, steps + 1)
    tip = m.motion(phi, "N").position
    y = tip[:, 1]
    low = int(y.argmin())
    soil = y[low] + DEPTH
    below = y < soil
    entry_i = low
    while below[entry_i - 1]:
        entry_i -= 1
    exit_i = low
    while below[exit_i + 1]:
        exit_i += 1

    def interpolate(i, j):  # crossing between samples i (above) and j (below), linear
        w = (y[i] - soil) / (y[i] - y[j])
        return phi[i] + w * (phi[j] - phi[i])

    entry, leave = interpolate(entry_i - 1, entry_i), interpolate(exit_i + 1, exit_i)
    out = {("trajectory_height", None): np.ptp(y)}
    psi = m.attitude(np.array([entry, leave]))
    out[("angle_difference", None)] = abs(np.degrees(psi[1] - psi[0]))
    ends = m.motion(np.array([entry, leave]), "N").position[:, 0]
    for s in SPACINGS:
        x_in, x_out = ends + s / np.pi * np.array([entry, leave])
        x_low = tip[low, 0] + s / np.pi * phi[low]
        out[("hole_width", s)] = abs(x_out - x_in)
        out[("hole_verticality", s)] = abs(0.5 * (x_in + x_out) - x_low)
    half = np.linspace(0, np.pi, steps // 2 + 1)
    out[("arm_distance", None)] = polyline_distance(_centre_line(m, half, 0),
                                                    _centre_line(m, half, 1)).min()
    perimeter = polar_perimeter(m.pitch_curve)
    circles = envelope_circles(m, perimeter / (np.pi * TEETH), 6.0)  # tip + 6 mm
    out[("ground_clearance", None)] = (_lowest_of_circles(m, circles, phi) - soil).min()
    out[("module", None)] = perimeter / (np.pi * TEETH)
    return out


def timed(function, *args, repeat=3):
    """Best wall time of ``repeat`` calls, and the last value."""
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        value = function(*args)
        best = min(best, time.perf_counter() - start)
    return value, best


def errors(values, reference):
    length = max(abs(values[k] - reference[k]) for k in reference if k[0] in LENGTH_KEYS)
    angle = abs(values[("angle_difference", None)] - reference[("angle_difference", None)])
    return length, angle


def closure_table():
    curve = LimaconPitchCurve(**PAPER)
    converged = solve_closure(curve, rtol=1e-15).centre_distance
    rows = []
    for nodes in (16, 32, 64, 128, 256, 512):
        a, seconds = timed(centre_distance_at_nodes, curve, nodes, repeat=5)
        rows.append((f"trapezoid, {nodes} nodes", a, abs(a - converged), seconds))
    closure, seconds = timed(solve_closure, curve, repeat=5)
    rows.append((f"adaptive (default rtol 1e-13: {closure.nodes} nodes)", closure.centre_distance,
                 abs(closure.centre_distance - converged), seconds))
    t = np.radians(np.arange(0, 361))
    from scipy.optimize import brentq

    def rectangle():
        r = curve.radius(t)
        return brentq(lambda a: np.sum(r / (a - r)) * np.radians(1) - 2 * np.pi, r.max() + 1e-9, 100)

    a, seconds = timed(rectangle, repeat=5)
    rows.append(("peer: 1-degree rectangle rule, both ends counted", a, abs(a - converged), seconds))
    return converged, rows


PRICKING_GRIDS = (90, 180, 360, 720, 1440, 2880)


def pricking_table():
    import tomllib

    from kinematics.pricking import design_pricking

    def example_points(name):
        with open(Path(__file__).resolve().parents[1] / "params" / f"{name}.toml", "rb") as f:
            return np.array(tomllib.load(f)["trajectory"]["points"], dtype=float)

    rows = []
    for name, degree in (("kernel-a", 3), ("kernel-b", 3), ("kernel-b", 5)):
        points = example_points(name)
        design_pricking(points, rocker=45.0, degree=degree, grid=90)  # warm caches
        for grid in PRICKING_GRIDS:
            design, seconds = timed(
                lambda: design_pricking(points, rocker=45.0, degree=degree, grid=grid), repeat=2)
            rows.append((name, degree, grid, design.forward_deviation, design.grid_closure_error,
                         seconds))
            print(f"{name} degree {degree} grid {grid:>5}: forward deviation "
                  f"{design.forward_deviation:8.1e} mm, closure {design.grid_closure_error:8.1e} "
                  f"rad, {seconds * 1e3:6.0f} ms", flush=True)
    return rows


def solids_lines():
    """The mesh-resolution tables of the solids (see benchmarks/mesh_resolution.py), and their
    rows (segments, flank points) for the plot."""
    from cadgen.design import build_mechanism
    from cadgen.params import load_params

    from .mesh_resolution import flank_table, markdown, segments_table

    params = load_params(Path(__file__).resolve().parents[1] / "params" / "xin2024-planter.toml")
    mechanism = build_mechanism(params)
    segments, flanks = segments_table(params, mechanism), flank_table(params, mechanism)
    return markdown(segments, flanks), segments, flanks


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("docs/accuracy.md"))
    args = parser.parse_args(argv)

    print("reference: refined metrics at 72,000 steps per revolution ...", flush=True)
    reference, ref_seconds = timed(refined_metrics, 72000, repeat=1)
    rows = []
    for steps in (360, 3600, 36000):
        for name, function in (("sampled (peer)", sampled_metrics), ("refined", refined_metrics)):
            values, seconds = timed(function, steps, repeat=3 if steps < 36000 else 1)
            length, angle = errors(values, reference)
            rows.append((steps, name, length, angle, seconds))
            print(f"{steps:>6} {name:<15} max length error {length:9.2e} mm, "
                  f"angle error {angle:9.2e} deg, {seconds * 1e3:8.1f} ms", flush=True)
    default_values, _ = timed(refined_metrics, 3600, repeat=1)
    converged, closure_rows = closure_table()
    for label, a, error, seconds in closure_rows:
        print(f"{label:<52} a = {a:.12f} mm  error {error:8.1e} mm  {seconds * 1e6:8.1f} us")

    lines = ["# Accuracy against time", "",
             "Generated by `python -m benchmarks.accuracy` (do not edit by hand). Machine: the "
             "project's 2-core reference machine; times are the best of 3 runs (1 at 36,000 steps).",
             "", "## Metrics against steps per revolution", "",
             f"Reference: this project's refined metrics at 72,000 steps ({ref_seconds:.2f} s). "
             "Error = largest absolute error over the length metrics (trajectory height, hole width "
             "and verticality at 150/185/200 mm, arm distance, ground clearance) and the error of "
             "the entry/exit attitude difference. `sampled` reads the metrics off the samples "
             "(the peer); `refined` is the default method.", "",
             "| steps/rev | method | max length error (mm) | angle error (deg) | time (ms) | "
             "time vs refined at 3600 |", "|---:|---|---:|---:|---:|---:|"]
    base = [r for r in rows if r[0] == 3600 and r[1] == "refined"][0][4]
    for steps, name, length, angle, seconds in rows:
        lines.append(f"| {steps} | {name} | {length:.2e} | {angle:.2e} | {seconds * 1e3:.1f} | "
                     f"{seconds / base:.2f} |")
    lines += ["", "## Each metric at the default resolution (refined, 3600 steps)", "",
              "| metric | spacing (mm) | value | abs. error vs reference |", "|---|---:|---:|---:|"]
    for key, value in default_values.items():
        spacing = "" if key[1] is None else f"{key[1]:g}"
        lines.append(f"| {key[0]} | {spacing} | {value:.6f} | {abs(value - reference[key]):.1e} |")
    lines += ["", "## Closure of the non-circular pair (centre distance a)", "",
              "Each time includes locating max r1 by refined search (about 0.5 ms), which every "
              "rule needs to bracket its root.", "",
              f"Converged a = {converged:.12f} mm (adaptive rule at rtol 1e-15).", "",
              "| rule | a (mm) | error (mm) | time (us) |", "|---|---:|---:|---:|"]
    for label, a, error, seconds in closure_rows:
        lines.append(f"| {label} | {a:.12f} | {error:.1e} | {seconds * 1e6:.0f} |")
    from .screen import knob_markdown as screen_markdown, knob_rows as screen_rows

    screen_knob = screen_rows(log=lambda line: print(line, flush=True))
    lines += screen_markdown(screen_knob)
    pricking = pricking_table()
    lines += ["", "## Pricking mechanism: carrier grid of the tabulated pitch curves", "",
              "Forward check = largest distance between the type-value loop and the loop rebuilt "
              "from the four tabulated pitch curves alone (ratios as radius quotients, periodic "
              "cubic spline, integrated); closure = error of the integrated ratio over one turn. "
              "Time = the whole inverse design (two passes: design, then scaled to whole teeth), "
              "best of 2. Default grid: 720.", "",
              "| loop | curve degree | grid | forward check (mm) | closure (rad) | time (ms) |",
              "|---|---:|---:|---:|---:|---:|"]
    for name, degree, grid, deviation, closure, seconds in pricking:
        lines.append(f"| {name} | {degree} | {grid} | {deviation:.1e} | {closure:.1e} | "
                     f"{seconds * 1e3:.0f} |")
    mesh_lines, segments, _ = solids_lines()
    lines += mesh_lines
    from .knobs import markdown as knob_markdown, plot, sweep_rows, tooth_rows

    flank, dxf = tooth_rows()
    sweeps = sweep_rows()
    lines += knob_markdown(flank, dxf, sweeps)
    figure = args.output.with_suffix(".png")
    args.output.parent.mkdir(parents=True, exist_ok=True)
    series = {
        "metrics, refined (mm)": [(r[4], max(r[2], 1e-16)) for r in rows if r[1] == "refined"],
        "metrics, read off samples (peer, mm)": [(r[4], r[2]) for r in rows
                                                if r[1] != "refined"],
        "closure, trapezoid nodes (mm)": [(row[3], row[2]) for row in closure_rows
                                          if row[0].startswith("trapezoid")],
        "pricking inverse grid, kernel-b quintic (mm)": [
            (row[5], row[3]) for row in pricking if row[0] == "kernel-b" and row[1] == 5],
        "tooth flank points (mm)": [(row["seconds"], row["deviation_flank"]) for row in flank],
        "DXF chord tolerance (mm)": [(row["seconds"], row["deviation_max"]) for row in dxf],
        "segments per circle (relative volume)": [(row[4] / 1e3, abs(row[1]))
                                                  for row in segments],
        "sweep tolerance, arms (certified gap, mm)": [(row[5], row[6]) for row in sweeps
                                                      if row[0].startswith("arm")],
        "population screen, samples/rev (per design, mm)": [
            (row["cpu_us"] * 1e-6, max(row["errors"].values()))
            for row in screen_knob["rows"] if not row["unresolved"]],
    }
    plot(series, figure)
    lines += ["", f"![error against time, every knob]({figure.name})", ""]
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text("\n".join(lines))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
