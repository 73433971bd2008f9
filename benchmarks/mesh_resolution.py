"""Mesh resolution of the solids: accuracy against time (part of ``python -m benchmarks.accuracy``).

Two knobs set how closely the STL meshes follow the true parts:

* ``solids.segments_per_circle``: facets of a round feature. Measured on the
  planter's duckbill tube (a hollow cylinder: volume and surface in closed
  form) and on gearbox 2's housing (the hull of three discs; its outline is
  circumscribed, so the reference is the exact disc hull, computed here with
  shapely from analytic arcs at 2^16 points per circle, whose own error is
  below 1e-8 relative).
* ``gears.flank_points``: points per generated tooth flank. Measured on the
  paper's 40-tooth sun gear (module 1.8) and on the non-circular central gear.
  A rack-cut gear's root is a trochoid with no closed-form area, so the
  reference is the same gear generated at 2000 flank points (converged: its
  change from 1000 points is printed).

Errors are relative (volume, surface area of the extruded part). Times: best of
3 for the tube and housing builds; one generation for a gear (the whole cut,
envelope and checks, plus the extrusion).
"""

from __future__ import annotations

import math
import time

import numpy as np

from .accuracy import timed

SEGMENTS = (16, 32, 64, 96, 256, 1024)
FLANK_POINTS = (12, 24, 48, 96, 192, 384)
REFERENCE_FLANK_POINTS = 2000


def _tube(outer, wall, length, segments):
    import manifold3d as m3d

    from cadgen.solids.extrude import to_trimesh

    solid = (m3d.Manifold.cylinder(length, outer, outer, segments)
             - m3d.Manifold.cylinder(length, outer - wall, outer - wall, segments))
    return to_trimesh(solid, "tube")


def segments_table(params, mechanism):
    """Rows ``(segments, tube volume err, tube area err, housing volume err, ms)``."""
    import shapely

    from cadgen.solids.housings import housing_circles, planting_shells
    from cadgen.solids.extrude import to_trimesh
    from cadgen.solids.shell import closed_shell

    outer, wall, length = 28.77, params.planter.shell_wall, 109.0
    inner = outer - wall
    tube_volume = math.pi * (outer**2 - inner**2) * length
    tube_area = 2 * math.pi * (outer + inner) * length + 2 * math.pi * (outer**2 - inner**2)
    shells = planting_shells(params, mechanism)
    box = shells["gearbox2"]
    a, r = mechanism.centre_distance, mechanism.r
    radius = {c.point: c.radius for c in housing_circles(params, mechanism) if c.gearbox == "gearbox2"}
    # the envelope circles reach the flange's edge: the gears' discs are inside by that much
    discs = [(0.0, 0.0, radius["C"] - box.envelope), (a, 0.0, radius["D"] - box.envelope),
             (a + 2 * r, 0.0, radius["E"] - box.envelope)]
    height = 33.5

    def exact_hull(grow):
        t = np.linspace(0, 2 * np.pi, 2**16, endpoint=False)
        points = np.concatenate([np.column_stack([x + (q + grow) * np.cos(t), y + (q + grow) * np.sin(t)])
                                 for x, y, q in discs])
        return shapely.MultiPoint(points).convex_hull.area

    exact = (exact_hull(box.clearance + box.wall) * (height + 2 * box.wall)
             - exact_hull(box.clearance) * height)
    rows = []
    for n in SEGMENTS:
        tube, tube_seconds = timed(lambda: _tube(outer, wall, length, n))
        housing, seconds = timed(lambda: to_trimesh(closed_shell(
            discs, height=height, clearance=box.clearance, wall=box.wall, segments=n).solid,
            "gearbox2"))
        rows.append((n, tube.volume / tube_volume - 1, tube.area / tube_area - 1,
                     housing.volume / exact - 1, (tube_seconds + seconds) * 1e3))
        print(f"segments {n:>5}: tube volume {rows[-1][1]:9.2e}, area {rows[-1][2]:9.2e}, "
              f"housing volume {rows[-1][3]:9.2e}, {rows[-1][4]:7.1f} ms", flush=True)
    return rows


def flank_table(params, mechanism):
    """Rows ``(gear, flank points, volume err, area err, triangles, seconds)``."""
    from cadgen.gears.pairs import circle_pair, generate_pair
    from cadgen.gears.trains import _system, planting_pair
    from cadgen.solids.extrude import to_trimesh
    from cadgen.solids.parts import gear_solid

    cutting = params.gears
    teeth = params.pitch_curve.teeth
    cases = {
        "sun (40 teeth, m 1.8)": (circle_pair(("sun", "idler"), 36.0, 43.2), (40, 48),
                                  _system(cutting, 1.8)),
        f"central, non-circular ({teeth} teeth)": (
            planting_pair(mechanism), teeth, _system(cutting, mechanism.module(teeth))),
    }

    def solid(pair, z, system, points):
        generated = generate_pair(pair, z, system=system, flank_points=points)
        profile = generated.profiles[0]
        # the raw generated outline (no DXF thinning): what the flank points alone buy
        return to_trimesh(gear_solid(profile, 10.0, 96, "gears.face_width",
                                     chord_tolerance=1e-9)[0], profile.name)

    rows = []
    for label, (pair, z, system) in cases.items():
        reference = solid(pair, z, system, REFERENCE_FLANK_POINTS)
        previous = solid(pair, z, system, REFERENCE_FLANK_POINTS // 2)
        print(f"{label}: reference change 1000 -> 2000 flank points: volume "
              f"{previous.volume / reference.volume - 1:.1e}", flush=True)
        for points in FLANK_POINTS:
            start = time.perf_counter()
            mesh = solid(pair, z, system, points)
            seconds = time.perf_counter() - start
            rows.append((label, points, mesh.volume / reference.volume - 1,
                         mesh.area / reference.area - 1, len(mesh.faces), seconds))
            print(f"{label} flank points {points:>4}: volume {rows[-1][2]:9.2e}, area "
                  f"{rows[-1][3]:9.2e}, {len(mesh.faces)} triangles, {seconds:6.2f} s", flush=True)
    return rows


def markdown(segments, flanks) -> list:
    """The tables of :func:`segments_table` and :func:`flank_table` rows."""
    lines = ["", "## Solids: mesh resolution", "",
             "Relative errors of the extruded parts (negative: the mesh is smaller). Round "
             "features are inscribed polygons (the tube) except the housings, whose outlines are "
             "circumscribed so that they always enclose their gears (positive error).", "",
             "### Segments per circle (`solids.segments_per_circle`, default 96)", "",
             "Tube: the duckbill tube, outer radius 28.77 mm, wall 2.5 mm, 109 mm long (closed "
             "form). Housing: gearbox 2 of the paper's design against the exact hull of its discs.",
             "", "| segments | tube volume | tube surface | housing volume | time (ms) |",
             "|---:|---:|---:|---:|---:|"]
    for n, volume, area, housing, ms in segments:
        lines.append(f"| {n} | {volume:.2e} | {area:.2e} | {housing:.2e} | {ms:.1f} |")
    lines += ["", "### Flank points per tooth (`gears.flank_points`, default 96)", "",
              f"Against the same gear at {REFERENCE_FLANK_POINTS} flank points, face width 10 mm, "
              "before the DXF thinning (which the written STL adds at the chord tolerance). Time: "
              "cutting the pair and extruding the gear. The volume converges with the square of "
              "the flank spacing. The non-circular gear's surface converges more slowly: its "
              "concave stretches are finished by the pinion cutter's secondary cuts at a fixed 8 "
              "rolling positions per pitch, whose scallops the flank points do not refine.", "",
              "| gear | flank points | volume | surface | triangles | time (s) |",
              "|---|---:|---:|---:|---:|---:|"]
    for label, points, volume, area, triangles, seconds in flanks:
        lines.append(f"| {label} | {points} | {volume:.2e} | {area:.2e} | {triangles} | "
                     f"{seconds:.2f} |")
    return lines
