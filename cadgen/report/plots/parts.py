"""Pictures of the parts: the assembled solids (front view at the assembly's pose), each
gear pair at the start position, and the clearances over the FCL sweep."""

from __future__ import annotations

import re

import numpy as np

from cadgen.report.plots.base import _figure, _fill, _legend_below, _png
from kinematics.planar import cross

__all__ = ["assembly_view", "pair_figure_jobs", "pair_figures", "pair_figure_data",
           "pair_figure_datas",
           "draw_pair_figure", "clearance_figure"]


_COLOURS = {"ground": "#b5895a", "housing": "#8fa3b8", "gear": "#d9a441", "cam": "#7a9e7e",
            "planter": "#6d7f99", "blade": "#4f5d73", "rocker": "#6d7f99", "needle": "#3b4657",
            "lever": "#2f6fa8", "push-rod": "#6e747c", "link": "#4d7fb0"}


def _silhouette(part, pose):
    """The part's outline in the world's xy plane: its footprint or its section for prisms when
    known, else its triangles' projections merged (shapely)."""
    import shapely

    known = part.footprint if getattr(part, "footprint", None) is not None else part.outline
    if known is not None:
        outline = np.asarray(known) @ pose[:2, :2].T + pose[:2, 3]
        return shapely.Polygon(outline)
    triangles = part.mesh.triangles @ pose[:3, :3].T + pose[:3, 3]
    flat = triangles[:, :, :2]
    area = cross(flat[:, 1] - flat[:, 0], flat[:, 2] - flat[:, 0])
    # a ray through a closed, consistently wound surface enters through one face and leaves
    # through one facing the other way, so the faces of one winding cover the silhouette: half
    # the triangles to merge (the union is the costly part)
    closed = part.mesh.is_watertight and part.mesh.is_winding_consistent
    keep = area > 1e-9 if closed else np.abs(area) > 1e-9
    if not closed:
        return shapely.union_all(shapely.polygons(flat[keep]))
    return _union_by_plane(triangles[keep])


def _union_by_plane(triangles):
    """The union of the xy projections of front-facing ``triangles`` ``(n, 3, 3)`` of a closed,
    consistently wound mesh.

    The triangles of one plane of the mesh tile a face without overlapping, so each plane's are
    merged as a coverage (edges dissolved, no overlay: a shaft's end caps in a fifth of the
    time), and only the planes' faces are overlaid. A plane whose merge does not keep its
    triangles' area (a T-junction, say) is overlaid triangle by triangle as before.
    """
    import shapely

    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    offset = np.einsum("ij,ij->i", normal, triangles[:, 0])
    plane = np.round(np.column_stack([normal * 1e6, offset * 1e3])).astype(np.int64)
    _, group = np.unique(plane, axis=0, return_inverse=True)
    group = group.ravel()
    polygons = shapely.polygons(triangles[:, :, :2])
    if group.max() + 1 > len(triangles) // 2:      # curved: few triangles share a plane
        return shapely.union_all(polygons)
    areas = shapely.area(polygons)
    faces = []
    for index in range(group.max() + 1):
        members = polygons[group == index]
        face = None
        if len(members) > 1:
            try:
                face = shapely.coverage_union_all(members)
            except shapely.errors.GEOSException:
                face = None
            expected = float(areas[group == index].sum())
            if face is not None and not (face.is_valid and abs(face.area - expected)
                                         <= 1e-9 * expected):
                face = None
        faces.append(face if face is not None else shapely.union_all(members))
    return shapely.union_all(faces)


def assembly_view(assembly, angle: float, *, title: str, paths=(), soil_level=None) -> bytes:
    """Front view of every placed part at carrier angle ``angle`` (rad), drawn from the back
    layer to the front one, with optional reference paths ``[(xy (n, 2), label)]``."""
    import shapely

    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_rgba

    figure, ax = _figure(7.0, 9.0)
    placed = []
    for name, part, pose in assembly.placements(angle):
        depth = float((part.mesh.bounds[1, 2] + pose[2, 3]) if part.kind != "ground" else -np.inf)
        placed.append((depth, name, part, pose))
    # every outline in one collection, back to front (a collection draws in its order), each
    # hole filled white after its part: one artist instead of a hundred
    outlines, faces, edges = [], [], []
    black, white = to_rgba("k", 0.95), to_rgba("white")
    for _, _, part, pose in sorted(placed, key=lambda item: item[0]):
        shape = _silhouette(part, pose)
        face = to_rgba(_COLOURS.get(part.kind, "0.6"), 0.95)
        for polygon in getattr(shape, "geoms", [shape]):
            if polygon.is_empty or not isinstance(polygon, shapely.Polygon):
                continue
            outlines.append(np.asarray(polygon.exterior.coords))
            faces.append(face)
            edges.append(black)
            for ring in polygon.interiors:
                outlines.append(np.asarray(ring.coords))
                faces.append(white)
                edges.append(to_rgba("k"))
    if outlines:
        ax.add_collection(PolyCollection(outlines, facecolors=faces, edgecolors=edges,
                                         linewidths=0.3), autolim=False)
        ax.update_datalim(np.vstack(outlines))
        ax.autoscale_view()
    for xy, label in paths:
        ax.plot(xy[:, 0], xy[:, 1], "k--", lw=0.8, label=label)
    if soil_level is not None:
        ax.axhline(soil_level, color="saddlebrown", lw=1.0, label="soil surface")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm, forward travel)")
    ax.set_ylabel("y (mm)")
    ax.set_title(title, fontsize=9)
    if paths or soil_level is not None:
        _legend_below(figure, ncols=2)
    ax.grid(alpha=0.2)
    # (the layout gives the figure the drawing's proportions, at most 9 in high)
    return _png(figure)

# ----------------------------------------------------------------------------------------------
# Gear pairs at the start position

def pair_figure_jobs(train) -> dict:
    """``{file name: callable -> PNG bytes}``: a picture of each pair at the start position."""
    return {name: (lambda stage=stage: _pair_figure(stage)) for name, stage in _pairs(train)}


def pair_figure_datas(train) -> dict:
    """``{file name: pair_figure_data(stage)}`` of each pair, as :func:`pair_figure_jobs`."""
    return {name: pair_figure_data(stage) for name, stage in _pairs(train)}


def _pairs(train):
    for index, stage in enumerate(train.stages):
        slug = re.sub(r"[^a-z0-9]+", "-", stage.name.lower()).strip("-")
        yield f"gears-{index + 1}-{slug}.png", stage


def pair_figures(train) -> dict:
    """A picture of each pair at the start position (PNG bytes, keyed by file name)."""
    return {name: draw() for name, draw in pair_figure_jobs(train).items()}


def _pair_figure(stage) -> bytes:
    return draw_pair_figure(pair_figure_data(stage))


def pair_figure_data(stage) -> dict:
    """What a pair's picture shows, as plain arrays and strings (it can be sent to another
    process): each gear's outline and pitch curve placed at the start position, its label,
    and the title."""
    pair = stage.generated.pair
    rotations = pair.rotations(np.array([0.0]))
    gears = []
    for k, (profile, check) in enumerate(zip(stage.generated.profiles, stage.generated.checks)):
        outline, pitch = profile.placed(rotations[k][0], (pair.centre_distance * k, 0.0))
        gears.append((np.asarray(outline), np.asarray(pitch),
                      f"{profile.name} ({profile.teeth} teeth, {check.cutter})"))
    m = stage.meshing
    title = (f"{stage.name}: module {stage.generated.system.module:.3f} mm; "
             f"{m.interference_poses} interfering poses of {m.poses}, "
             f"TE {m.transmission_error_pp_deg:.1e} deg")
    return {"gears": gears, "title": title}


def draw_pair_figure(data: dict) -> bytes:
    """The picture of :func:`pair_figure_data`'s pair (PNG bytes)."""
    figure, ax = _figure(8.0, 5.0)
    for outline, pitch, label in data["gears"]:
        _fill(ax, outline[:, 0], outline[:, 1], alpha=0.45, label=label)
        ax.plot(pitch[:, 0], pitch[:, 1], "k:", lw=0.6)
    ax.set_title(data["title"], fontsize=9)
    ax.plot([], [], "k:", lw=0.6, label="pitch curves")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm, along the centre line)")
    ax.set_ylabel("y (mm)")
    _legend_below(figure, ncols=3)
    ax.grid(alpha=0.2)
    return _png(figure)

# ----------------------------------------------------------------------------------------------
# Clearances over the sweep

def clearance_figure(sweeps: dict, *, angle_label: str = "carrier angle (deg, 0 = catching)"
                     ) -> bytes:
    """Minimum distance between the solids vs carrier angle, per sweep, the minimum and target
    marked, interference ranges shaded.

    ``angle_label`` names the angle's origin (the planting mechanism counts from the catching
    position, the pricking one from the outer dead centre). A sweep that covers half a turn
    (the two planting arms swap every half turn, so their distance repeats) is drawn over the
    second half too, dashed, so that its end at 180 deg reads as the start again.
    """
    figure, ax = _figure(8.0, 5.0)
    colours = {"arm_interference": "tab:blue", "ground_clearance": "tab:brown"}
    for key, sweep in sweeps.items():
        samples = sweep["samples"]
        colour = colours.get(key, "k")
        angles = np.asarray(samples["carrier_angle_deg"], dtype=float)
        distances = np.asarray(samples["distance_mm"], dtype=float)
        ax.plot(angles, distances, color=colour, label=sweep["label"])
        span = angles[-1] - angles[0] if len(angles) else 360.0
        if 0.0 < span <= 180.0 + 1e-6:
            ax.plot(angles + span, distances, color=colour, ls="--", lw=0.9, alpha=0.7,
                    label=f"{sweep['label']}: repeats every {span:g} deg (the arms swap)")
        ax.axhline(sweep["target_mm"], color=colour, ls=":", lw=1.0,
                   label=f"target > {sweep['target_mm']:g} mm ({sweep['label']})")
        angle = sweep["carrier_angle_deg"]
        ax.plot([angle], [sweep["minimum_mm"]], "o", color=colour,
                label=f"certified minimum {sweep['minimum_mm']:.2f} mm at {angle:.2f} deg")
        # the number beside its point, on the side with room (inside the axes)
        right = angle < 300
        ax.annotate(f"{sweep['minimum_mm']:.2f} mm", (angle, sweep["minimum_mm"]),
                    textcoords="offset points", xytext=(6 if right else -6, -12),
                    ha="left" if right else "right", fontsize=8, color=colour,
                    bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                          "alpha": 0.8})
        for start, end in sweep.get("interference_ranges_deg") or []:
            ax.axvspan(start, end, color="red", alpha=0.2)
    ax.set_xlim(0, 360)
    ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
    ax.set_xlabel(angle_label)
    ax.set_ylabel("minimum distance between the solids (mm)")
    ax.set_title("Clearances of the solids over a revolution (FCL, certified minimum marked)",
                 fontsize=9)
    ax.grid(alpha=0.3)
    _legend_below(figure, ncols=2, fontsize=7)
    return _png(figure)
