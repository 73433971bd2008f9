"""A generic solids toolkit: validated outlines, extrusions, closed housings, mass properties.

Modules
-------
outline
    Outline validation (finite, enough points, no repeats, area, simple) and the
    shapes housings are made of: :func:`circle`, :func:`hull_of_circles`,
    :func:`offset_outline`, :func:`segments_for`. numpy, scipy and shapely only.
extrude
    The manifold3d/trimesh adapter: :func:`extrude` (validates first),
    :func:`to_trimesh` (refuses empty, open, mis-wound, inside-out meshes),
    :func:`from_trimesh`.
shell
    :func:`closed_shell`, a hollow housing round gears' swept discs, and
    :func:`encloses`, the check that a part lies inside its cavity.
split_housing
    :func:`~cadgen.solids.split_housing.split_housing`: a housing as a base and a cover
    parted between gear layers, with bearing seats, shaft holes and a bolted flange;
    :func:`~cadgen.solids.split_housing.shaft_solid`.
segments
    A printed housing too long for the printer's bed, cut between its seats into segments
    joined by bolted splice lugs.
machine_parts
    The drivetrain's records (:mod:`cadgen.machine`) as assembly parts: housings, shafts.
fixing_features
    The holes and bosses the fixings need: tapped holes, passages, the cam's screw holes,
    a keyed hub's boss and bore.
bought, bought_makers, bought_places
    The bought items as solids: :func:`~cadgen.solids.bought.register_maker` (a maker per
    kind, from its catalogue dimensions), :class:`~cadgen.solids.bought.BoughtItem` (one
    item where it sits in the part that holds it, ``Part.bought``),
    :func:`~cadgen.solids.bought.bought_parts` (placed with every copy of that part); the
    catalogue kinds' shapes; the placements read from the records that cut their seats.
overlaps, contact
    :func:`~cadgen.solids.overlaps.overlap_check`: the parts sharing material at the
    assembly pose, a joint's fit told from a collision by the overlap's thickness; the
    bought solids' contacts screened first with FCL.
mass
    :func:`mass_properties`: volume, area, mass, centre of mass, inertia (mm, kg).
housings, ground, parts, planting, pricking, outcome
    The mechanisms' parts built with the toolkit, and what a build's solids came to.

Writing the meshes (STL, GLB, 3MF) is :mod:`cadgen.export.meshes`'s job.
errors
    :class:`SolidError` and friends (the project's :class:`~kinematics.errors.MechanismError` family).
tolerances
    The named tolerances and limits used above.

Nothing heavy is imported here: manifold3d, trimesh and shapely load on first use.
"""

from cadgen.solids.errors import ExportFormatError, SolidError, SolidInputError
from cadgen.solids.extrude import cross_section, extrude, from_trimesh, to_trimesh
from cadgen.solids.mass import mass_properties
from cadgen.solids.outline import (
    circle,
    holes_problems,
    hull_of_circles,
    offset_outline,
    outline_problems,
    segments_for,
    signed_area,
    validate_holes,
    validate_outline,
)
from cadgen.solids.shell import Housing, closed_shell, encloses, shell_outlines

__all__ = [
    "ExportFormatError",
    "Housing",
    "SolidError",
    "SolidInputError",
    "circle",
    "closed_shell",
    "cross_section",
    "encloses",
    "extrude",
    "from_trimesh",
    "holes_problems",
    "hull_of_circles",
    "mass_properties",
    "offset_outline",
    "outline_problems",
    "segments_for",
    "shell_outlines",
    "signed_area",
    "to_trimesh",
    "validate_holes",
    "validate_outline",
]
