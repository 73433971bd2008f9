"""Collision sweep of the paper's planting assembly: certified FCL minimum against a plain scan.

Run:  python -m benchmarks.sweep [--output docs/sweep.md]

Two clearances of the solids, each over the carrier angle, measured in this run:

* ``arm to arm``: gearbox 2, cam and planter shell of arm 1 against those of
  arm 2 (the scene this table has measured from the start, with one speed bound
  for every pair; the build's sweep adds the shafts and blades, each part with
  its own bounds). The distance repeats every half turn, so the certified search
  covers ``[0, pi]``; the plain scan, like a peer that does not know it, covers a
  turn.
* ``housings to ground``: gearbox 1 and both gearbox-2 housings against the soil
  slab, over a turn.

Methods: the certified sweep (:func:`cadgen.sweep.search.certified_distance`,
360 screening steps per interval, ``atol`` 1e-6 mm, speed and acceleration
bounds from the mechanism), the plain 3,600-pose scan
(:func:`cadgen.sweep.search.plain_scan`), and the reference: the certified sweep
at ``atol`` 1e-10 mm, checked against a dense scan of 2,000 poses 1e-6 rad apart
round its argument. Errors are against the reference value. Times are CPU
times of this process (the machine may be shared), best of 3 for the certified
sweep, one run otherwise, each from a fresh scene whose part geometry (hulls,
and the BVH models the sweep asks for) is built inside the time; the part
meshes are converted from the solids beforehand, and building a scene alone is
timed apart.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
PARAMS = REPO / "params" / "xin2024-planter.toml"
ARM_PARTS = ("gearbox2-base", "gearbox2-cover", "cam", "planter-shell")
HOUSINGS = ("gearbox1-base", "gearbox1-cover", "gearbox2-base-arm1", "gearbox2-base-arm2",
            "gearbox2-cover-arm1", "gearbox2-cover-arm2")
Z = (0.0, 0.0, 1.0)
STEPS = 360
ATOL = 1e-6
REFERENCE_ATOL = 1e-10
PLAIN_POSES = 3600


def planting():
    """The paper's design: parameters, mechanism, evaluation and its assembly (no gears), every
    part's mesh converted from its solid (the parts' work, not the sweeps')."""
    from cadgen.cam.design import design_cam
    from cadgen.design import build_mechanism, evaluate
    from cadgen.params import load_params
    from cadgen.solids.planting import planting_assembly

    params = load_params(PARAMS)
    mechanism = build_mechanism(params)
    evaluation = evaluate(params, mechanism, steps=720)
    cam = design_cam(params, mechanism, evaluation.events)
    assembly, _, _ = planting_assembly(params, mechanism, None, cam, evaluation.events.soil_level)
    for part in assembly.parts:
        part.mesh
    return params, mechanism, evaluation, assembly


def cpu_timed(function, repeat=3):
    """Best CPU time (s) of ``repeat`` calls, and the last value."""
    best = math.inf
    for _ in range(repeat):
        start = time.process_time()
        value = function()
        best = min(best, time.process_time() - start)
    return value, best


def arm_bounds(mechanism, parts):
    """Speed (mm/rad) and acceleration (mm/rad^2) bounds of any point of one arm's parts.

    Gearbox 2 and the cam ride on gearbox 2: C circles at ``rc`` and the body
    turns at rate 1, so ``rc + reach`` for both. The planter shell: E's bounds
    plus its turn (rate at most ``spin``; ``spin rate + spin^2`` read off the P1
    bound) times its reach from E.
    """
    from cadgen.sweep.scene import part_reach

    closure, rc = mechanism.closure, mechanism.carrier_radii["C"]
    spin = max(abs(1.0 - closure.ratio_min), abs(1.0 - closure.ratio_max))
    turn = (mechanism.acceleration_bound("P1") - mechanism.acceleration_bound("E")) / mechanism.L1
    box = rc + max(part_reach(parts[n], axis=Z)
                   for n in ("gearbox2-base", "gearbox2-cover", "cam"))
    reach = part_reach(parts["planter-shell"], axis=Z)
    return (max(box, mechanism.speed_bound("E") + spin * reach),
            max(box, mechanism.acceleration_bound("E") + turn * reach))


def cases(mechanism, assembly):
    """``[(label, scene factory, lipschitz, acceleration, upper)]`` of the two clearances.

    A factory makes a fresh scene with no part geometry kept from an earlier one.
    """
    from cadgen.sweep import fcl
    from cadgen.sweep.scene import part_reach

    parts = {part.name: part for part in assembly.parts}
    speed, acceleration = arm_bounds(mechanism, parts)
    rc = mechanism.carrier_radii["C"]
    ground_speed = max(max(part_reach(parts[f"gearbox1-{h}"], axis=Z) for h in ("base", "cover")),
                       rc + max(part_reach(parts[f"gearbox2-{h}"], axis=Z)
                                for h in ("base", "cover")))

    def fresh(group_a, group_b):
        def make():
            fcl._SHAPES.clear()
            return fcl.FclScene(assembly, group_a, group_b)
        return make

    return [("arm to arm", fresh([f"{n}-arm1" for n in ARM_PARTS],
                                 [f"{n}-arm2" for n in ARM_PARTS]),
             2 * speed, 2 * acceleration, math.pi),
            ("housings to ground", fresh(HOUSINGS, ["ground"]), ground_speed, ground_speed,
             2 * math.pi)]


def measure(label, scene_of, lipschitz, acceleration, upper):
    """One clearance: every figure of its table rows, as a dict."""
    from cadgen.sweep.search import certified_distance, plain_scan

    def sweep(atol):
        scene = scene_of()
        return certified_distance(scene, lipschitz=lipschitz, acceleration=acceleration,
                                  steps=STEPS, atol=atol, upper=upper), scene

    _, build_seconds = cpu_timed(scene_of)
    (reference, scene), reference_seconds = cpu_timed(lambda: sweep(REFERENCE_ATOL), repeat=1)
    window = reference.argument + np.linspace(-1e-3, 1e-3, 2000)   # the argument itself left out
    dense = float(scene.distances(window).min())
    (certified, scene), certified_seconds = cpu_timed(lambda: sweep(ATOL), repeat=3)
    exact_queries = scene.exact_queries
    (plain, plain_argument), plain_seconds = cpu_timed(
        lambda: plain_scan(scene_of(), PLAIN_POSES), repeat=1)
    print(f"{label}: reference {reference.minimum:.12f} mm (bound {reference.bound:.12f}, "
          f"{reference.evaluations} poses, {reference_seconds:.2f} s); dense window "
          f"{dense:.12f}; certified {certified.minimum:.12f} ({certified.evaluations} poses, "
          f"{exact_queries} FCL mesh queries, {certified_seconds:.3f} s); plain {plain:.12f} "
          f"({plain_seconds:.2f} s)", flush=True)
    return dict(label=label, lipschitz=lipschitz, acceleration=acceleration, upper=upper,
                build_seconds=build_seconds, reference=reference,
                reference_seconds=reference_seconds, dense=dense, certified=certified,
                certified_seconds=certified_seconds, exact_queries=exact_queries, plain=plain,
                plain_argument=plain_argument, plain_seconds=plain_seconds)


def markdown(results=None) -> list:
    """The tables of ``docs/sweep.md`` as lines (measures first when ``results`` is None)."""
    if results is None:
        _, mechanism, _, assembly = planting()
        results = [measure(*case) for case in cases(mechanism, assembly)]
    lines = ["## Collision sweep of the solids (python-fcl)", "",
             "Generated by `python -m benchmarks.sweep` (do not edit by hand). The paper's "
             "planting assembly (`params/xin2024-planter.toml`, no gears: they lie inside the "
             "housings). "
             f"Certified: {STEPS} screening steps over the interval, atol {ATOL:g} mm, bounds on "
             "the relative speed and acceleration from the mechanism. Plain: "
             f"{PLAIN_POSES} evenly spaced poses over a turn, no refinement. Reference: the "
             f"certified sweep at atol {REFERENCE_ATOL:g} mm. Arm to arm: gearbox 2, cam and "
             "planter shell of each arm, one speed bound for every pair (the build adds "
             "shafts and blades, each part with its own "
             "bounds), searched over [0, pi] (the distance repeats every half turn). Times: CPU "
             "of one process, best of 3 for the certified sweep, each from a fresh scene (its "
             "hulls and the BVH models it asks for built inside the time; the meshes converted "
             "from the solids beforehand). Every pose's distance is the same engine's: bounding "
             "spheres, then hull bounds that are often exact, then FCL's mesh distance where "
             "they are not (cadgen.sweep.fcl).", "",
             "| clearance | method | minimum (mm) | error vs reference (mm) | certified bound (mm) "
             "| poses | time (s) | time vs certified |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        reference, certified = r["reference"], r["certified"]
        base = r["certified_seconds"]
        rows = [("certified", certified.minimum, f"{certified.bound:.9f}", certified.evaluations,
                 base),
                (f"plain {PLAIN_POSES}-pose scan", r["plain"], "none", PLAIN_POSES,
                 r["plain_seconds"]),
                (f"reference (atol {REFERENCE_ATOL:g})", reference.minimum,
                 f"{reference.bound:.12f}", reference.evaluations, r["reference_seconds"])]
        for method, value, bound, poses, seconds in rows:
            lines.append(f"| {r['label']} | {method} | {value:.12f} | "
                         f"{abs(value - reference.minimum):.1e} | {bound} | {poses} | "
                         f"{seconds:.3f} | {seconds / base:.1f} |")
    lines += ["", "| clearance | L (mm/rad) | A (mm/rad^2) | where (deg) | nearest pair | "
              "dense window - reference (mm) | FCL mesh queries (certified) | scene build (s) |",
              "|---|---:|---:|---:|---|---:|---:|---:|"]
    for r in results:
        reference = r["reference"]
        lines.append(f"| {r['label']} | {r['lipschitz']:.1f} | {r['acceleration']:.1f} | "
                     f"{math.degrees(reference.argument):.6f} | {reference.pair[0]} - "
                     f"{reference.pair[1]} | {r['dense'] - reference.minimum:.1e} | "
                     f"{r['exact_queries']} | {r['build_seconds']:.3f} |")
    lines += ["", "Dense window: 2,000 poses 1e-6 rad apart round (not on) the reference's "
              "argument, through the same scene; it can only lie above the true minimum, so a "
              "small non-negative difference confirms the reference. The plain scan has no bound: "
              "its error is what sampling alone leaves between samples."]
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=REPO / "docs" / "sweep.md")
    args = parser.parse_args(argv)
    lines = ["# Collision sweep: accuracy against time", ""] + markdown()[2:] + [""]
    print("\n".join(lines))
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text("\n".join(lines), encoding="utf-8")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
