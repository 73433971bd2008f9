"""A picture of the assembled solids: the front view (the mechanism plane) at the assembly's pose."""

from __future__ import annotations

import numpy as np

from kinematics.planar import cross

from cadgen.report.plots.planting import _figure, _fill, _png

__all__ = ["assembly_view"]

_COLOURS = {"ground": "#b5895a", "housing": "#8fa3b8", "gear": "#d9a441", "cam": "#7a9e7e",
            "planter": "#6d7f99", "blade": "#4f5d73", "rocker": "#6d7f99", "needle": "#3b4657"}


def _silhouette(part, pose):
    """The part's outline in the world's xy plane: its section for prisms, else its triangles'
    projections merged (shapely)."""
    import shapely

    if part.outline is not None:
        outline = np.asarray(part.outline) @ pose[:2, :2].T + pose[:2, 3]
        return shapely.Polygon(outline)
    triangles = part.mesh.triangles @ pose[:3, :3].T + pose[:3, 3]
    flat = triangles[:, :, :2]
    area = np.abs(cross(flat[:, 1] - flat[:, 0], flat[:, 2] - flat[:, 0]))
    return shapely.union_all(shapely.polygons(flat[area > 1e-9]))


def assembly_view(assembly, angle: float, *, title: str, paths=(), soil_level=None) -> bytes:
    """Front view of every placed part at carrier angle ``angle`` (rad), drawn from the back
    layer to the front one, with optional reference paths ``[(xy (n, 2), label)]``."""
    import shapely

    figure, ax = _figure(7.0, 8.0)
    placed = []
    for name, part, pose in assembly.placements(angle):
        depth = float((part.mesh.bounds[1, 2] + pose[2, 3]) if part.kind != "ground" else -np.inf)
        placed.append((depth, name, part, pose))
    for depth, name, part, pose in sorted(placed, key=lambda item: item[0]):
        shape = _silhouette(part, pose)
        polygons = getattr(shape, "geoms", [shape])
        for polygon in polygons:
            if polygon.is_empty or not isinstance(polygon, shapely.Polygon):
                continue
            x, y = polygon.exterior.xy
            _fill(ax, x, y, color=_COLOURS.get(part.kind, "0.6"), ec="k", lw=0.3, alpha=0.95)
            for ring in polygon.interiors:
                _fill(ax, *ring.xy, color="white", ec="k", lw=0.3)
    for xy, label in paths:
        ax.plot(xy[:, 0], xy[:, 1], "k--", lw=0.8, label=label)
    if soil_level is not None:
        ax.axhline(soil_level, color="saddlebrown", lw=1.0, label="soil surface")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm, forward travel)")
    ax.set_ylabel("y (mm)")
    ax.set_title(title, fontsize=9)
    if paths or soil_level is not None:
        ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.2)
    return _png(figure)
