"""The peer for non-circular gear teeth: ncgears 0.3.1 generating and verifying one conjugate pair.

Run:  python -m benchmarks.peer_ncgears [--venv DIR] [--repeat 3]
                                         [--output benchmarks/results/ncgears.json]

The spec (geometry.md, "Non-circular gear teeth") names ncgears as the peer to beat: a 24-tooth pair
on the pitch curve r = 30 + 8 cos(t) mm, module 2.5. ncgears is never a dependency of this project:
this script keeps it in a virtualenv of its own (default ``~/.cache/cadgen-bench/ncgears-venv``),
creates that venv and installs ``ncgears==0.3.1`` into it when missing, and runs the peer there in a
subprocess, one fresh interpreter per repetition.

What is run inside the venv (the peer's documented API)::

    pair = ncgears.generate_from_centrode("30 + 8*cos(phi)", teeth=24, module=2.5,
                                          output_directory=<tmp>, name="peer")

``generate_from_centrode`` builds the teeth and verifies the pair in the same call (interference on
a phase grid, contact recovery, analytic residuals); it raises if a check fails. The wall time
measured is that call alone (generate + verify + writing its CSV/JSON result files), best of
``--repeat`` runs; interpreter start-up and ``import ncgears`` are timed apart.

How ncgears gets the centre distance for a centrode input: the radius expression is in arbitrary
units. It first solves the reference centre distance C0 (expression units) with
int_0^2pi r/(C0 - r) dphi = target_cycle_delta (2 pi: one mate revolution, ratio 1 on average), then
scales the whole design so that the drive pitch perimeter is exactly z pi m. The reported
``center_distance`` is the scaled one (mm); ``pitch_curve_scale`` = center_distance / C0 says how
much the given curve was shrunk or grown (for r = 30 + 8 cos t, perimeter 191.86 mm against
24 pi 2.5 = 188.50 mm, so about 0.9825).

The comparison script that puts this project's own generator beside the peer calls ``run_peer``
with the same case and settings and reads the dictionary it returns (the keys are those written to
the JSON file; ``ncgears_metadata`` holds the peer's complete verification report).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import venv as venv_module
from pathlib import Path

PEER_PACKAGE = "ncgears"
PEER_VERSION = "0.3.1"
DEFAULT_VENV = Path.home() / ".cache" / "cadgen-bench" / "ncgears-venv"
DEFAULT_OUTPUT = Path(__file__).resolve().parent / "results" / "ncgears.json"
DEFAULT_EXPRESSION = "30 + 8*cos(phi)"

TRANSMISSION_ERROR_DEFINITION = (
    "ncgears metadata 'maximum_transmission_error' (radians; GearPair.summary() prints it in "
    "degrees). It is an angle of the DRIVEN gear. At {poses} drive angles "
    "phi_k = 2 pi (k + 0.6180...)/{poses} over one drive revolution, the finished zero-clearance "
    "outlines are posed at the nominal law (drive fixed, driven at psi(phi_k)). If they already "
    "overlap by more than {area:.3g} mm^2 (1e-11 module^2) the pose scores 0. Otherwise the driven "
    "gear is turned about its own centre, each way in turn: from {first:.3g} rad, doubling up to "
    "5 deg, then bisected to {tol:.3g} rad, until the overlap area passes that threshold. The pose "
    "scores the smaller of the two first-contact angles. The number is the maximum over the "
    "{poses} poses. So it is the largest one-sided free rotation to first flank contact "
    "(unsigned), sampled at {poses} poses. It is not a peak-to-peak error along a continuous mesh "
    "cycle, and penetration at a pose is not counted here (the overlap check reports that)."
)
OVERLAP_DEFINITION = (
    "max over {poses} poses of the intersection area (mm^2) of the posed drive and driven outline "
    "polygons (Shapely/GEOS), poses = 4 staggered grids (offsets 0, 1/2, 1/4, 3/4) of "
    "max(64, 4 * max(z1, z2)) phases over one drive revolution; the pair is rejected above "
    "overlap_area_tolerance = 20 * 1e-6 module^2"
)

# Runs inside the peer's venv: argv[1] is the JSON case; the last stdout line is the JSON answer.
_CHILD = r'''
import json, math, os, sys, tempfile, time
t0 = time.perf_counter()
import ncgears
import ncgears.engine as engine
import_s = time.perf_counter() - t0
case = json.loads(sys.argv[1])
for name, value in case["overrides"].items():
    if not hasattr(engine, name):
        raise SystemExit(f"ncgears.engine has no constant {name!r}")
    setattr(engine, name, type(getattr(engine, name))(value))
kwargs = dict(teeth=case["teeth"], module=case["module"],
              pressure_angle_deg=case["pressure_angle_deg"], name="peer")
for key in ("samples", "samples_per_radian"):
    if case[key] is not None:
        kwargs[key] = case[key]
generate = (ncgears.generate_from_centrode if case["mode"] == "centrode"
            else ncgears.generate_from_transmission)
with tempfile.TemporaryDirectory() as out:
    t = time.perf_counter()
    pair = generate(case["expression"], output_directory=out, **kwargs)
    generate_s = time.perf_counter() - t
    drive_points = len(pair.drive_outline)
    driven_points = len(pair.driven_outline)
closed = pair.metadata["topology"] == "closed"
module = case["module"]
print(json.dumps({
    "version": ncgears.__version__,
    "import_s": import_s,
    "generate_s": generate_s,
    "cpu_count": os.cpu_count(),
    "python": sys.version.split()[0],
    "drive_outline_points": drive_points,
    "driven_outline_points": driven_points,
    "te_poses": (engine.CONTACT_RECOVERY_PHASES_CLOSED if closed
                 else engine.CONTACT_RECOVERY_PHASES_OPEN),
    "te_first_step_rad": engine.CONTACT_SEARCH_INITIAL_ANGLE,
    "te_max_angle_rad": engine.CONTACT_SEARCH_MAX_ANGLE,
    "te_bisection_tolerance_rad": engine.CONTACT_SEARCH_ANGLE_TOLERANCE,
    "te_contact_area_threshold_mm2": engine.CONTACT_AREA_TOLERANCE_FACTOR * module ** 2,
    "chord_tolerance_mm": engine.ANALYTIC_CHORD_TOLERANCE_FACTOR * module,
    "summary": pair.summary(),
    "metadata": pair.metadata,
}))
'''


def _log(message: str) -> None:
    print(f"[peer_ncgears] {message}", file=sys.stderr, flush=True)


def _venv_python(venv_dir: Path) -> Path:
    return venv_dir / ("Scripts/python.exe" if os.name == "nt" else "bin/python")


def _installed_version(python: Path) -> str | None:
    if not python.exists():
        return None
    probe = subprocess.run([str(python), "-c", "import ncgears; print(ncgears.__version__)"],
                           capture_output=True, text=True)
    return probe.stdout.strip() if probe.returncode == 0 else None


def ensure_venv(venv_dir: Path = DEFAULT_VENV, *, log=_log) -> Path:
    """The python of a venv holding ncgears==0.3.1, created and installed if missing."""
    venv_dir = Path(venv_dir).expanduser()
    python = _venv_python(venv_dir)
    if _installed_version(python) == PEER_VERSION:
        return python
    if not python.exists():
        log(f"creating virtualenv {venv_dir}")
        venv_dir.parent.mkdir(parents=True, exist_ok=True)
        venv_module.create(venv_dir, with_pip=True)
    log(f"installing {PEER_PACKAGE}=={PEER_VERSION} into {venv_dir} "
        "(with shapely, sympy, scipy, ezdxf)")
    subprocess.run([str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                    f"{PEER_PACKAGE}=={PEER_VERSION}"], check=True)
    found = _installed_version(python)
    if found != PEER_VERSION:
        raise RuntimeError(f"{venv_dir}: expected ncgears {PEER_VERSION}, found {found}")
    log(f"ncgears {found} ready")
    return python


def _run_once(python: Path, case: dict) -> tuple[dict, float]:
    with tempfile.TemporaryDirectory() as scratch:
        start = time.perf_counter()
        done = subprocess.run([str(python), "-c", _CHILD, json.dumps(case)], capture_output=True,
                              text=True, cwd=scratch)
        process_s = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"ncgears failed (exit {done.returncode}):\n{done.stderr.strip()}")
    return json.loads(done.stdout.strip().splitlines()[-1]), process_s


def run_peer(expression: str = DEFAULT_EXPRESSION, *, mode: str = "centrode", teeth: int = 24,
             module: float = 2.5, pressure_angle_deg: float = 20.0, samples: int | None = None,
             samples_per_radian: int | None = None, overrides: dict | None = None, repeat: int = 3,
             venv_dir: Path = DEFAULT_VENV, log=_log) -> dict:
    """Generate and verify one pair with ncgears ``repeat`` times (fresh interpreter each) and
    return timings, the verification figures with their definitions, and the peer's metadata.

    ``mode`` is "centrode" (expression = drive pitch radius r(phi)) or "transmission"
    (expression = driven angle psi(phi)). ``samples`` (input table rows, ncgears default 8192) and
    ``samples_per_radian`` (initial flank tessellation density, default 110, refined adaptively to
    a 2.5e-5 module chord error) are ncgears' own accuracy/time options; None keeps its defaults.
    ``overrides`` sets module constants of ``ncgears.engine`` before the run (for example
    ``{"CONTACT_RECOVERY_PHASES_CLOSED": 360}`` to measure the transmission error at 360 poses, or
    ``{"_MAX_GEOMETRY_WORKERS": 1}`` for one thread).
    """
    if mode not in ("centrode", "transmission"):
        raise ValueError("mode must be 'centrode' or 'transmission'")
    if repeat < 1:
        raise ValueError("repeat must be at least 1")
    python = ensure_venv(venv_dir, log=log)
    case = dict(expression=expression, mode=mode, teeth=teeth, module=module,
                pressure_angle_deg=pressure_angle_deg, samples=samples,
                samples_per_radian=samples_per_radian, overrides=dict(overrides or {}))
    runs = []
    for index in range(repeat):
        answer, process_s = _run_once(python, case)
        log(f"run {index + 1}/{repeat}: generate+verify {answer['generate_s']:.3f} s "
            f"(process {process_s:.3f} s, import {answer['import_s']:.3f} s)")
        runs.append((answer, process_s))
    best, _ = min(runs, key=lambda run: run[0]["generate_s"])
    meta = best["metadata"]
    te_values = sorted({answer["metadata"]["maximum_transmission_error"] for answer, _ in runs})
    te_rad = float(meta["maximum_transmission_error"])
    centre = float(meta["center_distance"])
    reference = float(meta.get("centrode_reference_center_distance") or 0.0)
    module_ = float(meta["module"])
    return {
        "peer": {"package": PEER_PACKAGE, "version": best["version"], "license": "Apache-2.0",
                 "call": (f"ncgears.generate_from_{mode}({expression!r}, teeth={teeth}, "
                          f"module={module}, pressure_angle_deg={pressure_angle_deg}"
                          + (f", samples={samples}" if samples is not None else "")
                          + (f", samples_per_radian={samples_per_radian}"
                             if samples_per_radian is not None else "") + ")")},
        "case": case,
        "machine": {"cpu_count": best["cpu_count"], "platform": platform.platform(),
                    "peer_python": best["python"],
                    "geometry_worker_threads": meta.get("geometry_worker_limit")},
        "timing": {
            "repeat": repeat,
            "generate_verify_s_best": min(a["generate_s"] for a, _ in runs),
            "generate_verify_s_all": [a["generate_s"] for a, _ in runs],
            "process_s_best": min(p for _, p in runs),
            "import_s_best": min(a["import_s"] for a, _ in runs),
            "what": ("generate_verify: the generate_from_* call alone (teeth, all checks, result "
                     "files); process: whole subprocess incl. interpreter start and imports"),
        },
        "summary": best["summary"],
        "drive_teeth": meta["drive_teeth"],
        "driven_teeth": meta["driven_teeth"],
        "average_ratio": meta["average_angular_ratio"],
        "centre_distance_mm": centre,
        "reference_centre_distance": reference or None,
        "pitch_curve_scale": centre / reference if reference else None,
        "centre_distance_definition": (
            "centrode input: C0 solves int_0^2pi r/(C0 - r) dphi = target_cycle_delta (2 pi) in "
            "the expression's units, then the design is scaled so the drive pitch perimeter = "
            "z pi m; centre_distance_mm = z pi m / int (arc density) = C0 * pitch_curve_scale"),
        "transmission_error_rad": te_rad,
        "transmission_error_deg": te_rad * 180.0 / 3.141592653589793,
        "transmission_error_all_runs_rad": te_values,
        "transmission_error_definition": TRANSMISSION_ERROR_DEFINITION.format(
            poses=best["te_poses"], area=best["te_contact_area_threshold_mm2"],
            first=best["te_first_step_rad"], tol=best["te_bisection_tolerance_rad"]),
        "transmission_error_poses": best["te_poses"],
        "transmission_error_resolution_rad": best["te_bisection_tolerance_rad"],
        "transmission_error_contact_area_mm2": best["te_contact_area_threshold_mm2"],
        "overlap_area_max_mm2": meta["placed_pair_overlap_area"],
        "overlap_area_tolerance_mm2": meta["overlap_area_tolerance"],
        "overlap_poses": meta["verification_phase_count"],
        "overlap_definition": OVERLAP_DEFINITION.format(poses=meta["verification_phase_count"]),
        "contact_coverage": {
            "poses": meta["protected_contact_verification_phase_count"],
            "covered_fraction": meta["protected_contact_coverage_fraction"],
            "minimum_contact_pairs": meta["minimum_protected_contact_pairs"],
            "maximum_residual_mm": meta["maximum_protected_contact_residual"],
            "what": ("analytic flank points (not polygons) of the two gears compared at the "
                     "nominal pose; pairs within 1e-6 module count as contact"),
        },
        "tessellation": {
            "drive_outline_points": best["drive_outline_points"],
            "driven_outline_points": best["driven_outline_points"],
            "chord_tolerance_mm": best["chord_tolerance_mm"],
            "maximum_chord_error_mm": meta["maximum_analytic_chord_error"],
            "maximum_envelope_residual_mm": meta["maximum_envelope_residual"],
        },
        "geometry": {
            "pressure_angle_deg": meta["pressure_angle_deg"],
            # ncgears defaults (addendum 1.0, dedendum 1.2, rack-tip fillet 0.3 module)
            "addendum_mm": module_ * 1.0, "dedendum_mm": module_ * 1.2,
            "rack_tip_fillet_mm": module_ * 0.3,
            "driven_pitch_radius_range_mm": [meta["minimum_driven_pitch_radius"],
                                             meta["maximum_driven_pitch_radius"]],
            "centrodes_are_convex": meta["centrodes_are_convex"],
            "undercut_curves": meta["cutter_undercut_curve_count"],
            "minimum_root_radius_mm": meta["minimum_root_radius"],
            "minimum_tip_thickness_mm": meta["minimum_tip_thickness"],
            "drive_centrode_outline_distance_mm": meta["drive_centrode_outline_distance"],
            "backlash_deg": [meta["minimum_backlash_deg"], meta["maximum_backlash_deg"]],
        },
        "ncgears_metadata": meta,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--venv", type=Path, default=DEFAULT_VENV,
                        help=f"virtualenv for ncgears (default {DEFAULT_VENV})")
    parser.add_argument("--repeat", type=int, default=3, help="runs; the best time is kept")
    parser.add_argument("--output", type=Path, default=DEFAULT_OUTPUT)
    parser.add_argument("--expression", default=DEFAULT_EXPRESSION,
                        help="r(phi) for --mode centrode, psi(phi) for --mode transmission")
    parser.add_argument("--mode", choices=("centrode", "transmission"), default="centrode")
    parser.add_argument("--teeth", type=int, default=24)
    parser.add_argument("--module", type=float, default=2.5)
    parser.add_argument("--pressure-angle", type=float, default=20.0)
    parser.add_argument("--samples", type=int, help="ncgears input samples (its default 8192)")
    parser.add_argument("--samples-per-radian", type=int,
                        help="ncgears flank density (its default 110)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override an ncgears.engine constant, "
                             "e.g. CONTACT_RECOVERY_PHASES_CLOSED=360")
    args = parser.parse_args(argv)
    overrides = {}
    for item in args.set:
        name, _, value = item.partition("=")
        overrides[name.strip()] = json.loads(value)
    result = run_peer(args.expression, mode=args.mode, teeth=args.teeth, module=args.module,
                      pressure_angle_deg=args.pressure_angle, samples=args.samples,
                      samples_per_radian=args.samples_per_radian, overrides=overrides,
                      repeat=args.repeat, venv_dir=args.venv)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print(json.dumps({k: v for k, v in result.items() if k != "ncgears_metadata"}))
    _log(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
