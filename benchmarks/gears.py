"""Non-circular gear teeth: our generator against the ncgears peer, and its accuracy knobs.

Run:  python -m benchmarks.gears [--output docs/gears.md] [--json benchmarks/results/gears.json]
                                 [--repeat 3] [--peer-repeat 3] [--no-peer] [--venv DIR]

Three studies, all measured in this run:

1. **Against the peer** (geometry.md, "Non-circular gear teeth"): ncgears 0.3.1 generating and
   verifying one conjugate pair, 24 teeth on r = 30 + 8 cos t, module 2.5, 20 deg. ncgears scales
   the curve so that the drive pitch perimeter is exactly z pi m; we scale it the same way
   (r_s(t) = s (30 + 8 cos t), s = 24 pi 2.5 / perimeter) and use its tooth settings (addendum
   1.0 m, dedendum 1.2 m, cutter tip radius 0.3 m). Ours is timed as ``generate_pair`` (both gears
   and their checks) plus ``meshing_check`` at 384 poses, best of ``--repeat``, at several flank
   resolutions; the peer through :func:`benchmarks.peer_ncgears.run_peer` (its own venv, fresh
   interpreter per run, best of ``--peer-repeat``). If the peer cannot be run (no network for the
   first install, a failing install), our side is still measured and the peer is reported missing.
2. **Flank resolution against accuracy and time**: the drive gear's analytic outline against
   ``simulated_rack_cut`` (boolean subtraction of the rack at 400 positions per pitch, computed
   once), with the reference's own scallop error estimated from 200 against 400 positions.
3. **DXF chord tolerance against accuracy and time**: one gear written with ``write_gear_dxf`` at
   several tolerances, re-read with ezdxf, compared with the dense outline.

Writes the tables to ``docs/gears.md`` and every figure to ``benchmarks/results/gears.json``.
Progress goes to stdout.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cadgen.gears.pairs import PitchPair, generate_pair
from cadgen.gears.meshing import meshing_check
from cadgen.gears.teeth import (ToothSystem, gear_outline, rack_space_boundary,
                          rack_tooth_outline, simulated_rack_cut)
from kinematics.pitch_curves import polar_perimeter, solve_closure

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_OUTPUT = ROOT / "docs" / "gears.md"
#: The line after which the output file holds hand-written text (the profile shift's section):
#: kept as it is when the tables are generated again.
HAND_WRITTEN = "<!-- hand-written below: kept by python -m benchmarks.gears -->"


def _hand_written(path: Path) -> str:
    """The hand-written end of ``path`` (from :data:`HAND_WRITTEN` on), or nothing."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError:
        return ""
    start = text.find(HAND_WRITTEN)
    return "" if start < 0 else "\n\n" + text[start:]
DEFAULT_JSON = Path(__file__).resolve().parent / "results" / "gears.json"

TEETH = 24
MODULE = 2.5
# ncgears' defaults: addendum 1.0 m, dedendum 1.2 m, rack tip fillet 0.3 m, 20 deg
SYSTEM = ToothSystem(MODULE, pressure_angle=np.radians(20.0), addendum=1.0, dedendum=1.2,
                     tip_radius=0.3)
POSES = 384
PEER_FLANKS = (48, 96, 192, 400)
ACCURACY_FLANKS = (12, 24, 48, 96, 192, 400)
REFERENCE_POSITIONS = 400
COARSE_POSITIONS = 200
# (flank_points, fillet_points) of the root-fillet diagnostic; 16 is the generator's default
FILLET_CASES = ((48, 16), (48, 32), (48, 64), (48, 128), (400, 128))
#: rack height (mm) above the flank/fillet junction below which a flank vertex counts as root
JUNCTION_GUARD = 0.05
DXF_FLANKS = 192
DXF_TOLERANCES = (0.05, 0.01, 0.005, 0.001, 0.0002)


def log(message: str) -> None:
    print(f"[gears] {message}", flush=True)


# --------------------------------------------------------------------------- the case


@dataclass(frozen=True)
class ScaledCosine:
    """The peer's pitch curve r(t) = scale (30 + 8 cos t) (mm)."""

    scale: float = 1.0

    def radius(self, t):
        return self.scale * (30.0 + 8.0 * np.cos(np.asarray(t, dtype=float)))

    def radius_rate_bound(self) -> float:
        return 8.0 * self.scale

    def radius_derivatives(self, t):
        t = np.asarray(t, dtype=float)
        return (self.scale * (30.0 + 8.0 * np.cos(t)), -8.0 * self.scale * np.sin(t),
                -8.0 * self.scale * np.cos(t))


def build_case():
    """The scaled curve, its closure and the 1:1 closed pair (reference construction)."""
    perimeter = polar_perimeter(ScaledCosine())
    scale = TEETH * np.pi * MODULE / perimeter
    curve = ScaledCosine(scale)
    closure = solve_closure(curve)
    a, law = closure.centre_distance, closure.law

    def drive(t):
        r, dr, _ = curve.radius_derivatives(t)
        t = np.asarray(t, float)
        return r, dr, t, np.ones_like(r)

    def driven(t):
        r, dr, _ = curve.radius_derivatives(t)
        w, _ = law.ratio(t)
        return a - r, -dr, np.pi - law.integral(t), -w

    pair = PitchPair(("drive", "driven"), a, 2 * np.pi, drive, driven)
    return dict(perimeter=perimeter, scale=scale, curve=curve, closure=closure, pair=pair)


# --------------------------------------------------------------------------- geometry helpers


def ring_distances(points: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Distance of each point to the closed polyline ``ring`` (segments, via a shapely STRtree)."""
    import shapely

    ring = np.asarray(ring, dtype=float)
    segments = shapely.linestrings(np.stack([ring, np.roll(ring, -1, axis=0)], axis=1))
    tree = shapely.STRtree(segments)
    (source, _), distance = tree.query_nearest(shapely.points(np.asarray(points, dtype=float)),
                                               return_distance=True, all_matches=False)
    out = np.full(len(points), np.inf)
    np.minimum.at(out, source, distance)
    return out


def flank_mask(points: np.ndarray, curve, phase: float, system: ToothSystem,
               guard: float = JUNCTION_GUARD) -> np.ndarray:
    """True for vertices on a working flank or a tip, False in a root fillet or root.

    Each vertex takes the label of the nearest point of a dense analytic envelope (400 rack flank
    points and 200 tip-fillet points per space) or is a tip vertex (on the addendum curve). Flank
    points generated less than ``guard`` mm (rack height) above the flank/fillet junction count as
    root: there the fillet's chords start, and nearest-point labels are ambiguous. The junction is
    not at a fixed offset from the pitch curve: the generating point sits up to ~7 mm along the
    tangent from the pitch point, where the convex pitch curve has fallen away from the tangent,
    so it lies about 1.6 to 2.0 mm inside the pitch curve here, not 2.5.
    """
    from scipy.spatial import cKDTree

    flanks, fillets = 400, 200
    xy, _ = rack_tooth_outline(system, flank_points=flanks, fillet_points=fillets)
    m = system.module
    junction = -system.dedendum * m + system.tip_radius * m * (1 - np.sin(system.pressure_angle))
    label = np.zeros(len(xy), dtype=bool)
    label[:flanks] = label[-flanks:] = True
    label &= xy[:, 1] > junction + guard
    dense = [rack_space_boundary(curve, phase + (k + 0.5) * system.pitch, system,
                                 flank_points=flanks, fillet_points=fillets)
             for k in range(TEETH)]
    _, nearest = cKDTree(np.vstack(dense)).query(points)
    s = np.arange(16384) * (curve.length / 16384)
    base, _, outward = curve.frame(s)
    _, foot = cKDTree(base).query(points)
    offset = np.einsum("ij,ij->i", points - base[foot], outward[foot])
    return np.tile(label, TEETH)[nearest] | (offset > system.addendum_height - 1e-3)


def reference_fillet_sagitta(system: ToothSystem, fillet_points: int = 16) -> float:
    """Chord sagitta (mm) of the rack tip fillet as `simulated_rack_cut` draws it (16 points)."""
    step = (np.pi / 2 - system.pressure_angle) / (fillet_points - 1)
    return system.tip_radius * system.module * (1 - np.cos(step / 2))


def polygon_area(points: np.ndarray) -> float:
    x, y = points[:, 0], points[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def best_of(repeat: int, function):
    """(best seconds, result of the best run)."""
    best, result = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        value = function()
        elapsed = time.perf_counter() - start
        if elapsed < best:
            best, result = elapsed, value
    return best, result


# --------------------------------------------------------------------------- 1. the peer


def ours_against_peer(case, repeat: int):
    pair = case["pair"]
    rows = []
    for flanks in PEER_FLANKS:
        def run():
            t0 = time.perf_counter()
            generated = generate_pair(pair, TEETH, system=SYSTEM, flank_points=flanks)
            t1 = time.perf_counter()
            report = meshing_check(*generated.profiles, pair, poses=POSES)
            return generated, report, t1 - t0, time.perf_counter() - t1

        seconds, (generated, report, gen_s, mesh_s) = best_of(repeat, run)
        row = dict(
            flank_points=flanks, seconds=seconds, generate_s=gen_s, meshing_s=mesh_s,
            outline_points=[len(p.outline) for p in generated.profiles],
            free_play_max_deg=report.free_play_max_deg,
            transmission_error_pp_deg=report.transmission_error_pp_deg,
            backlash_deg=[report.backlash_min_deg, report.backlash_max_deg],
            interference_poses=report.interference_poses,
            overlap_area_max_mm2=report.overlap_area_max,
            poses=report.poses, cutters=[c.cutter for c in generated.checks],
            problems=[p for c in generated.checks for p in c.problems])
        rows.append(row)
        log(f"ours, flank_points {flanks}: {seconds:.3f} s (generate {gen_s:.3f} + meshing "
            f"{mesh_s:.3f}), {row['outline_points']} points, free play "
            f"{row['free_play_max_deg']:.3g} deg, TE p-p "
            f"{row['transmission_error_pp_deg']:.3g} deg, "
            f"interference at {row['interference_poses']}/{POSES} poses")
    return rows


def the_peer(repeat: int, venv_dir):
    try:
        from benchmarks.peer_ncgears import DEFAULT_VENV, run_peer
        result = run_peer(teeth=TEETH, module=MODULE, pressure_angle_deg=20.0, repeat=repeat,
                          venv_dir=venv_dir or DEFAULT_VENV,
                          log=lambda message: log(f"peer: {message}"))
    except Exception as error:  # no network, failed install, failing peer: report it missing
        text = str(error).strip()
        reason = type(error).__name__ + (f": {text.splitlines()[-1]}" if text else "")
        log(f"the peer could not be run ({reason}); continuing with our side only")
        return None, reason
    result = {k: v for k, v in result.items() if k != "ncgears_metadata"}
    log(f"peer: best {result['timing']['generate_verify_s_best']:.3f} s, TE "
        f"{result['transmission_error_deg']:.3g} deg over {result['transmission_error_poses']} "
        f"poses, centre distance {result['centre_distance_mm']!r} mm")
    return result, None


# --------------------------------------------------------------------------- 2. flank resolution


def _two_way(ours, ours_flank, reference, reference_flank):
    """Largest vertex-to-polyline distance both ways: whole, flanks (and tips), roots."""
    there = ring_distances(ours, reference)
    back = ring_distances(reference, ours)
    return dict(
        ours_to_reference_max=float(there.max()), reference_to_ours_max=float(back.max()),
        deviation_max=float(max(there.max(), back.max())),
        deviation_flank=float(max(there[ours_flank].max(), back[reference_flank].max())),
        deviation_root=float(max(there[~ours_flank].max(), back[~reference_flank].max())))


def flank_accuracy(case, repeat: int):
    pair = case["pair"]
    first = generate_pair(pair, TEETH, system=SYSTEM, flank_points=48)
    curve, phase = first.curves[0], first.phases[0]
    log(f"reference: simulated rack cut at {REFERENCE_POSITIONS} positions per pitch ...")
    start = time.perf_counter()
    reference = simulated_rack_cut(curve, TEETH, SYSTEM, phase=phase,
                                   positions_per_pitch=REFERENCE_POSITIONS)
    reference_s = time.perf_counter() - start
    log(f"  {len(reference)} vertices, {reference_s:.2f} s; and at {COARSE_POSITIONS} positions ...")
    start = time.perf_counter()
    coarse = simulated_rack_cut(curve, TEETH, SYSTEM, phase=phase,
                                positions_per_pitch=COARSE_POSITIONS)
    coarse_s = time.perf_counter() - start
    reference_flank = flank_mask(reference, curve, phase, SYSTEM)
    coarse_flank = flank_mask(coarse, curve, phase, SYSTEM)
    between = _two_way(coarse, coarse_flank, reference, reference_flank)
    scallop = dict(
        positions=[COARSE_POSITIONS, REFERENCE_POSITIONS], reference_vertices=len(reference),
        coarse_vertices=len(coarse), reference_s=reference_s, coarse_s=coarse_s,
        rolling_step_mm=SYSTEM.pitch / REFERENCE_POSITIONS,
        fillet_sagitta=reference_fillet_sagitta(SYSTEM),
        **{f"between_{k}": v for k, v in between.items()})
    # scallops shrink with the square of the step: d(200, 400) ~ e200 - e400 = 3 e400
    scallop["floor_flank"] = between["deviation_flank"] / 3.0
    scallop["floor_root"] = max(between["deviation_root"] / 3.0, scallop["fillet_sagitta"])
    log(f"  reference {COARSE_POSITIONS} vs {REFERENCE_POSITIONS} positions: flanks "
        f"{between['deviation_flank']:.3g} mm, roots {between['deviation_root']:.3g} mm: the "
        f"reference's own error is about {scallop['floor_flank']:.2g} mm on the flanks and "
        f"{scallop['floor_root']:.2g} mm in the roots (its 16-point rack fillet: sagitta "
        f"{scallop['fillet_sagitta']:.2g} mm)")
    rows = []
    for flanks in ACCURACY_FLANKS:
        seconds, generated = best_of(repeat, lambda: generate_pair(pair, TEETH, system=SYSTEM,
                                                                   flank_points=flanks))
        outline_s, _ = best_of(repeat, lambda: gear_outline(curve, TEETH, SYSTEM, phase=phase,
                                                            flank_points=flanks))
        outline = generated.profiles[0].outline
        row = dict(flank_points=flanks, seconds=seconds, drive_outline_s=outline_s,
                   drive_outline_points=len(outline),
                   **_two_way(outline, flank_mask(outline, curve, phase, SYSTEM), reference,
                              reference_flank),
                   area_difference_mm2=polygon_area(outline) - polygon_area(reference))
        vs_coarse = _two_way(outline, flank_mask(outline, curve, phase, SYSTEM), coarse,
                             coarse_flank)
        row["vs_coarse_deviation_flank"] = vs_coarse["deviation_flank"]
        rows.append(row)
        log(f"flank_points {flanks}: {len(outline)} points, deviation flanks "
            f"{row['deviation_flank']:.3g} mm, roots {row['deviation_root']:.3g} mm, "
            f"generate_pair {seconds:.3f} s (drive outline alone {outline_s * 1e3:.0f} ms)")
    # diagnostic: the root fillet's own resolution (fillet_points, not exposed by generate_pair)
    fillet_rows = []
    for flanks, fillets in FILLET_CASES:
        seconds, (outline, _) = best_of(repeat, lambda: gear_outline(
            curve, TEETH, SYSTEM, phase=phase, flank_points=flanks, fillet_points=fillets))
        row = dict(flank_points=flanks, fillet_points=fillets, seconds=seconds,
                   drive_outline_points=len(outline),
                   **_two_way(outline, flank_mask(outline, curve, phase, SYSTEM), reference,
                              reference_flank))
        fillet_rows.append(row)
        log(f"gear_outline flank_points {flanks}, fillet_points {fillets}: {len(outline)} points, "
            f"deviation flanks {row['deviation_flank']:.3g} mm, roots {row['deviation_root']:.3g} mm")
    return rows, scallop, fillet_rows


# --------------------------------------------------------------------------- 3. DXF


def dxf_tolerance(case, repeat: int):
    import ezdxf

    from cadgen.export.dxf import write_gear_dxf

    generated = generate_pair(case["pair"], TEETH, system=SYSTEM, flank_points=DXF_FLANKS)
    profile = generated.profiles[0]
    dense = np.asarray(profile.outline, dtype=float)
    dense_area = polygon_area(dense)
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for tolerance in DXF_TOLERANCES:
            path = Path(scratch) / f"drive-{tolerance:g}.dxf"
            seconds, summary = best_of(repeat, lambda: write_gear_dxf(path, profile,
                                                                      chord_tolerance=tolerance))
            doc = ezdxf.readfile(path)
            outlines = doc.modelspace().query('LWPOLYLINE[layer=="OUTLINE"]')
            written = np.array([p[:2] for p in outlines[0].get_points("xy")], dtype=float)
            if np.allclose(written[0], written[-1]):
                written = written[:-1]
            deviation = ring_distances(dense, written)
            audit = doc.audit()
            row = dict(
                chord_tolerance=tolerance, chord_tolerance_used=summary.chord_tolerance_used,
                points_written=summary.outline_points_written, points_read=len(written),
                outline_polylines=len(outlines), deviation_max=float(deviation.max()),
                area_error_mm2=polygon_area(written) - dense_area,
                area_error_relative=(polygon_area(written) - dense_area) / dense_area,
                summary_area_mm2=summary.outline_area, file_bytes=path.stat().st_size,
                audit_errors=len(audit.errors), seconds=seconds)
            rows.append(row)
            log(f"DXF chord tolerance {tolerance:g} mm: {row['points_written']} points, deviation "
                f"{row['deviation_max']:.3g} mm, area error {row['area_error_mm2']:.3g} mm^2, "
                f"{seconds * 1e3:.0f} ms")
    return dict(dense_points=len(dense), dense_area_mm2=dense_area, flank_points=DXF_FLANKS,
                gear=profile.name, rows=rows)


# --------------------------------------------------------------------------- report


def fmt(value, spec=".3g"):
    return "n/a" if value is None else format(value, spec)


def report(case, ours, peer, peer_error, accuracy, scallop, fillets, dxf, meta) -> list[str]:
    a = case["closure"].centre_distance
    lines = [
        "# Non-circular gear teeth: against the peer, and accuracy against time",
        "",
        "Generated by `python -m benchmarks.gears` (do not edit by hand). Machine: "
        f"{meta['cpu_count']} CPUs, {meta['platform']}, Python {meta['python']}. "
        f"Total run {meta['total_s']:.0f} s.",
        "",
        "Case (the spec's peer case): pitch curve r = s (30 + 8 cos t), s chosen so the drive "
        f"pitch perimeter is exactly 24 pi 2.5 = {TEETH * np.pi * MODULE:.6f} mm "
        f"(unscaled perimeter {case['perimeter']:.6f} mm, s = {case['scale']:.9f}); 24:24 teeth, "
        "module 2.5, 20 deg, addendum 1.0 m, dedendum 1.2 m, cutter tip radius 0.3 m (ncgears' "
        "rack tip fillet), no backlash. Cutters chosen by `generate_pair`: "
        f"{' / '.join(ours[0]['cutters'])} (drive / driven); generator checks: "
        + ("; ".join(sorted({str(p) for r in ours for p in r['problems']})) or "no problems")
        + ".",
        "",
        "## 1. Against the peer (ncgears 0.3.1), same run",
        "",
    ]
    if peer is None:
        lines += [f"**The peer is missing from this run**: {peer_error}. Only our side is shown.", ""]
    peer_s = peer["timing"]["generate_verify_s_best"] if peer else None
    lines += [
        f"Ours: `generate_pair` (both gears, their checks) + `meshing_check` at {POSES} poses, "
        f"best of {meta['repeat']} in this process. Peer: `ncgears.generate_from_centrode(...)` "
        "(both gears, its checks and its verification, incl. writing its CSV/JSON result files; "
        f"interpreter start and import excluded), best of {meta['peer_repeat']}, each in a fresh "
        "interpreter of its own venv"
        + (f", using {peer['machine']['geometry_worker_threads']} geometry threads; ours is "
           "started without worker threads." if peer else "."),
        "",
        f"**Transmission error: ours is measured over all {POSES} poses, the peer's over "
        f"{peer['transmission_error_poses'] if peer else 6} poses.** Free play = the peer's "
        "definition (largest, over the poses, of the smaller free turn of the driven gear to first "
        "contact, in deg); TE p-p = our peak-to-peak of the driven gear's deviation from the law "
        "with either flank driving. Both are 0 for exact zero-backlash conjugate flanks, so on "
        "polygon outlines they measure the chord gaps of the tessellated flanks.",
        "",
        "| implementation | flank points | outline points (drive/driven) | time (s) | generate / verify (s) "
        "| peer time / ours | free play max (deg) | TE p-p (deg) | backlash range (deg) "
        "| interference |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for row in ours:
        ratio = f"{peer_s / row['seconds']:.1f}" if peer else "n/a"
        interference = (f"{row['interference_poses']}/{POSES} poses, max area "
                        f"{row['overlap_area_max_mm2']:.3g} mm^2")
        lines.append(
            f"| ours | {row['flank_points']} | {row['outline_points'][0]} / {row['outline_points'][1]} "
            f"| {row['seconds']:.3f} | {row['generate_s']:.3f} / {row['meshing_s']:.3f} | {ratio} "
            f"| {row['free_play_max_deg']:.3g} ({POSES} poses) | {row['transmission_error_pp_deg']:.3g} "
            f"| {row['backlash_deg'][0]:.3g} .. {row['backlash_deg'][1]:.3g} | {interference} |")
    if peer:
        tess = peer["tessellation"]
        backlash = peer["geometry"]["backlash_deg"]
        lines.append(
            f"| ncgears {peer['peer']['version']} | adaptive (chord {tess['chord_tolerance_mm']:.3g} mm) "
            f"| {tess['drive_outline_points']} / {tess['driven_outline_points']} | {peer_s:.3f} "
            f"| (one call) | 1.0 | {peer['transmission_error_deg']:.3g} "
            f"({peer['transmission_error_poses']} poses) | n/a "
            f"| {fmt(backlash[0])} .. {fmt(backlash[1])} (designed, from its clearance; not measured) "
            f"| max area {peer['overlap_area_max_mm2']:.3g} mm^2 over {peer['overlap_poses']} poses "
            f"(limit {peer['overlap_area_tolerance_mm2']:.3g}) |")
    else:
        lines.append("| ncgears 0.3.1 | missing | | | | | | | | |")
    lines += ["", "Centre distance:", "",
              "| | value (mm) |", "|---|---:|",
              f"| ours (`solve_closure` on the scaled curve; its error estimate "
              f"{case['closure'].error_estimate:.1e} mm) | {a:.12f} |"]
    if peer:
        difference = a - peer["centre_distance_mm"]
        lines += [f"| ncgears (scaled reference C0 x scale {peer['pitch_curve_scale']:.9f}) "
                  f"| {peer['centre_distance_mm']:.12f} |",
                  f"| ours - peer | {difference:.2e} |",
                  f"| scale: ours - peer | {case['scale'] - peer['pitch_curve_scale']:.2e} |"]
    else:
        lines.append("| ncgears | missing |")
    lines += ["", "## 2. Flank resolution against accuracy and time", "",
              f"The drive gear's analytic outline (`generate_pair(..., flank_points=n)`) against a "
              f"simulated cut: the rack polygon subtracted from the blank at {REFERENCE_POSITIONS} "
              f"rolling positions per pitch (`simulated_rack_cut`, {scallop['reference_vertices']} "
              f"vertices, {scallop['reference_s']:.1f} s, computed once). Deviation = largest "
              "distance of either outline's vertices to the other's polyline (shapely), split into "
              "*flanks* (vertices generated by the rack's straight flank, and the tips) and *roots* "
              "(root fillets and roots, generated by the rack's tip fillet and tip, plus the flank "
              f"within {JUNCTION_GUARD} mm of rack height above the flank/fillet junction); each "
              "vertex is labelled by the nearest point of a dense analytic envelope. Times: `generate_pair` "
              "(both gears and their checks) and `gear_outline` for the drive gear alone, best of "
              f"{meta['repeat']}.",
              "",
              f"**Reference floor.** The reference is itself off by the scallops between rack "
              f"positions (rolling step {scallop['rolling_step_mm'] * 1e3:.1f} um). The same cut "
              f"at {COARSE_POSITIONS} positions differs from the {REFERENCE_POSITIONS}-position one "
              f"by {scallop['between_deviation_flank']:.1e} mm on the flanks and "
              f"{scallop['between_deviation_root']:.1e} mm in the roots; with scallops shrinking "
              "as the square of the step, the reference's own flank error is about "
              f"{scallop['floor_flank']:.0e} mm. In the roots, `simulated_rack_cut` draws the rack's "
              f"tip fillet as a 16-point polygon (hard-coded), whose chord sagitta "
              f"{scallop['fillet_sagitta']:.1e} mm is the floor there. Deviations at or below "
              "these floors are the reference's error, not ours.",
              "",
              "| flank points | drive outline points | deviation, flanks (mm) | deviation, roots (mm) "
              "| whole outline (mm) | ours -> ref | ref -> ours | flanks vs the 200-position cut (mm) "
              "| area ours - ref (mm^2) | generate_pair (ms) | drive outline alone (ms) |",
              "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in accuracy:
        lines.append(
            f"| {row['flank_points']} | {row['drive_outline_points']} | {row['deviation_flank']:.2e} "
            f"| {row['deviation_root']:.2e} | {row['deviation_max']:.2e} "
            f"| {row['ours_to_reference_max']:.2e} | {row['reference_to_ours_max']:.2e} "
            f"| {row['vs_coarse_deviation_flank']:.2e} | {row['area_difference_mm2']:.2e} "
            f"| {row['seconds'] * 1e3:.0f} | {row['drive_outline_s'] * 1e3:.0f} |")
    lines.append(f"| reference floor ({REFERENCE_POSITIONS}/pitch) | {scallop['reference_vertices']} "
                 f"| ~{scallop['floor_flank']:.0e} | ~{scallop['fillet_sagitta']:.1e} | | | | "
                 f"{scallop['between_deviation_flank']:.2e} (200 vs 400) | | "
                 f"{scallop['reference_s'] * 1e3:.0f} (the cut) | |")
    lines += ["", "Root fillet resolution: the rack's tip fillet is drawn with `fillet_points`; "
              "`generate_pair` sets it to half the flank points (at least 16), which is why the "
              "root deviation above falls to the reference's floor from 96 flank points on. "
              "Calling `gear_outline` directly for the drive gear:",
              "",
              "| flank points | fillet points | drive outline points | deviation, flanks (mm) "
              "| deviation, roots (mm) | time (ms) |",
              "|---:|---:|---:|---:|---:|---:|"]
    for row in fillets:
        lines.append(f"| {row['flank_points']} | {row['fillet_points']} | "
                     f"{row['drive_outline_points']} | {row['deviation_flank']:.2e} "
                     f"| {row['deviation_root']:.2e} | {row['seconds'] * 1e3:.0f} |")
    lines += ["", "## 3. DXF chord tolerance against accuracy and time", "",
              f"The drive gear at flank_points = {dxf['flank_points']} ({dxf['dense_points']} "
              "points) written with `write_gear_dxf(path, profile, chord_tolerance=...)` and read "
              "back with ezdxf. Deviation = largest distance of the dense outline's vertices to the "
              "written OUTLINE polyline; area error = written minus dense (dense area "
              f"{dxf['dense_area_mm2']:.4f} mm^2). Time = the whole write (thinning, document, "
              f"audit, atomic write), best of {meta['repeat']}.",
              "",
              "| chord tolerance (mm) | used (mm) | points written | deviation (mm) | area error (mm^2) "
              "| relative area error | file size (kB) | time (ms) |",
              "|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in dxf["rows"]:
        lines.append(
            f"| {row['chord_tolerance']:g} | {row['chord_tolerance_used']:g} | {row['points_written']} "
            f"| {row['deviation_max']:.2e} | {row['area_error_mm2']:.2e} "
            f"| {row['area_error_relative']:.1e} | {row['file_bytes'] / 1024:.0f} "
            f"| {row['seconds'] * 1e3:.0f} |")
    lines.append("")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=DEFAULT_OUTPUT)
    parser.add_argument("--json", type=Path, default=DEFAULT_JSON)
    parser.add_argument("--repeat", type=int, default=3, help="runs of ours; the best is kept")
    parser.add_argument("--peer-repeat", type=int, default=3, help="runs of the peer")
    parser.add_argument("--no-peer", action="store_true", help="skip the peer (report it missing)")
    parser.add_argument("--venv", type=Path, default=None, help="the peer's virtualenv")
    args = parser.parse_args(argv)

    started = time.perf_counter()
    case = build_case()
    log(f"case: scale {case['scale']:.9f}, centre distance {case['closure'].centre_distance!r} mm")
    log("1. against the peer: ours ...")
    ours = ours_against_peer(case, args.repeat)
    if args.no_peer:
        peer, peer_error = None, "skipped (--no-peer)"
        log("peer skipped (--no-peer)")
    else:
        log("1. against the peer: ncgears ...")
        peer, peer_error = the_peer(args.peer_repeat, args.venv)
    if peer:
        log(f"centre distance ours - peer = "
            f"{case['closure'].centre_distance - peer['centre_distance_mm']:.2e} mm")
    log("2. flank resolution against the simulated cut ...")
    accuracy, scallop, fillets = flank_accuracy(case, args.repeat)
    log("3. DXF chord tolerance ...")
    dxf = dxf_tolerance(case, args.repeat)
    meta = dict(cpu_count=os.cpu_count(), platform=platform.platform(),
                python=sys.version.split()[0], repeat=args.repeat, peer_repeat=args.peer_repeat,
                total_s=time.perf_counter() - started)

    lines = report(case, ours, peer, peer_error, accuracy, scallop, fillets, dxf, meta)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text("\n".join(lines) + _hand_written(args.output), encoding="utf-8")
    closure = case["closure"]
    result = dict(
        machine=meta,
        case=dict(teeth=TEETH, module=MODULE, pressure_angle_deg=20.0, addendum=SYSTEM.addendum,
                  dedendum=SYSTEM.dedendum, tip_radius=SYSTEM.tip_radius,
                  unscaled_perimeter_mm=case["perimeter"], scale=case["scale"],
                  centre_distance_mm=closure.centre_distance,
                  centre_distance_error_estimate_mm=closure.error_estimate),
        against_peer=dict(ours=ours, poses=POSES, peer=peer, peer_missing=peer_error,
                          centre_distance_difference_mm=(closure.centre_distance
                                                         - peer["centre_distance_mm"])
                          if peer else None,
                          time_ratio_peer_over_ours={str(r["flank_points"]):
                                                     peer["timing"]["generate_verify_s_best"]
                                                     / r["seconds"] for r in ours} if peer else None),
        flank_resolution=dict(rows=accuracy, reference=scallop, fillet_diagnostic=fillets),
        dxf_chord_tolerance=dxf)
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    log(f"wrote {args.output} and {args.json} ({meta['total_s']:.0f} s)")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
