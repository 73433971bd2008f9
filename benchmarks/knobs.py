"""The remaining resolution knobs for ``python -m benchmarks.accuracy``: tooth flank points, DXF
chord tolerance, sweep tolerance, and the error-against-time plot of every knob.

* Flank points and chord tolerance: the study of ``benchmarks/gears.py`` (without its peer):
  the analytic outline against a simulated rack cut (400 positions per pitch), and the DXF
  polyline against the dense outline, on the peer case (24 teeth, r = 30 + 8 cos t, module 2.5).
* Sweep tolerance (``resolution.sweep_atol``): the build's certified sweeps of the paper's
  assembly at 1e-3, 1e-6 and 1e-9 mm against the same sweep at 1e-11 mm.
"""

from __future__ import annotations

import time

import numpy as np

SWEEP_TOLERANCES = (1e-3, 1e-6, 1e-9)
SWEEP_REFERENCE = 1e-11


def tooth_rows():
    """(flank rows, dxf rows) from benchmarks.gears, measured once each."""
    from . import gears

    case = gears.build_case()
    flank, _, _ = gears.flank_accuracy(case, repeat=1)
    dxf = gears.dxf_tolerance(case, repeat=1)["rows"]
    return flank, dxf


def sweep_rows():
    """``[(clearance, atol, minimum, error vs reference, poses, seconds, certified gap)]``.

    The refinement finds the minimum to round-off at any tolerance; what ``atol`` buys
    is the certificate: the true minimum lies within ``gap`` below the value found.
    """
    from cadgen.pipeline.clearances import SWEEP_STEPS
    from cadgen.sweep.search import certified_distance

    from ._paper import sweep_cases

    rows = []
    for label, scene_of, lipschitz, acceleration, upper in sweep_cases():
        reference = certified_distance(scene_of(), lipschitz=lipschitz, acceleration=acceleration,
                                       upper=upper, atol=SWEEP_REFERENCE, steps=SWEEP_STEPS)
        for atol in SWEEP_TOLERANCES:
            scene = scene_of()
            start = time.perf_counter()
            result = certified_distance(scene, lipschitz=lipschitz, acceleration=acceleration,
                                        upper=upper, atol=atol, steps=SWEEP_STEPS)
            seconds = time.perf_counter() - start
            rows.append((label, atol, result.minimum, abs(result.minimum - reference.minimum),
                         result.evaluations, seconds, result.minimum - result.bound))
            print(f"sweep {label} atol {atol:g}: error {rows[-1][3]:.1e} mm, certified within "
                  f"{rows[-1][6]:.1e} mm, {result.evaluations} poses, {seconds:.2f} s", flush=True)
    return rows


def markdown(flank, dxf, sweeps) -> list:
    lines = ["", "## Tooth flank points (`gears.flank_points`, default 96)", "",
             "The drive gear of the peer case against a simulated rack cut at 400 positions per "
             "pitch; deviation = largest distance between the outlines, flanks and roots apart "
             "(the reference's own root floor is its fillet's sagitta, 6e-4 mm). Time: "
             "`generate_pair`, both gears and their checks.", "",
             "| flank points | outline points | flank deviation (mm) | root deviation (mm) | "
             "time (s) |", "|---:|---:|---:|---:|---:|"]
    for row in flank:
        lines.append(f"| {row['flank_points']} | {row['drive_outline_points']} | "
                     f"{row['deviation_flank']:.1e} | {row['deviation_root']:.1e} | "
                     f"{row['seconds']:.2f} |")
    lines += ["", "## DXF chord tolerance (`gears.chord_tolerance`, default 0.005 mm)", "",
              "One gear (192 flank points) written and read back with ezdxf: the largest "
              "distance of the dense outline from the written polyline, the points written, "
              "the area lost and the time to write.", "",
              "| chord tolerance (mm) | points | deviation (mm) | area error (mm2) | time (ms) |",
              "|---:|---:|---:|---:|---:|"]
    for row in dxf:
        lines.append(f"| {row['chord_tolerance']:g} | {row['points_written']} | "
                     f"{row['deviation_max']:.1e} | {row['area_error_mm2']:.1e} | "
                     f"{row['seconds'] * 1e3:.0f} |")
    lines += ["", "## Sweep tolerance (`resolution.sweep_atol`, default 1e-6 mm)", "",
              f"The build's certified sweeps against the same sweep at {SWEEP_REFERENCE:g} mm. "
              "Brent's refinement finds the minimum to round-off at every tolerance (error 0); "
              "what the tolerance buys is the certificate: no carrier angle comes closer than "
              "the minimum less the certified gap.",
              "", "| clearance | atol (mm) | minimum (mm) | error (mm) | certified gap (mm) | "
              "poses | time (s) |", "|---|---:|---:|---:|---:|---:|---:|"]
    for label, atol, value, error, poses, seconds, gap in sweeps:
        lines.append(f"| {label} | {atol:g} | {value:.9f} | {error:.1e} | {gap:.1e} | {poses} | "
                     f"{seconds:.2f} |")
    return lines


def plot(series: dict, path) -> None:
    """Error against time, log-log, one line per knob: ``{label: [(seconds, error), ...]}``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, ax = plt.subplots(figsize=(8.5, 6.0), dpi=110, layout="constrained")
    floor = 1e-16   # an error of exactly 0 (round-off) is drawn at the floor
    for label, points in series.items():
        # in the knob's own order, coarse to fine (sorting by time would zigzag on noise)
        seconds = np.array([p[0] for p in points])
        errors = np.maximum(np.array([p[1] for p in points], dtype=float), floor)
        ax.loglog(seconds, errors, "o-", label=label, ms=4)
    ax.axhline(1e-2, color="0.5", ls=":", lw=0.8)
    ax.annotate("0.01 mm", (ax.get_xlim()[0], 1e-2), fontsize=7, color="0.4",
                xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("error against the converged or analytic reference (mm or relative)")
    ax.set_title("Accuracy against time, every resolution knob (python -m benchmarks.accuracy)",
                 fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="lower left")
    figure.savefig(path, metadata={"Software": None})
    plt.close(figure)
