"""How fast the studio answers ``POST /api/evaluate``: p50, p95 and max per mechanism kind.

Run:  python -m benchmarks.studio [--output docs/studio-benchmark.md] [--requests 50]

Each request goes through the whole app (FastAPI's TestClient, in this process: the
guards, the JSON body read, validation, the evaluation, the payload and its JSON
encoding; no network), one at a time as the page sends them, and each changes a value
so no cache answers it:

- planting (the paper's design): ``planter.L2`` and ``pitch_curve.b1`` stepped in turn
  (a new b1 is a new pitch curve: its closure is solved again);
- pricking (kernel-b): every type-value point moved by a small seeded random amount
  (up to 0.5 mm), so the inverse design's caches (``cadgen.design``) never hit.

Three figures per request: **wall**, the time of the request through the app;
**CPU**, the process CPU time it took (all threads: the app runs in the client's
worker thread), which the other processes on the machine do not inflate; and the
evaluation's own ``elapsed_ms`` (validation to payload, before JSON encoding). Three
warm-up requests per kind are not counted. numpy's BLAS runs on one thread, as in
``cadgen studio`` (:func:`cadgen.math_threads.single_threaded_math`). The aims (issue
16): p95 <= 100 ms for the planting mechanism, <= 500 ms for the pricking inverse design.
"""

from __future__ import annotations

import argparse
import copy
import os
import time
import tomllib
import warnings
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PLANTING = REPO / "params" / "xin2024-planter.toml"
PRICKING = REPO / "params" / "kernel-b.toml"
AIMS_MS = {"planting": 100.0, "pricking": 500.0}
WARM_UP = 3


def _numpy():
    import numpy

    return numpy


def planting_variants(count: int) -> list:
    """``count`` parameter sets of the paper's design, each differing from the one before."""
    base = tomllib.loads(PLANTING.read_text(encoding="utf-8"))
    variants = []
    for index in range(count):
        data = copy.deepcopy(base)
        step = (index // 2) % 25
        if index % 2:
            data["pitch_curve"]["b1"] = round(27.3 + 0.016 * step, 4)
        else:
            data["planter"]["L2"] = round(186.0 + 0.32 * step, 3)
        variants.append(data)
    return variants


def pricking_variants(count: int, seed: int = 16) -> list:
    """``count`` kernel-b variants, every type-value point moved by at most 0.5 mm."""
    np = _numpy()
    rng = np.random.default_rng(seed)
    base = tomllib.loads(PRICKING.read_text(encoding="utf-8"))
    points = np.asarray(base["trajectory"]["points"], dtype=float)
    variants = []
    for _ in range(count):
        data = copy.deepcopy(base)
        moved = points + rng.uniform(-0.5, 0.5, size=points.shape)
        data["trajectory"]["points"] = np.round(moved, 3).tolist()
        variants.append(data)
    return variants


def measure(client, token: str, variants: list) -> dict:
    """Per request: wall ms, process CPU ms, the answer's elapsed_ms; warm-up dropped."""
    wall, cpu, evaluation = [], [], []
    for index, params in enumerate(variants):
        cpu_start, start = time.process_time(), time.perf_counter()
        response = client.post("/api/evaluate", json={"params": params},
                               headers={"X-Cadgen-Token": token})
        seconds, cpu_seconds = time.perf_counter() - start, time.process_time() - cpu_start
        if response.status_code != 200:
            raise RuntimeError(f"request {index} failed: {response.status_code} "
                               f"{response.text[:300]}")
        if index < WARM_UP:
            continue
        wall.append(1e3 * seconds)
        cpu.append(1e3 * cpu_seconds)
        evaluation.append(response.json()["elapsed_ms"])
    return {"wall": wall, "cpu": cpu, "evaluation": evaluation,
            "bytes": len(response.content)}


def _figures(values) -> tuple:
    np = _numpy()
    values = np.asarray(values, dtype=float)
    return (float(np.percentile(values, 50)), float(np.percentile(values, 95)),
            float(values.max()))


def table(results: dict) -> list:
    """Markdown rows: per kind and figure, p50, p95, max against the aim."""
    lines = ["| mechanism | requests | figure | p50 (ms) | p95 (ms) | max (ms) | aim p95 (ms) |"
             " p95 within aim |", "|---|---:|---|---:|---:|---:|---:|---|"]
    labels = {"wall": "wall, through the app", "cpu": "process CPU",
              "evaluation": "evaluation (elapsed_ms)"}
    for kind, figures in results.items():
        for key, label in labels.items():
            p50, p95, top = _figures(figures[key])
            within = "yes" if p95 <= AIMS_MS[kind] else "NO"
            lines.append(f"| {kind} | {len(figures[key])} | {label} | {p50:.1f} | {p95:.1f} | "
                         f"{top:.1f} | {AIMS_MS[kind]:.0f} | {within} |")
    return lines


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=None,
                        help="write the table as markdown (e.g. docs/studio-benchmark.md)")
    parser.add_argument("--requests", type=int, default=50,
                        help="counted requests per mechanism kind (default 50)")
    args = parser.parse_args(argv)
    warnings.filterwarnings("ignore", category=DeprecationWarning)
    from cadgen.math_threads import single_threaded_math

    single_threaded_math()   # as `cadgen studio` runs: before numpy loads
    from fastapi.testclient import TestClient

    from cadgen.studio.server import create_app, new_token

    token = new_token()
    app = create_app(PLANTING, token=token, output_root=REPO / "outputs")
    results = {}
    with TestClient(app, base_url="http://127.0.0.1") as client:
        count = args.requests + WARM_UP
        for kind, variants in (("planting", planting_variants(count)),
                               ("pricking", pricking_variants(count))):
            results[kind] = measure(client, token, variants)
            p50, p95, _ = _figures(results[kind]["wall"])
            print(f"{kind}: wall p50 {p50:.1f} ms, p95 {p95:.1f} ms "
                  f"({results[kind]['bytes'] / 1e3:.0f} kB answer)", flush=True)
    lines = table(results)
    print("\n".join(lines))
    if args.output:
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
        sizes = ", ".join(f"{kind} {r['bytes'] / 1e3:.0f} kB" for kind, r in results.items())
        text = ["# Studio evaluation speed", "",
                "Generated by `python -m benchmarks.studio` (do not edit by hand) on a "
                f"{os.cpu_count()}-core machine (load average {load:.2f} at the end). "
                f"{args.requests} requests per mechanism kind after {WARM_UP} warm-up ones, each "
                "changing a value (planting: planter.L2 and pitch_curve.b1 in turn; pricking: "
                "kernel-b's type-value points moved up to 0.5 mm), through the whole app "
                "(FastAPI's TestClient: guards, body, validation, evaluation, payload, JSON "
                f"encoding). Answer sizes: {sizes}. CPU is the process's CPU time per request, "
                "which other processes on the machine do not inflate.", "", *lines, ""]
        args.output.parent.mkdir(parents=True, exist_ok=True)
        args.output.write_text("\n".join(text), encoding="utf-8")
        print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
