"""Mass properties of the planting mechanism's moving bodies: from the solids, or estimated.

A dynamics body is every part that turns as one about one axis (:func:`body_of_part`): the
carrier 1 (gearbox 1's housing, the sleeve S, the transmission driven gear), the central
shaft (O, both suns, the drive's gear on it), the input shaft, and per side of carrier 1
(arm 1, arm 2): each of set II's idlers with its shaft, each of set I's idlers (free on that
shaft), gearbox 2 (its housing, the hollow shaft C and set II's planet, the cam), the central
gear (shaft C2, set I's planet), the intermediate gear (shaft D, gear D) and the planter
(shaft E, the planet gear E, the shell and the whole duckbill linkage: lumped, its motion
relative to the planter is the cam contact force's, see :mod:`cadgen.dynamics.planting`).

:func:`solid_mass_properties` integrates the placed solids (trimesh, :mod:`cadgen.solids.mass`)
at the carrier angle 0 and sums each body's parts (the bought ones at steel's density);
:func:`estimated_mass_properties` uses the parameters alone: every gear a disc of its pitch
curve times the face width, each housing a shell of its wall round its gears' envelope, the
planter a plate and a tube. Both return ``{body: BodyMass}`` with the centre in world mm at
carrier angle 0.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

__all__ = ["BodyMass", "body_of_part", "solid_mass_properties", "estimated_mass_properties",
           "STEEL_DENSITY"]

#: kg/m^3, bought items (bearings, keys, screws, rings, pins): steel.
STEEL_DENSITY = 7850.0

#: Part stems (a copy's suffix and a cut segment's number removed) -> body, per side.
_BODY_OF_STEM = (
    (r"(frame-.*|ground|sprocket.*)", None),
    (r"(shaft-input|spacer-input-\d+|input-gear-[12])", "input"),
    (r"(shaft-O|spacer-O-\d+|sun|sun-I|central-shaft-gear)", "central shaft"),
    (r"(gearbox1-.*|shaft-S|spacer-S-\d+|transmission-driven-gear)", "carrier"),
    (r"(shaft-A|spacer-A-\d+|idler-1)", "idler A"),
    (r"idler-1-I", "idler A-I"),
    (r"(shaft-B|spacer-B-\d+|idler-2)", "idler B"),
    (r"idler-2-I", "idler B-I"),
    (r"(shaft-C|spacer-C-\d+|train-1-planet|gearbox2-.*|cam)", "gearbox 2"),
    (r"(shaft-C2|spacer-C2-\d+|planet-I|central)", "central gear"),
    (r"(shaft-D|spacer-D-\d+|intermediate|gear-D)", "intermediate"),
    (r"(shaft-E|spacer-E-\d+|planet-gear-E|planter-shell|blade-.*|lever|push-rod|roller.*)",
     "planter"),
)
#: Bodies of which carrier 1 holds one per side (the others: one for the machine).
PER_SIDE = ("idler A", "idler A-I", "idler B", "idler B-I", "gearbox 2", "central gear",
            "intermediate", "planter")


@dataclass(frozen=True)
class BodyMass:
    """One body's mass (kg), centre of mass (world mm at carrier angle 0, (2,)), moment of
    inertia about its centre of mass along z (kg mm^2), and the parts summed."""

    mass: float
    centre: np.ndarray
    inertia: float
    parts: tuple = ()


def body_of_part(part_name: str, second_side: bool = False) -> str | None:
    """The dynamics body of one placed copy, ``"planter 2"`` (per side) or ``"carrier"``; None
    for what does not move (the frame, the soil). ``second_side``: the copy rides on arm 2 /
    side 2 of carrier 1 (its body ``carrier1:mirrored``, or its phase half a turn).

    Raises
    ------
    KeyError
        For a part no body is known for (a new part kind: give it a body here).
    """
    side = "2" if second_side else "1"
    stem = re.sub(r"-arm2$", "", part_name)
    for pattern, body in _BODY_OF_STEM:
        if re.fullmatch(pattern, stem) or re.fullmatch(pattern, re.sub(r"-\d+$", "", stem)):
            if body is None:
                return None
            return f"{body} {side}" if body in PER_SIDE else body
    raise KeyError(f"no dynamics body for the part {part_name!r}")


def _combine(items) -> BodyMass:
    """Sum ``(mass, centre (2,), inertia about own centre, name)`` by the parallel axis rule."""
    mass = sum(m for m, _, _, _ in items)
    centre = sum(m * np.asarray(c) for m, c, _, _ in items) / mass
    inertia = sum(i + m * float(np.sum((np.asarray(c) - centre) ** 2)) for m, c, i, _ in items)
    return BodyMass(float(mass), np.asarray(centre, dtype=float), float(inertia),
                    tuple(name for _, _, _, name in items))


def solid_mass_properties(outcome, body_of=body_of_part) -> tuple:
    """``({body: BodyMass}, skipped)`` of the built solids at carrier angle 0.

    Each made part's mass properties are integrated once in its own frame and moved to every
    copy's pose (the centre by the pose, the inertia tensor turned: ``R I R^T``); the bought
    solids ride with their host part's body. ``skipped``: ``[(part, reason)]`` of meshes that
    could not be integrated (never silently: the report lists them). ``body_of(part name,
    second side)``: the part's body (the pricking mechanism's:
    :func:`cadgen.dynamics.pricking_mass.pricking_body_of_part`).
    """
    from cadgen.machine.fits import FitError, process_fits
    from cadgen.solids.bought import BoughtPart
    from cadgen.solids.errors import SolidError
    from cadgen.solids.mass import mass_properties

    assembly = outcome.assembly
    fits = process_fits(outcome.process)
    own: dict = {}
    items: dict = {}
    skipped = []
    for part in list(assembly.parts) + list(assembly.bought):
        host = getattr(part, "host", "")
        for name, body_name, phase in part.instances or ((part.name, part.body, 0.0),):
            second = body_name.endswith(":mirrored") or abs(phase - math.pi) < 1e-9
            body = body_of(host or part.name, second)
            if body is None:
                continue
            # a bought item's mesh is one per catalogue size, shared by every item of that size
            key = ("bought", id(part.mesh)) if host else part.name
            if key not in own:
                try:
                    # a bought solid (hosted, or placed alone as the pricking sprocket)
                    density = STEEL_DENSITY if host or isinstance(part, BoughtPart) else (
                        outcome.density or fits.material(part.kind).density)
                    own[key] = mass_properties(part.mesh, density)
                except (SolidError, FitError) as error:
                    own[key] = None
                    skipped.append((part.name, str(error)))
            props = own[key]
            if props is None:
                continue
            pose = assembly.body_pose(body_name, phase) @ part.local(phase)
            rotation = pose[:3, :3]
            centre = rotation @ props["centre_of_mass_mm"] + pose[:3, 3]
            inertia = (rotation @ props["inertia_kg_mm2"] @ rotation.T)[2, 2]
            items.setdefault(body, []).append((props["mass_kg"], centre[:2], inertia, name))
    return {body: _combine(parts) for body, parts in items.items()}, skipped


# ------------------------------------------------------------------ estimated
def _disc(radius_mm: float, width_mm: float, density: float, centre) -> tuple:
    mass = density * 1e-9 * math.pi * radius_mm ** 2 * width_mm
    return mass, np.asarray(centre, dtype=float), 0.5 * mass * radius_mm ** 2


def _polar_plate(angle, radius, width_mm: float, density: float, centre, direction) -> tuple:
    """A gear blank bounded by the polar pitch curve ``radius(angle)`` (samples over one turn):
    area ``1/2 int rho^2``, first moment ``1/3 int rho^3 u``, polar moment ``1/4 int rho^4``;
    ``direction`` turns the curve's angle 0 into the world."""
    step = np.diff(np.append(angle, angle[0] + 2 * math.pi))
    areal = density * 1e-9 * width_mm
    mass = areal * 0.5 * float(np.sum(radius ** 2 * step))
    first = areal / 3.0 * np.array([np.sum(radius ** 3 * np.cos(angle + direction) * step),
                                    np.sum(radius ** 3 * np.sin(angle + direction) * step)])
    polar = areal * 0.25 * float(np.sum(radius ** 4 * step))
    offset = first / mass
    return mass, np.asarray(centre, dtype=float) + offset, polar - mass * float(offset @ offset)


def _shell(points, envelope_mm: float, height_mm: float, wall_mm: float, density: float):
    """A closed housing: a stadium of radius ``envelope`` round the segment ``points`` (2, 2)
    mm, its two faces and its side wall of ``wall`` thickness; inertia of the two faces as
    plates (the side wall's share taken the same way)."""
    p, q = (np.asarray(v, dtype=float) for v in points)
    length = float(np.linalg.norm(q - p))
    face = math.pi * envelope_mm ** 2 + 2 * envelope_mm * length
    side = (2 * math.pi * envelope_mm + 2 * length) * height_mm
    mass = density * 1e-9 * wall_mm * (2 * face + side)
    width, span = 2 * envelope_mm, length + 2 * envelope_mm
    return mass, 0.5 * (p + q), mass * (span ** 2 + width ** 2) / 12.0


def estimated_mass_properties(params, mechanism, drive=None) -> dict:
    """``{body: BodyMass}`` from the parameters alone (no solid): an estimate.

    Gears: discs of their pitch radius (the non-circular ones: plates bounded by their
    pitch curves) times the face width, at the gear material's density; housings: shells of
    the housing wall round a stadium over their gears' axes; the planter: its plate (L1 by
    a tenth of L1, the arm's thickness) and the duckbill a tube (L2 long, the pot's diameter
    plus the mouth's clearance, the shell's wall). Shafts, keys and bearings are left out.
    """
    from cadgen.gears.circular import planting_modules, train1_set_radii
    from cadgen.machine.fits import process_fits

    fits = process_fits(params.manufacturing.process)
    steel = params.solids.density_kg_m3 or fits.material("gear").density
    housing_density = params.solids.density_kg_m3 or fits.material("housing").density
    module = planting_modules(mechanism, params.pitch_curve.teeth, params.gears.circular_module)[1]
    width = params.gears.face_width or 6.0 * module
    wall = params.housing.wall or max(3.0, 1.5 * module)
    out = {}
    radii2, radii1 = train1_set_radii(mechanism, "II"), train1_set_radii(mechanism, "I")
    phi0 = np.zeros(1)
    shaft_items = [_disc(radii2[0], width, steel, (0, 0)), _disc(radii1[0], width, steel, (0, 0))]
    carrier_reach = mechanism.carrier_radii["C"]
    envelope1 = max(radii2[3], radii1[3], radii2[1], radii1[1]) + wall + 2.0
    carrier_items = [(*_shell(((0, 0), (0, 0)), carrier_reach + envelope1, 3 * width, wall,
                              housing_density)[:3], "gearbox 1 (shell)")]
    if drive is not None:
        shaft_items.append(_disc(drive.radii[1], width, steel, (0, 0)))
        carrier_items.append((*_disc(drive.radii[3], width, steel, (0, 0)), "driven gear"))
        out["input"] = _combine([(*_disc(drive.radii[0], width, steel, (0, 0)), "input gear 1"),
                                 (*_disc(drive.radii[2], width, steel, (0, 0)), "input gear 2")])
    out["central shaft"] = _combine([(*item, "sun") for item in shaft_items])
    out["carrier"] = _combine(carrier_items)
    a, r = mechanism.centre_distance, mechanism.r
    t = np.linspace(0.0, 2 * math.pi, 2048, endpoint=False)
    r1 = mechanism.pitch_curve.radius(t)
    for side, arm in (("1", 0), ("2", 1)):
        points = {name: mechanism.motion(phi0, name, arm).position[0]
                  for name in ("A", "B", "C", "D", "E", "P1", "N")}
        gamma = mechanism.phic + math.pi * arm
        for body, key, k in (("idler A", "II", 1), ("idler A-I", "I", 1),
                             ("idler B", "II", 2), ("idler B-I", "I", 2)):
            radius = train1_set_radii(mechanism, key)[k]
            out[f"{body} {side}"] = _combine([(*_disc(radius, width, steel,
                                                      points["AB"[k - 1]]), body)])
        envelope2 = max(a, 2 * r) / 2 + r + wall + 2.0
        out[f"gearbox 2 {side}"] = _combine([
            (*_shell((points["C"], points["E"]), envelope2, 2 * width, wall, housing_density),
             "gearbox 2 (shell)"),
            (*_disc(radii2[3], width, steel, points["C"]), "train-1 planet")])
        out[f"central gear {side}"] = _combine([
            (*_polar_plate(t, r1, width, steel, points["C"], mechanism.phic), "central"),
            (*_disc(radii1[3], width, steel, points["C"]), "planet I")])
        # the intermediate's own pitch curve: radius a - r1(t) at polar angle pi - F(t)
        # from the line D -> C, at the catching pose
        angle = math.pi - mechanism.intermediate_rotation(t + math.pi * arm) \
            + mechanism.intermediate_rotation(np.array([math.pi * arm]))[0]
        order = np.argsort(np.mod(angle, 2 * math.pi))
        out[f"intermediate {side}"] = _combine([
            (*_polar_plate(np.mod(angle, 2 * math.pi)[order], (a - r1)[order], width, steel,
                           points["D"], gamma), "intermediate"),
            (*_disc(r, width, steel, points["D"]), "gear D")])
        plate_width = 0.1 * mechanism.L1
        plate_mass = housing_density * 1e-9 * mechanism.L1 * plate_width \
            * params.planter.arm_thickness
        tube_diameter = params.cam.pot_diameter + 2 * params.cam.mouth_clearance
        tube_mass = housing_density * 1e-9 * math.pi * tube_diameter \
            * params.planter.shell_wall * mechanism.L2
        out[f"planter {side}"] = _combine([
            (*_disc(r, width, steel, points["E"]), "planet gear E"),
            (plate_mass, 0.5 * (points["E"] + points["P1"]), plate_mass * mechanism.L1 ** 2 / 12,
             "planter plate"),
            (tube_mass, 0.5 * (points["P1"] + points["N"]), tube_mass * mechanism.L2 ** 2 / 12,
             "duckbill tube")])
    return out
