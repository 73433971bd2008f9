"""What a build's solids came to: the assembly, its housings' enclosure checks, mass properties.

The report section lists each part's mass properties at its material's density
(``[manufacturing] process``, :func:`cadgen.machine.fits.process_fits`; or the
file's ``solids.density_kg_m3`` for every part), per
housing whether its gears stay inside the cavity over a revolution, and each part's
printing pose (:func:`printing_pose`: largest flat face down on z = 0, centred on
x = y = 0) checked against the printer's build volume; the files are written by
:func:`cadgen.export.meshes.write_solids` (the STLs in that pose).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cadgen.params.machine import DEFAULT_BUILD_VOLUME

__all__ = ["SolidsOutcome", "solids_outcome", "solids_report", "enclosure_checks",
           "printing_pose", "resting_faces", "fits_build_volume", "SUPPORT_RTOL", "FACE_AREA_RTOL",
           "FOOTPRINT_AREA_RTOL"]

#: A facet lies on a supporting plane of the part (the part can rest on it) when no
#: vertex is further than this fraction of the part's size on its outer side.
SUPPORT_RTOL = 1e-9
#: Flat faces whose areas differ by less than this fraction are equally large: the
#: one already facing down (-z) is kept, so a gear is not turned over for rounding.
FACE_AREA_RTOL = 1e-6
#: A part is turned about z onto its footprint's smallest box only when that box is
#: smaller by more than this fraction: a round part (a gear, the cam) keeps its angle.
FOOTPRINT_AREA_RTOL = 0.01
#: Parts that are not made (the soil slab, a bought sprocket's envelope): not checked against
#: the build volume, not in the bill's made parts.
_NOT_MADE = frozenset({"ground", "sprocket"})


@dataclass
class SolidsOutcome:
    assembly: object
    housings: dict           # housing name -> Housing (shell) or SplitHousing (split_housing)
    enclosure: list          # one dict per housing
    carrier_angle: float     # rad, the assembly file's pose
    density: float | None    # kg/m^3 of every made part, or None: each part's material's
    file_type: str
    build_volume: tuple = DEFAULT_BUILD_VOLUME   # mm (x, y, z), the printer's
    process: str = "machined"                    # [manufacturing] process: parts' materials
    segments: int = 96                           # polygons per circle (the overlaps' chord)
    gear_material: str | None = None             # [machine] gear_material, else the process's
    _poses: dict = field(default_factory=dict, repr=False)
    _overhangs: dict = field(default_factory=dict, repr=False)   # printed parts' (mm^2)
    _printed: dict = field(default_factory=dict, repr=False)   # part name -> printing mesh
    _made: dict = field(default_factory=dict, repr=False)   # what once() computed, by key

    def once(self, key, compute):
        """``compute()``, computed once per key (the STL bytes, the assembly file, the report
        section): a build prepares them while it waits for its worker, then writes them."""
        if key not in self._made:
            self._made[key] = compute()
        return self._made[key]

    def printing_pose(self, part) -> np.ndarray:
        """The part's printing pose, computed once per part: a printed part on the resting face
        with the least overhang that fits the printer (:mod:`cadgen.solids.printing`), any other
        on its largest flat face (:func:`printing_pose`)."""
        if part.name not in self._poses:
            if self.printed(part):
                from cadgen.solids.printing import least_overhang_pose

                pose, overhang = least_overhang_pose(part.mesh, self.build_volume)
                self._poses[part.name], self._overhangs[part.name] = pose, overhang
            else:
                self._poses[part.name] = printing_pose(part.mesh)
        return self._poses[part.name]

    def printed(self, part) -> bool:
        """Whether the part is printed (its material's process), not bought or machined."""
        from cadgen.machine.fits import FitError, process_fits

        try:
            return process_fits(self.process, self.gear_material).material(
                part.kind).process == "printed"
        except FitError:   # not a made part (the soil, a bought sprocket)
            return False

    def overhang(self, part) -> float | None:
        """A printed part's overhang area in its printing pose (mm^2), None for another."""
        self.printing_pose(part)
        return self._overhangs.get(part.name)

    def printing_mesh(self, part):
        """A copy of the part's mesh in its printing pose (what its STL holds), made once per
        part (the report's print extents and the STL both read it; neither changes it)."""
        if part.name not in self._printed:
            self._printed[part.name] = part.mesh.copy().apply_transform(self.printing_pose(part))
        return self._printed[part.name]


def solids_outcome(params, assembly, housings) -> SolidsOutcome:
    """The solids of a build with their enclosure checks and the file's output settings."""
    settings = params.solids
    return SolidsOutcome(assembly, housings, enclosure_checks(assembly, housings),
                         settings.assembly_carrier_angle_rad, settings.density_kg_m3,
                         settings.assembly_format, tuple(params.manufacturing.build_volume),
                         params.manufacturing.process, settings.segments_per_circle,
                         getattr(getattr(params, "machine", None), "gear_material", None))


def _turn_onto(normal) -> np.ndarray:
    """(3, 3) rotation taking the unit vector ``normal`` to -z, about their common normal."""
    normal = np.asarray(normal, dtype=float)
    down = np.array([0.0, 0.0, -1.0])
    cosine = float(np.clip(normal @ down, -1.0, 1.0))
    axis = np.cross(normal, down)
    sine = float(np.linalg.norm(axis))
    if sine < 1e-12:
        # already down (identity), or straight up: half a turn about x
        return np.eye(3) if cosine > 0 else np.diag([1.0, -1.0, -1.0])
    axis /= sine
    cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]],
                      [-axis[1], axis[0], 0.0]])
    return np.eye(3) + sine * cross + (1.0 - cosine) * cross @ cross   # Rodrigues


def _flat_faces(mesh):
    """Every flat face of a mesh: (areas (k,), unit normals (k, 3), a point of each (k, 3)).

    trimesh's facets (groups of adjacent coplanar triangles) and the triangles in none.
    """
    facets = mesh.facets
    sizes = np.fromiter((len(f) for f in facets), dtype=np.int64, count=len(facets))
    member = np.concatenate(facets) if len(facets) else np.zeros(0, dtype=np.int64)
    in_facet = np.zeros(len(mesh.faces), dtype=bool)
    in_facet[member] = True
    single = np.flatnonzero(~in_facet)
    area_faces = np.asarray(mesh.area_faces, dtype=float)
    face_normals = np.asarray(mesh.face_normals, dtype=float)
    facet_areas, largest = _facet_areas(sizes, member, area_faces)
    areas = np.concatenate([facet_areas, area_faces[single]])
    # a facet's normal is its largest triangle's (trimesh's facets_normal)
    normals = np.concatenate([face_normals[largest].reshape(-1, 3), face_normals[single]])
    first = np.concatenate([member[np.cumsum(sizes) - sizes], single]).astype(np.int64)
    points = mesh.vertices[mesh.faces[first, 0]]
    return areas, normals, points


def _facet_areas(sizes, member, area_faces):
    """``(areas, largest)`` of trimesh's facets (``sizes`` triangles each, ``member`` their
    triangles one facet after another): each facet's area, the sum of its triangles' in facet
    order from 0 as trimesh's ``facets_area`` adds them (Python's ``sum``; bincount adds in
    input order too: the same bits), and its largest triangle (the first of equal ones, as
    ``argmax``), whose normal trimesh's ``facets_normal`` takes. Vectorised: a gear's flanks
    are thousands of two-triangle facets, a Python call each in trimesh."""
    if not len(sizes):
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    facet_of = np.repeat(np.arange(len(sizes)), sizes)
    member_areas = area_faces[member]
    areas = np.bincount(facet_of, weights=member_areas, minlength=len(sizes))
    biggest = np.maximum.reduceat(member_areas, np.cumsum(sizes) - sizes)
    at_max = np.flatnonzero(member_areas == biggest[facet_of])
    _, first_max = np.unique(facet_of[at_max], return_index=True)
    return areas, member[at_max[first_max]]


def _footprint_turn(points) -> np.ndarray:
    """(3, 3) turn about z making the smallest-area box round ``points``' (n, 2) footprint square
    with x and y, its long side along x; identity when that saves less than
    :data:`FOOTPRINT_AREA_RTOL` of the area (a gear, or a part already square with the axes,
    stays as it is).
    """
    from scipy.spatial import ConvexHull

    points = np.asarray(points, dtype=float)
    try:
        hull = points[ConvexHull(points).vertices]
    except Exception:   # a footprint of no area (qhull refuses it): nothing to turn
        return np.eye(3)
    edges = np.roll(hull, -1, axis=0) - hull
    angles = np.arctan2(edges[:, 1], edges[:, 0])
    cos, sin = np.cos(angles), np.sin(angles)
    # the hull in each edge's frame (rotated by -angle): the box's sides along the edge
    along = hull[:, 0][None, :] * cos[:, None] + hull[:, 1][None, :] * sin[:, None]
    across = -hull[:, 0][None, :] * sin[:, None] + hull[:, 1][None, :] * cos[:, None]
    widths, heights = np.ptp(along, axis=1), np.ptp(across, axis=1)
    best = int(np.argmin(widths * heights))
    current = np.ptp(hull, axis=0)
    if widths[best] * heights[best] >= current[0] * current[1] * (1.0 - FOOTPRINT_AREA_RTOL):
        return np.eye(3)
    angle = angles[best] + (0.0 if widths[best] >= heights[best] else np.pi / 2)
    c, s = np.cos(-angle), np.sin(-angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def resting_faces(mesh, *, support_rtol: float = SUPPORT_RTOL) -> list:
    """``[(area, unit outward normal)]`` of the flat faces a part can rest on (no vertex beyond
    their plane), largest first."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    tolerance = support_rtol * max(float(mesh.scale), 1.0)
    areas, normals, points = _flat_faces(mesh)
    out = []
    for index in np.argsort(-areas, kind="stable"):
        if np.max((vertices - points[index]) @ normals[index]) <= tolerance:
            out.append((float(areas[index]), normals[index] / np.linalg.norm(normals[index])))
    return out


def printing_pose(mesh, *, support_rtol: float = SUPPORT_RTOL,
                  area_rtol: float = FACE_AREA_RTOL, normal=None) -> np.ndarray:
    """4x4 rigid transform putting a part on a printer bed: largest flat face down, on z = 0.

    The face is the largest by area among the mesh's flat faces (coplanar adjacent
    triangles, trimesh's facets) that the part can rest on: its plane supports the
    part (no vertex beyond it). Its outward normal is turned onto -z (the smallest
    rotation; a face already down is kept, so is a gear's), then the part is moved
    so that its lowest point is at z = 0 and its bounding box is centred on x = y = 0.
    A part with no flat face to rest on stands on the largest face of its convex hull.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        A closed part, mm.
    normal : (3,) float, optional
        The outward normal of the face to rest on (one of :func:`resting_faces`) instead.

    Returns
    -------
    (4, 4) float
    """
    vertices = np.asarray(mesh.vertices, dtype=float)
    if normal is not None:
        return _posed(vertices, vertices, np.asarray(normal, dtype=float))
    if len(mesh.faces) == 0 or not np.isfinite(vertices).all():
        raise ValueError(f"a printing pose needs a finite mesh with faces, not {len(mesh.faces)} "
                         f"faces")
    # a linear function's maximum over the vertices is its maximum over their hull: the
    # support test needs no 3D hull (qhull is the slow part), only the fallback does
    extreme = vertices
    tolerance = support_rtol * max(float(mesh.scale), 1.0)
    areas, normals, points = _flat_faces(mesh)
    best = None
    for index in np.argsort(-areas, kind="stable"):
        if best is not None and areas[index] < areas[best] * (1.0 - area_rtol):
            break
        if np.max((extreme - points[index]) @ normals[index]) > tolerance:
            continue          # not a face the part can rest on (a cavity's, a recess's)
        if best is None or normals[index][2] < normals[best][2]:
            best = index      # among equal faces, the one facing down already
    if best is None:
        hull = mesh.convex_hull
        extreme = np.asarray(hull.vertices, dtype=float)
        hull_areas, hull_normals, _ = _flat_faces(hull)
        normal = hull_normals[int(np.argmax(hull_areas))]
    else:
        normal = normals[best]
    return _posed(vertices, extreme, normal)


def _posed(vertices, extreme, normal) -> np.ndarray:
    """The face of outward ``normal`` turned onto -z, the footprint squared, the part on z = 0
    and centred on x = y = 0."""
    transform = np.eye(4)
    transform[:3, :3] = _turn_onto(normal / np.linalg.norm(normal))
    transform[:3, :3] = _footprint_turn((extreme @ transform[:3, :3].T)[:, :2]) @ transform[:3, :3]
    turned = vertices @ transform[:3, :3].T
    low, high = turned.min(axis=0), turned.max(axis=0)
    transform[:3, 3] = [-(low[0] + high[0]) / 2, -(low[1] + high[1]) / 2, -low[2]]
    return transform


def fits_build_volume(extents, build_volume) -> bool:
    """Whether a box of ``extents`` (x, y, z) fits ``build_volume``, as is or turned 90 deg about z."""
    x, y, z = (float(v) for v in extents)
    bx, by, bz = (float(v) for v in build_volume)
    return z <= bz and ((x <= bx and y <= by) or (y <= bx and x <= by))


def enclosure_checks(assembly, housings: dict) -> list:
    """Whether every gear stays inside its housing's cavity at every pose, with the margin.

    A gear turns about a fixed axis of its housing, so over a revolution it sweeps
    the disc of its largest outline radius about that axis: the gear stays inside
    at every pose exactly when that disc lies in the cavity outline and the gear's
    faces lie between the cavity's floor and roof. Reports the smallest radial
    margin (mm; negative: the gear cuts into the wall) and the gear it belongs to.
    """
    import shapely

    results = []
    for housing_name, housing in housings.items():
        cavity = shapely.Polygon(housing.cavity_outline)
        z_low, z_high = housing.z_cavity_bottom, housing.z_cavity_bottom + housing.cavity_height
        # a closed housing is one part; a split one is "<name>-base" and "<name>-cover" on
        # the same body; a split one cut into segments "<name>-base-1", ... (one body too)
        body = next(p.body for p in assembly.parts
                    if p.name in (housing_name, f"{housing_name}-base", f"{housing_name}-base-1"))
        worst, worst_gear, axial_ok = np.inf, None, True
        for part in assembly.parts:
            if part.kind != "gear":
                continue
            bottom, top = part.mesh.bounds[:, 2]
            local = part.local(0.0)
            middle = 0.5 * (bottom + top) + local[2, 3]
            # a gear in this cavity: on the housing's body, or (the central shaft's and the
            # sleeve's gears in the frame, on carrier 1's body about its fixed axis O) coaxial
            # with the housing's origin and between its end walls
            if part.body != body and not (z_low <= middle <= z_high
                                          and np.allclose(local[:2, 3], 0.0, atol=1e-6)):
                continue
            if part.body == body and not (z_low - 1.0 <= middle <= z_high + 1.0):
                continue   # coaxial with this body, but turning in another housing's cavity
            reach = float(np.max(np.linalg.norm(part.outline, axis=1)))
            axial_ok &= bool(z_low <= bottom + local[2, 3] + 1e-9
                             and top + local[2, 3] <= z_high + 1e-9)
            axes = [local[:2, 3]]
            if any(b.endswith(":mirrored") for _, b, _ in part.instances):
                axes.append(-local[:2, 3])   # the same gear on the carrier's other side
            for axis in axes:
                point = shapely.Point(axis)
                distance = cavity.exterior.distance(point)
                margin = (distance if cavity.contains(point) else -distance) - reach
                if margin < worst:
                    worst, worst_gear = margin, part.name
        results.append({"housing": housing_name, "gears_enclosed": bool(worst >= 0 and axial_ok),
                        "smallest_margin_mm": float(worst) if worst_gear else None,
                        "nearest_gear": worst_gear, "axial_fit": bool(axial_ok)})
    return results


def _overlaps(outcome: SolidsOutcome, fits) -> dict:
    """The parts sharing material at the assembly pose (:func:`cadgen.solids.overlaps.overlap_check`),
    a joined pair allowed the process's designed interference (none where hubs slide on)."""
    from cadgen.solids.overlaps import overlap_check

    interference = max(0.0, -(fits.hub_offset or 0.0), -(fits.seat_offset or 0.0))
    return overlap_check(outcome.assembly, outcome.carrier_angle, segments=outcome.segments,
                         interference=interference)


def _alignment(outcome: SolidsOutcome, fits) -> list:
    """Each shaft whose two bearing seats are bored in one housing's base and cover: how far the
    seats can tilt against each other (the cover shifting on its dowels, each bore off its place
    by the process's position tolerance) against what a deep-groove ball bearing accepts."""
    from cadgen.machine.fixings import BEARING_MISALIGNMENT_ARCMIN, dowel_pins, seat_misalignment

    rows = []
    for name, housing in outcome.housings.items():
        if not getattr(housing, "dowels", ()):
            continue
        low, high = housing.flange_z
        clearance = dowel_pins(housing.bolt_size, high - low)["clearance_max_mm"]
        floors = {(s.shaft, s.side, tuple(s.xy)): s for s in housing.seats if s.wall == "floor"}
        for seat in housing.seats:
            floor = floors.get((seat.shaft, seat.side, tuple(seat.xy)))
            if seat.wall != "roof" or floor is None:
                continue
            span = housing.cavity_height + (floor.depth + seat.depth) / 2
            angle = seat_misalignment(span, clearance, fits.position_tolerance)
            rows.append({"housing": name, "shaft": seat.shaft, "side": seat.side,
                         "span_mm": span, "dowel_clearance_mm": clearance,
                         "position_tolerance_mm": fits.position_tolerance,
                         "misalignment_arcmin": angle,
                         "allowance_arcmin": BEARING_MISALIGNMENT_ARCMIN,
                         "passed": angle <= BEARING_MISALIGNMENT_ARCMIN})
    return rows


def _bought_report(outcome: SolidsOutcome) -> dict:
    """The bought solids placed in the assembly file: how many, of each kind and designation
    (the bill's words; :func:`cadgen.solids.bought.placed_designations`)."""
    from collections import Counter

    from cadgen.solids.bought import placed_designations

    bought = list(getattr(outcome.assembly, "bought", ()))
    kinds = Counter()
    for part in bought:
        kinds[part.kind] += len(part.instances)
    return {"placed": int(sum(kinds.values())), "kinds": dict(sorted(kinds.items())),
            "designations": dict(sorted(placed_designations(outcome.assembly).items()))}


def solids_report(outcome: SolidsOutcome) -> dict:
    """Mass properties per part, the enclosure checks and the assembly's pose (report.json);
    computed once per outcome (a copy each call)."""
    import copy

    return copy.deepcopy(outcome.once("report", lambda: _solids_report(outcome)))


def _solids_report(outcome: SolidsOutcome) -> dict:
    from cadgen.machine.fits import process_fits
    from cadgen.solids.mass import mass_properties
    from cadgen.solids.printing import SUPPORT_FREE_MM2

    parts = []
    too_big = []
    total = 0.0
    materials = process_fits(outcome.process, outcome.gear_material)
    for part in outcome.assembly.parts:
        instances = part.instances or ((part.name, part.body, 0.0),)
        if part.kind in _NOT_MADE:
            continue
        material = materials.material(part.kind)
        density = outcome.density if outcome.density is not None else material.density
        props = mass_properties(part.mesh, density)
        total += props["mass_kg"] * len(instances)
        extents = [float(v) for v in np.ptp(outcome.printing_mesh(part).vertices, axis=0)]
        printed = material.process == "printed"
        # only a printed part meets the printer's bed; a machined one is not checked
        fits = fits_build_volume(extents, outcome.build_volume) if printed else None
        if printed and not fits:
            too_big.append({"part": part.name, "kind": part.kind, "print_extents_mm": extents})
        overhang = outcome.overhang(part) if printed else None
        parts.append({
            "part": part.name, "kind": part.kind, "instances": len(instances),
            "overhang_mm2": overhang,
            "supports_needed": None if overhang is None else overhang > SUPPORT_FREE_MM2,
            "file": f"solids/{part.name}.stl", "triangles": int(len(part.mesh.faces)),
            "volume_mm3": props["volume_mm3"], "area_mm2": props["area_mm2"],
            "material": material.name, "process": material.process, "density_kg_m3": density,
            "mass_kg": props["mass_kg"], "centre_of_mass_mm": props["centre_of_mass_mm"].tolist(),
            "inertia_kg_mm2": props["inertia_kg_mm2"].tolist(),
            "watertight": bool(part.mesh.is_watertight),
            "winding_consistent": bool(part.mesh.is_winding_consistent),
            "print_extents_mm": extents, "fits_build_volume": fits,
        })
    return {"density_kg_m3": outcome.density, "process": outcome.process,
            "parts": parts, "total_mass_kg": total, "bought": _bought_report(outcome),
            "assembly": {"file": f"solids/assembly.{outcome.file_type}",
                         "carrier_angle_deg": float(np.degrees(outcome.carrier_angle)),
                         "units": "m" if outcome.file_type == "glb" else "mm"},
            "enclosure": outcome.enclosure,
            "overlaps": _overlaps(outcome, materials),
            "alignment": _alignment(outcome, materials),
            "build_volume_mm": [float(v) for v in outcome.build_volume],
            "too_big_for_build_volume": too_big,
            "frames": "each STL in its printing pose: largest flat face down on z = 0, centred "
                      "on x = y = 0 (mm); the assembly places every instance from its part's "
                      "own frame (GLB in metres, 3MF in millimetres)"}
