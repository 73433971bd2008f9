"""Adapter to manifold3d and trimesh: extruded outlines, and meshes that keep the invariants.

manifold3d builds solids (its booleans are robust); trimesh holds and exports them.
:func:`extrude` validates before it builds (manifold3d would keep one lobe of a
bowtie), and :func:`to_trimesh` refuses a mesh that is empty, open, inconsistently
wound or inside out, naming the part and the invariant.

manifold3d and trimesh are imported inside the functions, so importing this
module stays light.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.solids.errors import SolidError
from cadgen.solids.outline import holes_problems, outline_problems, signed_area
from cadgen.solids.tolerances import CROSS_SECTION_AREA_RTOL, DEGENERATE_AREA_RTOL
from kinematics.errors import DesignError, Problem

__all__ = ["extrude", "cross_section", "to_trimesh", "part_mesh", "from_trimesh",
           "manifold3d_engine"]

#: Whether :func:`manifold3d_engine` has started manifold3d's thread pool in this process.
_ENGINE_STARTED = []


def manifold3d_engine():
    """manifold3d, its thread pool started with this thread's one core (once per process):
    every use of manifold3d in cadgen goes through here.

    manifold3d runs its larger steps on oneTBB worker threads, as many as the CPUs the
    process may use when the pool starts (oneTBB reads the affinity mask then; manifold3d
    offers no other setting). Two reasons for one thread:

    - **Fork safety.** A build forks a worker beside the teeth (:mod:`cadgen.pipeline.beside`).
      A oneTBB worker thread that holds one of the library's locks at the instant of the fork
      leaves the lock held, forever, in the child, whose next boolean then waits on it (seen
      once in the test suite: a forked worker stuck in ``tbb::detail::r1::wait_on_address``
      under ``Manifold.status``). With no worker threads there is no such lock to inherit.
    - **CPU.** The build keeps both cores busy already (the worker beside runs the sweeps
      and draws), and the second thread cost more CPU than it saved: the booleans of
      xin2024-planter's parts took 0.28 s of CPU on two threads (0.15 s wall), 0.19 s on one.

    The mask is put back at once for everything else. The meshes are the same bits either way
    (manifold3d's results do not depend on its thread count). A caller that ran manifold3d's
    booleans in this process before cadgen did keeps the pool it started.
    """
    import manifold3d

    if not _ENGINE_STARTED:
        _ENGINE_STARTED.append(True)
        _start_on_one_core(manifold3d)
    return manifold3d


def _start_on_one_core(manifold3d) -> None:
    import os

    try:
        cpus = os.sched_getaffinity(0)
    except (AttributeError, OSError):      # not Linux: the pool as manifold3d starts it
        return
    if len(cpus) < 2:
        return
    try:
        os.sched_setaffinity(0, {min(cpus)})   # this thread only, until put back below
    except OSError:
        return
    try:
        manifold3d.Manifold.cube((1.0, 1.0, 1.0)).status()   # the pool starts here
    finally:
        os.sched_setaffinity(0, cpus)


def cross_section(outline, *, holes=(), path: str = "solid", holes_path: str | None = None,
                  area_rtol: float = DEGENERATE_AREA_RTOL,
                  cross_section_area_rtol: float = CROSS_SECTION_AREA_RTOL):
    """A manifold3d ``CrossSection`` of a validated outline with holes.

    Parameters
    ----------
    outline : (n, 2) array_like
        mm; checked, problems at ``path``.
    holes : sequence of (m_i, 2) array_like
        Checked, hole ``i``'s problems at ``f"{holes_path}[{i}]"``.
    path : str
    holes_path : str, optional
        Defaults to ``path + ".holes"``.
    area_rtol, cross_section_area_rtol : float
        See :mod:`cadgen.solids.tolerances`.

    Returns
    -------
    manifold3d.CrossSection

    Raises
    ------
    DesignError
        Every problem of the outline and the holes.
    SolidError
        If manifold3d's cross section lost area (see ``CROSS_SECTION_AREA_RTOL``).
    """
    cross, _, problems = _cross_section(outline, holes, path, holes_path, area_rtol, cross_section_area_rtol)
    if problems:
        raise DesignError(problems)
    return cross


#: Cross sections already validated and built, by content (:func:`_section_key`): a split
#: housing's slabs share their outlines and holes (the flange slabs above and below the
#: parting plane have the same section), and each would validate them again.
_SECTIONS: dict = {}
#: Sections kept (the oldest forgotten first): a build makes a few dozen distinct ones.
_SECTIONS_KEPT = 128


def _section_key(outline, holes, area_rtol, cross_section_area_rtol):
    """A key of the cross section's content (the points' bits), or None for input that is not
    plain numbers (validated, not remembered)."""
    try:
        arrays = [np.asarray(outline, dtype=np.float64)] + [np.asarray(h, dtype=np.float64)
                                                            for h in holes]
    except (TypeError, ValueError):
        return None
    return (float(area_rtol), float(cross_section_area_rtol),
            tuple((a.shape, np.ascontiguousarray(a).tobytes()) for a in arrays))


def _cross_section(outline, holes, path, holes_path, area_rtol, cross_section_area_rtol):
    """``(cross section, area, problems)``; a valid section is built once per content (the
    problems name paths and are found again each time)."""
    holes = list(holes)
    key = _section_key(outline, holes, area_rtol, cross_section_area_rtol)
    if key is not None and key in _SECTIONS:
        cross, expected = _SECTIONS[key]
        return cross, expected, []
    cross, expected, problems = _new_cross_section(outline, holes, path, holes_path, area_rtol,
                                                   cross_section_area_rtol)
    if key is not None and not problems:
        if len(_SECTIONS) >= _SECTIONS_KEPT:
            del _SECTIONS[next(iter(_SECTIONS))]
        _SECTIONS[key] = (cross, expected)
    return cross, expected, problems


def _new_cross_section(outline, holes, path, holes_path, area_rtol, cross_section_area_rtol):
    manifold3d = manifold3d_engine()

    outer, problems = outline_problems(outline, path, area_rtol=area_rtol)
    if outer is None:
        # The holes cannot be placed against a broken outline, but their own
        # problems are still worth reporting now.
        for index, hole in enumerate(holes):
            problems += outline_problems(hole, f"{holes_path or path + '.holes'}[{index}]", area_rtol=area_rtol)[1]
        return None, 0.0, problems
    checked, hole_found = holes_problems(outer, holes, holes_path or path + ".holes", area_rtol=area_rtol)
    if hole_found:
        return None, 0.0, hole_found

    # EvenOdd fills "inside an odd number of contours": with the holes checked
    # disjoint and strictly inside, that is the outline minus the holes whatever
    # the holes' orientation. (The default Positive rule would fill a
    # counter-clockwise hole.) Holes are reversed anyway, so Positive would agree.
    contours = [outer] + [hole[::-1] for hole in checked]
    cross = manifold3d.CrossSection([np.ascontiguousarray(c) for c in contours], manifold3d.FillRule.EvenOdd)
    expected = signed_area(outer) - sum(signed_area(hole) for hole in checked)
    if abs(cross.area() - expected) > cross_section_area_rtol * expected:
        raise SolidError(path, "area_preserved",
                         f"manifold3d's cross section has {cross.area():.9g} mm^2, the validated "
                         f"outline {expected:.9g} mm^2: a piece was lost (snapped to its 1e-8 grid?)")
    return cross, expected, []


def extrude(outline, height: float, *, holes=(), z0: float = 0.0, path: str = "solid",
            outline_path: str | None = None, holes_path: str | None = None,
            area_rtol: float = DEGENERATE_AREA_RTOL,
            cross_section_area_rtol: float = CROSS_SECTION_AREA_RTOL):
    """Prism of an outline (with holes) from ``z0`` to ``z0 + height`` along +z.

    Parameters
    ----------
    outline : (n, 2) array_like
        mm, either orientation; validated first.
    height : float
        mm, finite and > 0 (a gear's face width, a plate's thickness).
    holes : sequence of (m_i, 2) array_like
        Through holes; each strictly inside the outline, pairwise disjoint.
    z0 : float
        mm, the bottom face's height.
    path : str
        Field path of ``height`` (e.g. ``"solids.face_width"``), also used for the
        outline when ``outline_path`` is not given.
    outline_path : str, optional
        Field path of the outline's problems; defaults to ``path``.
    holes_path : str, optional
        Hole ``i``'s problems go to ``f"{holes_path}[{i}]"``; defaults to
        ``outline_path + ".holes"``.
    area_rtol, cross_section_area_rtol : float
        See :mod:`cadgen.solids.tolerances`.

    Returns
    -------
    manifold3d.Manifold

    Raises
    ------
    DesignError
        Every problem at once: the outline's and the holes' (see
        :func:`cadgen.solids.outline.validate_outline`, ``hole_outside_outline``,
        ``holes_overlap``), ``face_width_not_positive`` for the height, ``not_finite``
        for ``z0``.
    SolidError
        If manifold3d lost part of the cross section or returned an error status.
    """
    problems = []
    height = float(height)
    z0 = float(z0)
    if not (math.isfinite(height) and height > 0.0):
        problems.append(Problem(path, "face_width_not_positive",
                                f"an extrusion needs a finite height > 0 mm, not {height!r}"))
    if not math.isfinite(z0):
        problems.append(Problem(path, "not_finite", f"the extrusion's base height z0 must be finite, not {z0!r}"))
    outline_path = outline_path or path
    cross, _, found = _cross_section(outline, holes, outline_path, holes_path, area_rtol, cross_section_area_rtol)
    problems = found + problems
    if problems:
        raise DesignError(problems)
    solid = cross.extrude(height).translate((0.0, 0.0, z0))
    _check_status(solid, outline_path)
    return solid


def _check_status(solid, name: str) -> None:
    manifold3d = manifold3d_engine()

    status = solid.status()
    if status != manifold3d.Error.NoError:
        raise SolidError(name, "engine_status", f"manifold3d reports {status.name}")


def to_trimesh(manifold, name: str):
    """A ``trimesh.Trimesh`` of a manifold3d solid, checked to be a proper volume.

    Parameters
    ----------
    manifold : manifold3d.Manifold
    name : str
        The part's name, stored in ``mesh.metadata["name"]`` and used in errors.

    Returns
    -------
    trimesh.Trimesh
        float64 vertices (manifold3d's ``to_mesh`` would round them to float32),
        watertight, consistently wound, positive volume.

    Raises
    ------
    SolidError
        Invariant ``not_empty`` (e.g. a difference that removed everything: an
        empty mesh is not a part), ``engine_status``, ``watertight``,
        ``winding_consistent`` or ``positive_volume``.
    """
    _check_status(manifold, name)
    if manifold.is_empty():
        raise SolidError(name, "not_empty", "the solid has no triangles (a boolean removed everything?)")
    mesh = manifold.to_mesh64()
    vertices = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    faces = np.asarray(mesh.tri_verts, dtype=np.int64)
    merge_from = np.asarray(mesh.merge_from_vert, dtype=np.int64)
    if merge_from.size:
        # Vertices split only for their properties (normals, uv) are one position:
        # weld them, or trimesh sees open seams.
        target = np.arange(len(vertices))
        target[merge_from] = np.asarray(mesh.merge_to_vert, dtype=np.int64)
        faces = target[faces]
    result = part_mesh(vertices, faces, name)
    if merge_from.size:
        result.remove_unreferenced_vertices()
    _check_volume(result, name)
    return result


def part_mesh(vertices, faces, name: str):
    """The ``trimesh.Trimesh`` of a part's triangles as :func:`to_trimesh` makes it (no
    processing, the part's name in its metadata); unchecked."""
    import trimesh

    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False, metadata={"name": name})


def _check_volume(mesh, name: str) -> None:
    if not mesh.is_watertight:
        raise SolidError(name, "watertight", "some edges do not have exactly two faces")
    if not mesh.is_winding_consistent:
        raise SolidError(name, "winding_consistent", "neighbouring faces disagree on orientation")
    if not _enclosed_volume(mesh.vertices, mesh.faces) > 0:
        raise SolidError(name, "positive_volume", f"the volume is {mesh.volume!r} mm^3 (inside out?)")


def _enclosed_volume(vertices, faces) -> float:
    """mm^3 a closed, consistently wound mesh encloses (negative: inside out).

    The divergence theorem: the sum over the triangles of ``det(a, b, c) / 6``, the
    vertices taken about their bounding box's centre first (a part far from the origin
    would otherwise sum large terms that cancel). Only the sign is used here, on every
    part made: trimesh's ``volume`` integrates all ten mass moments for it, and the
    report's mass properties (:mod:`cadgen.solids.mass`) are integrated once, there.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    vertices = vertices - 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    a, b, c = (vertices[np.asarray(faces)[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->", a, np.cross(b, c))) / 6.0


def from_trimesh(mesh, name: str = "mesh"):
    """A manifold3d solid of a trimesh mesh, for booleans with meshes made elsewhere.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Watertight, consistently wound, positive volume.
    name : str
        For errors.

    Returns
    -------
    manifold3d.Manifold

    Raises
    ------
    SolidError
        If the mesh is not a proper volume, or manifold3d refuses it (its status).
    """
    manifold3d = manifold3d_engine()

    _check_volume(mesh, name)
    solid = manifold3d.Manifold(manifold3d.Mesh64(
        vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
        tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64)))
    _check_status(solid, name)
    if solid.is_empty():
        raise SolidError(name, "not_empty", "manifold3d made an empty solid of a non-empty mesh")
    return solid
