"""Named tolerances and limits of the solids toolkit, in one place.

Each is a default; the functions that use one take it as a keyword argument so a
caller can trade accuracy for time (or strictness for leniency) explicitly.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "DEGENERATE_AREA_RTOL",
    "CONTAINMENT_MARGIN",
    "CROSS_SECTION_AREA_RTOL",
    "ENCLOSURE_VOLUME_ATOL",
    "MIN_WALL",
    "CHORD_TOLERANCE",
]

#: An outline whose area (or whose points' convex hull's area) is below this
#: fraction of its squared width is degenerate (all points on a line, or nearly
#: so): extruding it would give a sliver with no volume a machine could cut.
DEGENERATE_AREA_RTOL = 1e-12
#: Relative outward push of the vertices of circumscribed polygons. Mathematically
#: the polygon already contains its disc; the push makes that hold after rounding
#: too (a point of the circle at a tangency would otherwise land 1 ulp outside).
CONTAINMENT_MARGIN = 16 * float(np.finfo(float).eps)
#: manifold3d's 2-D engine (Clipper2) stores coordinates on a 1e-8 grid. A cross
#: section whose area differs from the validated outline's by more than this
#: fraction lost a piece (a snapped sliver, a dropped hole), which is an error.
CROSS_SECTION_AREA_RTOL = 1e-6
#: Volume (mm^3) of a part outside a housing's cavity below which the part counts
#: as enclosed: coplanar contact leaves zero-volume debris, not a real collision.
ENCLOSURE_VOLUME_ATOL = 1e-6
#: Thinnest housing wall (mm) accepted by default: the parameter files' rule
#: (``housing.wall``, ``wall_too_thin``), one value for both.
from cadgen.params.solids import MIN_WALL  # noqa: E402
#: Default largest distance (mm) between a polygon and the circle it stands for,
#: used by :func:`cadgen.solids.outline.segments_for`.
CHORD_TOLERANCE = 0.01
#: A split housing's flange width in bolt clearance-hole diameters (the hole on its mid-line,
#: one diameter of material either side); the kinematic envelope circles include it.
FLANGE_WIDTH_HOLES = 3.0
