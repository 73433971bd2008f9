"""Closed gearbox housings, and the check that a part lies inside one.

A housing encloses a set of gears: each gear sweeps a disc (its largest tip radius
about its axis), the cavity is the convex hull of those discs grown by a
clearance, and the wall surrounds the cavity on every side, top and bottom
included. The result is one watertight solid with an inner void.

Both outlines come from :func:`cadgen.solids.outline.hull_of_circles` on one
angular grid, so the cavity contains every grown disc exactly and the outer
outline is the cavity offset by the wall times a circumscribed polygon: the wall
is nowhere thinner than asked (see that function's notes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cadgen.solids.errors import SolidInputError
from cadgen.solids.extrude import extrude
from cadgen.solids.outline import hull_of_circles, signed_area
from cadgen.solids.tolerances import ENCLOSURE_VOLUME_ATOL, MIN_WALL
from kinematics.errors import DesignError, Problem

__all__ = ["Housing", "closed_shell", "shell_outlines", "encloses"]


@dataclass(frozen=True)
class Housing:
    """A closed housing and the pieces needed to test what it encloses.

    Attributes
    ----------
    solid : manifold3d.Manifold
        The housing material: outer prism minus the cavity (a hollow, closed solid).
    outer : manifold3d.Manifold
        The outer prism, void filled: everything the housing occupies or encloses.
    cavity : manifold3d.Manifold
        The void.
    cavity_outline, outer_outline : (n, 2) float
        Counter-clockwise outlines in mm.
    z_cavity_bottom, cavity_height, wall : float
        mm; the outer prism spans ``z_cavity_bottom - wall`` to
        ``z_cavity_bottom + cavity_height + wall``.
    """

    solid: object
    outer: object
    cavity: object
    cavity_outline: np.ndarray
    outer_outline: np.ndarray
    z_cavity_bottom: float
    cavity_height: float
    wall: float

    @property
    def volume(self) -> float:
        """Closed-form material volume (mm^3) from the two outlines' areas."""
        return (signed_area(self.outer_outline) * (self.cavity_height + 2.0 * self.wall)
                - signed_area(self.cavity_outline) * self.cavity_height)


def _shell_problems(circles, height, clearance, wall, min_wall, z_cavity_bottom, path):
    problems = []

    def finite(name, value):
        if not math.isfinite(value):
            problems.append(Problem(f"{path}.{name}", "not_finite", f"{name} must be finite, not {value!r}"))
            return False
        return True

    if finite("wall", wall):
        if wall <= 0.0 or wall < min_wall:
            problems.append(Problem(f"{path}.wall", "wall_too_thin",
                                    f"the wall is {wall:g} mm thick; the minimum is {min_wall:g} mm"))
    if finite("clearance", clearance) and clearance < 0.0:
        problems.append(Problem(f"{path}.clearance", "clearance_negative",
                                f"the clearance round the gears is {clearance:g} mm; it must be >= 0"))
    if finite("height", height) and height <= 0.0:
        problems.append(Problem(f"{path}.height", "height_not_positive",
                                f"the cavity height is {height:g} mm; it must be > 0"))
    finite("z_cavity_bottom", z_cavity_bottom)

    if circles.ndim != 2 or circles.shape[1] != 3 or len(circles) == 0:
        problems.append(Problem(f"{path}.circles", "not_circles",
                                f"expected (k, 3) rows (cx, cy, r) in mm with k >= 1, not shape {circles.shape}"))
        return problems
    for index in np.flatnonzero(~np.isfinite(circles).all(axis=1)):
        problems.append(Problem(f"{path}.circles[{index}]", "not_finite",
                                f"circle {index} is {circles[index].tolist()}: not finite"))
    for index in np.flatnonzero(np.isfinite(circles[:, 2]) & (circles[:, 2] <= 0.0)):
        problems.append(Problem(f"{path}.circles[{index}]", "radius_not_positive",
                                f"circle {index} has radius {circles[index, 2]:g} mm; it must be > 0"))
    return problems


def shell_outlines(circles, *, clearance: float, wall: float, segments: int) -> tuple[np.ndarray, np.ndarray]:
    """The cavity and outer outlines of a housing round some discs (unchecked arguments).

    Parameters
    ----------
    circles : (k, 3) array_like
        ``(cx, cy, r)`` rows, mm.
    clearance, wall : float
        mm.
    segments : int
        Sides per full circle of the circumscribed polygons.

    Returns
    -------
    cavity, outer : (n, 2) float
        Counter-clockwise; the cavity contains every disc grown by ``clearance``,
        the outer outline contains the cavity grown by ``wall``.
    """
    circles = np.asarray(circles, dtype=float).reshape(-1, 3)
    grow = np.array([0.0, 0.0, 1.0])
    cavity = hull_of_circles(circles + clearance * grow, segments)
    outer = hull_of_circles(circles + (clearance + wall) * grow, segments)
    return cavity, outer


def closed_shell(circles, *, height: float, clearance: float, wall: float, segments: int,
                 path: str = "housing", z_cavity_bottom: float = 0.0, min_wall: float = MIN_WALL) -> Housing:
    """A closed housing round the swept discs of some gears.

    Parameters
    ----------
    circles : (k, 3) array_like
        One row ``(cx, cy, r)`` per gear axis: the disc the gear sweeps (largest
        tip radius), mm, in the housing's frame.
    height : float
        Cavity height (mm), e.g. the face width plus axial play.
    clearance : float
        Gap (mm) between the swept discs and the cavity side, >= 0.
    wall : float
        Wall thickness (mm), on the sides, top and bottom; >= ``min_wall``.
    segments : int
        Sides per full circle of the circumscribed polygons (>= 3).
    path : str
        Field-path prefix of the problems (``path + ".wall"``, ...).
    z_cavity_bottom : float
        Height (mm) of the cavity floor.
    min_wall : float
        Thinnest wall accepted (mm), :data:`cadgen.solids.tolerances.MIN_WALL` by default.

    Returns
    -------
    Housing
        ``.solid`` is the housing (outer prism of height ``height + 2 wall`` from
        ``z_cavity_bottom - wall``, minus the cavity prism of height ``height`` from
        ``z_cavity_bottom``).

    Raises
    ------
    DesignError
        Every problem: ``wall_too_thin`` (at ``path.wall``; wall <= 0 or < min_wall),
        ``clearance_negative``, ``height_not_positive``, ``radius_not_positive``,
        ``not_finite``, ``not_circles``.
    SolidInputError
        For ``segments`` < 3.
    """
    circles = np.asarray(circles, dtype=float)
    if circles.ndim == 1 and circles.size == 3:
        circles = circles[None, :]
    height, clearance, wall = float(height), float(clearance), float(wall)
    min_wall, z_cavity_bottom = float(min_wall), float(z_cavity_bottom)
    if isinstance(segments, bool) or int(segments) != segments or segments < 3:
        raise SolidInputError("segments", f"segments must be an integer >= 3, not {segments!r}")
    problems = _shell_problems(circles, height, clearance, wall, min_wall, z_cavity_bottom, path)
    if problems:
        raise DesignError(problems)

    cavity_outline, outer_outline = shell_outlines(circles, clearance=clearance, wall=wall, segments=segments)
    outer = extrude(outer_outline, height + 2.0 * wall, z0=z_cavity_bottom - wall,
                    path=f"{path}.height", outline_path=f"{path}.outer_outline")
    cavity = extrude(cavity_outline, height, z0=z_cavity_bottom,
                     path=f"{path}.height", outline_path=f"{path}.cavity_outline")
    return Housing(solid=outer - cavity, outer=outer, cavity=cavity,
                   cavity_outline=cavity_outline, outer_outline=outer_outline,
                   z_cavity_bottom=z_cavity_bottom, cavity_height=height, wall=wall)


def encloses(housing, part, *, volume_atol: float = ENCLOSURE_VOLUME_ATOL) -> tuple[bool, float]:
    """Whether a part lies inside a housing's cavity, and how much of it does not.

    The part must not stick out of the housing (``part - housing.outer`` empty)
    and must not cut into its material (``part ^ housing.solid`` empty). The two
    pieces are disjoint, so their volumes add up to the part's volume outside the
    cavity.

    Parameters
    ----------
    housing : Housing
        Or anything with manifold3d solids ``.outer`` and ``.solid``.
    part : manifold3d.Manifold
        In the housing's frame (place it with ``.transform`` / ``.translate`` first).
    volume_atol : float
        mm^3 outside the cavity still counted as enclosed: coplanar contact leaves
        zero-volume debris (:data:`cadgen.solids.tolerances.ENCLOSURE_VOLUME_ATOL`).

    Returns
    -------
    enclosed : bool
    outside_volume : float
        mm^3 of the part outside the cavity (0.0 when both pieces are empty).
    """
    sticking_out = part - housing.outer
    # manifold3d's Python operator for intersection is ^ (there is no &).
    cutting_in = part ^ housing.solid
    outside = sum(0.0 if piece.is_empty() else max(piece.volume(), 0.0) for piece in (sticking_out, cutting_in))
    return outside <= volume_atol, float(outside)
