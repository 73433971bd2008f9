"""Mass properties of the pricking mechanism's moving bodies: from the solids, or estimated.

The bodies (:mod:`cadgen.dynamics.pricking`): the gear case (its base and cover, or their
printed segments, and the sprocket bolted to its floor), the intermediate (both intermediate
gears, their shaft and its spacers) and the planet (the planet gear, its shaft and spacers,
the rocker and the needle with its set screw). The sun, its shaft and the frame bracket do
not move: they are the frame. :func:`pricking_body_of_part` names a placed part's body for
:func:`cadgen.dynamics.mass.solid_mass_properties` (which integrates the solids at the start
pose); :func:`estimated_pricking_masses` uses the parameters alone: each gear a plate bounded
by its pitch curve times its face width, the case a shell of its wall round a stadium over O
and B, the rocker a bar and the needle a rod. Shafts, keys and bearings are left out of the
estimate. Both return ``{body: BodyMass}`` with the centre in world mm at the start pose.
"""

from __future__ import annotations

import math
import re

import numpy as np

from cadgen.dynamics.mass import _combine, _polar_plate, _shell
from cadgen.dynamics.pricking import CASE, INTERMEDIATE, PLANET

__all__ = ["pricking_body_of_part", "estimated_pricking_masses"]

#: Part stems (a copy's or a segment's number removed) -> body; None: the frame.
_BODY_OF_STEM = (
    (r"(frame-.*|ground|shaft-sun|spacer-sun-\d+|sun)", None),
    (r"(gear-case-.*|case-sprocket|sprocket.*)", CASE),
    (r"(shaft-intermediate|spacer-intermediate-\d+|intermediate-[12])", INTERMEDIATE),
    (r"(shaft-planet|spacer-planet-\d+|planet|rocker|needle)", PLANET),
)


def pricking_body_of_part(part_name: str, second_side: bool = False) -> str | None:
    """The dynamics body of one placed pricking part, None for the frame's.

    Raises
    ------
    KeyError
        For a part no body is known for (a new part kind: give it a body here).
    """
    for pattern, body in _BODY_OF_STEM:
        if re.fullmatch(pattern, part_name) or re.fullmatch(pattern,
                                                            re.sub(r"-\d+$", "", part_name)):
            return body
    raise KeyError(f"no dynamics body for the pricking part {part_name!r}")


def _gear_plate(design, name: str, width: float, density: float, centre, world_start: float):
    """A gear blank bounded by its pitch curve over one cycle: its own polar angles ``psi``
    (one turn) and radii, turned so that the contact at the start pose (``tau = 0``) points
    along ``world_start``."""
    functions, _ = design.cycle_functions()
    tau = np.linspace(0.0, design.motion.period, 2048, endpoint=False)
    rho, _, psi, _ = functions[name](tau)
    angle = np.mod(psi, 2 * math.pi)
    order = np.argsort(angle)
    return _polar_plate(angle[order], np.asarray(rho)[order], width, density, centre,
                        world_start - float(psi[0]))


def estimated_pricking_masses(params, design) -> dict:
    """``{body: BodyMass}`` from the parameters alone (no solid): an estimate.

    Gears at the gear material's density and their stage's face width; the case a shell of
    the housing wall (sides as high as both gear layers and their clearances) round the
    gears' largest radius over O and B; the rocker a bar (l1 x width x thickness) and the
    needle a rod (l2, its diameter), at the rocker's and the needle's material.
    """
    from kinematics.pricking_field import needle_geometry

    from cadgen.machine.fits import design_fits

    fits = design_fits(params)
    override = params.solids.density_kg_m3
    gear_density = override or fits.material("gear").density
    housing_density = override or fits.material("housing").density
    rocker_density = override or fits.material("rocker").density
    needle_density = override or fits.material("needle").density
    link, motion = design.linkage, design.motion
    centre = np.asarray(link.centre, dtype=float)
    start = motion.phi1_start
    line = np.array([math.cos(start), math.sin(start)])
    axis_a, axis_b = centre + link.a * line, centre + 2 * link.a * line
    faces = [params.gears.face_width_for(m) for m in design.modules]
    module = max(design.modules)
    wall = params.housing.wall_for(module)
    clearance = params.housing.clearance_for(module)
    reach = max(float(np.max(functions[0])) for functions in
                (design.cycle_functions()[0][n](np.linspace(0.0, motion.period, 512))
                 for n in ("sun", "intermediate 1", "intermediate 2", "planet")))
    envelope = reach + clearance + wall
    case = _shell((centre, axis_b), envelope, sum(faces) + 3 * clearance, wall, housing_density)
    out = {CASE: _combine([(*case, "gear case (shell)")])}
    out[INTERMEDIATE] = _combine([
        (*_gear_plate(design, "intermediate 1", faces[0], gear_density, axis_a, start + math.pi),
         "intermediate 1"),
        (*_gear_plate(design, "intermediate 2", faces[1], gear_density, axis_a, start),
         "intermediate 2")])
    needle = needle_geometry(design)
    phi2 = float(motion.phi2(motion.v_max))
    tip = axis_b + link.l * np.array([math.cos(phi2), math.sin(phi2)])
    axis = float(needle.axis_angle(phi2))
    root = tip - link.needle * np.array([math.cos(axis), math.sin(axis)])
    linkage = params.linkage
    bar = rocker_density * 1e-9 * link.rocker * linkage.rocker_width * linkage.rocker_thickness
    rod = needle_density * 1e-9 * math.pi * linkage.needle_diameter ** 2 / 4 * link.needle
    out[PLANET] = _combine([
        (*_gear_plate(design, "planet", faces[1], gear_density, axis_b, start + math.pi),
         "planet"),
        (bar, 0.5 * (axis_b + root), bar * (link.rocker ** 2 + linkage.rocker_width ** 2) / 12,
         "rocker"),
        (rod, 0.5 * (root + tip), rod * link.needle ** 2 / 12, "needle")])
    return out
