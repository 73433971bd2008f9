"""Tooth strength of a gear mesh over its poses: root bending (ISO 6336-3) and flank contact
(ISO 6336-2), each gear taken at every pose as the spur gear of its local pitch curvature.

Model (spur gears, vectorised over the poses of a mesh):

- **Equivalent gear.** At a pose each gear is the spur gear whose pitch circle has the radius
  of curvature ``R`` of its pitch curve at the contact (signed: a concave stretch is
  negative, the equivalent of an internal gear), equivalent tooth count ``z_v = 2 R / m``. A
  circular gear is its own equivalent (``z_v = z``).
- **Root bending**, ISO 6336-3 with the load at the tooth tip (the DIN 3990 / ISO 6336-3:1996
  "method C" form factors, whose formulas are method B's with the tip as the load point):
  ``sigma_F = Ft / (b m) Y_Fa Y_Sa Y_eps K_A K_V K_Fbeta K_Falpha``, ``Ft = Fn cos(alpha)``.
  ``Y_Fa`` and ``Y_Sa`` are computed from the basic rack (the cutter's addendum, tip radius,
  pressure angle) and the profile shift at ``z_v`` by ISO 6336-3's equations (30-degree
  tangent at the root fillet, ``theta`` by fixed-point iteration); an internal equivalent
  (concave stretch) by ISO 6336-3's internal-gear equations (the rack-like tooth with the
  fillet radius halved). ``Y_eps = 0.25 + 0.75 / eps_alpha`` (with the tip load). Validity:
  ``Y_Sa``'s formula holds for ``1 <= q_s < 8`` (ISO 6336-3); a pose outside it, a pointed
  equivalent tooth, a contact ratio below 1 or a form-factor iteration that does not settle
  is counted in ``invalid_poses`` with the reason, never silently used.
- **Contact**, Hertz at the pitch point (ISO 6336-2's ``sigma_H0``, written with the flank
  radii so that a non-circular and an internal pair need no other formula):
  ``sigma_H = Z_E Z_eps sqrt(Fn K_A K_V K_Hbeta K_Halpha / (b rho_red))``, ``1 / rho_red =
  1 / rho_1 + 1 / rho_2``, ``rho_i = R_i sin(alpha_w)`` (signed: an internal flank is
  concave), ``Z_E = sqrt(1 / (pi ((1 - nu1^2) / E1 + (1 - nu2^2) / E2)))``, ``Z_eps =
  sqrt((4 - eps_alpha) / 3)``. For a circular pair this is exactly ``Z_H Z_E Z_eps sqrt(Ft /
  (b d1) (u + 1) / u)`` with ISO's ``Z_H``.
- **Contact ratio** of the equivalent pair (ISO 21771), each gear's stretch of the path from
  the pitch point to its tip circle, capped at the mate's base tangent point (no contact
  beyond it: the flank there is undercut).
- **Safety**: ``S_F = sigma_FE Y_M / sigma_F`` (``Y_M = 0.7`` for an idler's reversed
  bending, ISO 6336-5), ``S_H = sigma_Hlim Z_L Z_V Z_R / sigma_H``; life, size, notch and
  roughness factors of the root are 1 (long life, modules below 5 mm, as ISO 6336-3's
  simplified method). Allowables: :mod:`cadgen.gears.gear_materials`.

The load factors are :class:`StrengthFactors` (their reasons there).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cadgen.gears.gear_materials import IDLER_BENDING_FACTOR, GearMaterial

__all__ = ["StrengthFactors", "RackProfile", "MeshGear", "MeshLoad", "MeshStrength",
           "form_factors", "contact_ratio", "elasticity_factor", "reduced_flank_radius",
           "mesh_strength", "STRESS_CORRECTION_VALIDITY", "RACK_INVERSE_TEETH"]

#: ISO 6336-3: the stress correction factor's formula holds for notch parameters ``q_s`` here.
STRESS_CORRECTION_VALIDITY = (1.0, 8.0)
#: ``1 / z_v`` below which an equivalent gear is taken as the rack (a straight stretch of a
#: pitch curve): the form factor is within 1e-5 of the rack's there.
RACK_INVERSE_TEETH = 1e-6
#: Fixed-point rounds of ISO 6336-3's ``theta`` equation, and the change that counts as settled.
_THETA_ROUNDS, _THETA_TOL = 60, 1e-12


@dataclass(frozen=True)
class StrengthFactors:
    """ISO 6336-1's load factors, the same for root and flank (dimensionless).

    - ``application`` ``K_A = 1``: the design load already carries ``machine.service_factor``
      (the shocks of stones and clods);
    - ``dynamic`` ``K_V = 1.05``: the pitch-line speeds are below 1 m/s (30-60 r/min), far
      below the mesh resonance, where ISO 6336-1's ``K_V = 1 + N K`` stays near 1; 1.05
      leaves room for the coarser teeth of laser-cut and printed gears;
    - ``face_load`` ``K_Hbeta = K_Fbeta = 1.15``: every gear sits between two bearings of its
      housing with a face no wider than its diameter (ISO 6336-1 method C's range for such
      mountings is about 1.1 to 1.3);
    - ``transverse_load`` ``K_Halpha = K_Falpha = 1``: spur gears of quality 8 or better under
      a load above 100 N/mm of face (ISO 6336-1 Table 9).
    """

    application: float = 1.0
    dynamic: float = 1.05
    face_load: float = 1.15
    transverse_load: float = 1.0

    @property
    def product(self) -> float:
        return self.application * self.dynamic * self.face_load * self.transverse_load

    def as_dict(self) -> dict:
        return {"K_A": self.application, "K_V": self.dynamic, "K_beta": self.face_load,
                "K_alpha": self.transverse_load}


@dataclass(frozen=True)
class RackProfile:
    """The basic rack the teeth are cut by: ``pressure_angle`` (rad) and the addendum,
    dedendum and tip radius coefficients (times the module)."""

    pressure_angle: float = np.radians(20.0)
    addendum: float = 1.0
    dedendum: float = 1.25
    tip_radius: float = 0.38


@dataclass(frozen=True)
class MeshGear:
    """One gear of a mesh.

    Attributes
    ----------
    name : str
    radius : (n,) float
        Signed radius of curvature (mm) of its pitch curve at the contact at each pose
        (negative: concave, an internal equivalent); a circular gear's working pitch radius.
    material : GearMaterial
    profile_shift : float
    teeth : int or None
        A circular gear's tooth count (its form factor's ``z``); None for a non-circular gear.
    tip_radius : float or None
        A circular gear's measured tip radius (mm); None: ``R + m (ha + x)``.
    reversed_bending : bool
        An idler: its teeth are bent both ways (``Y_M = 0.7``).
    """

    name: str
    radius: np.ndarray
    material: GearMaterial
    profile_shift: float = 0.0
    teeth: int | None = None
    tip_radius: float | None = None
    reversed_bending: bool = False


@dataclass(frozen=True)
class MeshLoad:
    """A mesh over its poses: its two gears, the tooth geometry and the normal force.

    ``pose`` (n,) is the mesh's cycle parameter (rad), ``period`` its cycle; ``normal_force``
    (n,) N along the line of action. ``working_pressure_angle`` (rad) differs from the rack's
    for a circular pair with shifts not summing to zero, and ``reference_radii`` are then its
    gears' reference pitch radii (``m z / 2``) where ``MeshGear.radius`` holds the working ones.
    """

    name: str
    gears: tuple
    module: float
    face_width: float
    rack: RackProfile
    pose: np.ndarray
    period: float
    normal_force: np.ndarray
    working_pressure_angle: float | None = None
    reference_radii: tuple | None = None
    load_source: str = "assumed static design load"


@dataclass(frozen=True)
class MeshStrength:
    """Stresses (MPa) and safety factors over a mesh's poses; per-gear arrays are ``(2, n)``."""

    name: str
    names: tuple
    pose: np.ndarray
    period: float
    normal_force: np.ndarray
    equivalent_teeth: np.ndarray
    contact_ratio: np.ndarray
    form_factor: np.ndarray
    stress_correction: np.ndarray
    root_stress: np.ndarray
    contact_stress: np.ndarray
    bending_safety: np.ndarray
    contact_safety: np.ndarray      # NaN where the material has no pitting endurance
    valid: np.ndarray               # (2, n) bool: every formula within its validity
    invalid_reasons: tuple = ()     # ((gear index, reason, count), ...)
    load_source: str = "assumed static design load"
    materials: tuple = field(default=(), repr=False)


# ------------------------------------------------------------------ ISO 6336-3 form factors
def _involute(angle):
    return np.tan(angle) - angle


def form_factors(equivalent_teeth, profile_shift, rack: RackProfile):
    """ISO 6336-3 tip-load form factor ``Y_Fa``, stress correction ``Y_Sa`` and notch
    parameter ``q_s`` of the spur gear of ``equivalent_teeth`` (negative: internal).

    Parameters
    ----------
    equivalent_teeth : (n,) float
        ``z_v``; ``inf`` (a straight stretch) is the rack.
    profile_shift : float or (n,) float
        ``x`` (external gears; ISO's internal equations have none).
    rack : RackProfile

    Returns
    -------
    (Y_Fa, Y_Sa, q_s, settled) : four (n,) arrays, ``settled`` False where the ``theta``
        iteration did not converge or the equivalent tooth is pointed.
    """
    z = np.atleast_1d(np.asarray(equivalent_teeth, dtype=float))
    x = np.broadcast_to(np.asarray(profile_shift, dtype=float), z.shape)
    alpha, rho_fp, h_fp = rack.pressure_angle, rack.tip_radius, rack.dedendum
    internal = z < 0.0
    # external: ISO 6336-3 eq. (the 30-degree tangent of the trochoidal fillet), in modules
    inverse = np.maximum(np.where(internal, 1.0, 1.0 / np.where(internal, 1.0, z)),
                         RACK_INVERSE_TEETH)
    e = np.pi / 4 - h_fp * np.tan(alpha) - (1 - np.sin(alpha)) * rho_fp / np.cos(alpha)
    g = rho_fp - h_fp + x
    h = 2 * inverse * (np.pi / 2 - e) - np.pi / 3
    theta = np.full(z.shape, np.pi / 6)
    for _ in range(_THETA_ROUNDS):
        theta_next = 2 * g * inverse * np.tan(theta) - h
        change = np.abs(theta_next - theta)
        theta = theta_next
    settled = change < _THETA_TOL
    # z sin(pi/3 - theta) written without z: pi/3 - theta = 2 (1/z) ((pi/2 - e) - g tan theta)
    gap = (np.pi / 2 - e) - g * np.tan(theta)
    delta = 2 * inverse * gap
    chord = 2 * gap * np.sinc(delta / np.pi)
    root_chord = chord + np.sqrt(3) * (g / np.cos(theta) - rho_fp)
    fillet = rho_fp + 2 * g**2 * inverse / (np.cos(theta) * (np.cos(theta) ** 2 - 2 * g * inverse))
    tip_pitch = 1 + 2 * (rack.addendum + x) * inverse     # d_an / d_n
    alpha_tip = np.arccos(np.clip(np.cos(alpha) / tip_pitch, -1.0, 1.0))
    half_tip = inverse * (np.pi / 2 + 2 * x * np.tan(alpha)) + _involute(alpha) \
        - _involute(alpha_tip)
    settled &= half_tip > 0.0                              # a pointed tip: no tooth to load
    alpha_load = alpha_tip - half_tip
    arm = 0.5 * ((np.cos(alpha) / np.cos(alpha_load) - np.cos(delta)) / inverse
                 + rho_fp - g / np.cos(theta))
    # internal: ISO 6336-3's rack-like internal tooth, fillet radius rho_fP / 2, load at alpha
    depth = rack.addendum + h_fp
    root_internal = 2 * (np.pi / 4 + np.tan(alpha) * (h_fp - rho_fp) + rho_fp / np.cos(alpha)
                         - rho_fp * np.cos(np.pi / 6))
    arm_internal = depth - (np.pi / 4 + (h_fp - depth) * np.tan(alpha)) * np.tan(alpha) \
        - rho_fp * (1 - np.sin(np.pi / 6))
    root_chord = np.where(internal, root_internal, root_chord)
    arm = np.where(internal, arm_internal, arm)
    fillet = np.where(internal, rho_fp / 2, fillet)
    alpha_load = np.where(internal, alpha, alpha_load)
    settled = np.where(internal, True, settled)
    form = 6 * arm * np.cos(alpha_load) / (root_chord**2 * np.cos(alpha))
    ratio = root_chord / arm
    notch = root_chord / (2 * fillet)
    correction = (1.2 + 0.13 * ratio) * notch ** (1 / (1.21 + 2.3 / ratio))
    return form, correction, notch, settled


# ------------------------------------------------------------------ pair geometry
def contact_ratio(radius_1, radius_2, module: float, rack: RackProfile, shifts=(0.0, 0.0),
                  working_pressure_angle: float | None = None, tip_radii=(None, None),
                  reference_radii=(None, None)):
    """Transverse contact ratio ``eps_alpha`` of the equivalent pair (ISO 21771), per pose.

    ``radius_i``: signed pitch radii (mm, negative internal); ``tip_radii``: measured tip
    radii (mm) or None for ``|R| +- m (ha + x)``. Each gear's stretch of the path of contact
    runs from the pitch point to its tip circle and stops at the mate's base tangent point.
    """
    alpha = rack.pressure_angle
    working = alpha if working_pressure_angle is None else working_pressure_angle
    radii = [np.asarray(r, dtype=float) for r in (radius_1, radius_2)]
    references = [r if ref is None else np.full(np.shape(r), float(ref)) * np.sign(r)
                  for r, ref in zip(radii, reference_radii)]
    base = [np.abs(ref) * np.cos(alpha) for ref in references]
    parts = []
    for k in (0, 1):
        r, x = references[k], shifts[k]
        tip = (np.abs(r) + np.sign(r) * module * (rack.addendum + x) if tip_radii[k] is None
               else np.full(np.shape(r), float(tip_radii[k])))
        along = np.sqrt(np.maximum(tip**2 - base[k] ** 2, 0.0))
        to_pitch = base[k] * np.tan(working)
        part = np.where(r > 0, along - to_pitch, to_pitch - along)
        parts.append(np.minimum(part, base[1 - k] * np.tan(working)))
    return (parts[0] + parts[1]) / (np.pi * module * np.cos(alpha))


def elasticity_factor(material_1: GearMaterial, material_2: GearMaterial) -> float:
    """``Z_E`` (sqrt(MPa)) of two materials: ``sqrt(1 / (pi sum (1 - nu^2) / E))``."""
    compliance = sum((1 - m.poisson_ratio**2) / m.youngs_modulus
                     for m in (material_1, material_2))
    return float(np.sqrt(1.0 / (np.pi * compliance)))


def reduced_flank_radius(radius_1, radius_2, working_pressure_angle: float):
    """``rho_red`` (mm) of the flanks at the pitch point, ``1 / (1 / rho_1 + 1 / rho_2)``,
    ``rho_i = R_i sin(alpha_w)`` signed (an internal flank concave); NaN where the flanks
    would not touch at a point (the concave one tighter than the convex)."""
    s = np.sin(working_pressure_angle)
    inverse = 1.0 / (np.asarray(radius_1, dtype=float) * s) \
        + 1.0 / (np.asarray(radius_2, dtype=float) * s)
    with np.errstate(divide="ignore"):
        return np.where(inverse > 0.0, 1.0 / np.where(inverse > 0.0, inverse, 1.0), np.nan)


# ------------------------------------------------------------------ a mesh
def mesh_strength(mesh: MeshLoad, factors: StrengthFactors = StrengthFactors()) -> MeshStrength:
    """Root and contact stresses and safety factors of both gears of ``mesh`` at its poses.

    Raises
    ------
    ValueError
        Arrays of different lengths, a force below zero, a module or face width not > 0.
    """
    force = np.atleast_1d(np.asarray(mesh.normal_force, dtype=float))
    pose = np.atleast_1d(np.asarray(mesh.pose, dtype=float))
    radii = [np.broadcast_to(np.asarray(g.radius, dtype=float), pose.shape) for g in mesh.gears]
    if force.shape != pose.shape:
        raise ValueError(f"mesh {mesh.name!r}: {force.shape[0]} forces for {pose.shape[0]} poses")
    if (force < 0).any() or not np.isfinite(force).all():
        raise ValueError(f"mesh {mesh.name!r}: normal forces must be finite and >= 0 N, "
                         f"got a least of {force.min():g}")
    if not (mesh.module > 0 and mesh.face_width > 0):
        raise ValueError(f"mesh {mesh.name!r}: module and face width must be > 0 mm, got "
                         f"{mesh.module!r} and {mesh.face_width!r}")
    rack = mesh.rack
    alpha = rack.pressure_angle
    working = alpha if mesh.working_pressure_angle is None else mesh.working_pressure_angle
    references = mesh.reference_radii or (None, None)
    teeth = []
    for gear, radius in zip(mesh.gears, radii):
        if gear.teeth is not None:
            teeth.append(np.full(pose.shape, float(gear.teeth)) * np.sign(radius))
        else:
            with np.errstate(divide="ignore"):
                teeth.append(2 * radius / mesh.module)
    teeth = np.array(teeth)
    shifts = tuple(float(g.profile_shift) for g in mesh.gears)
    ratio = contact_ratio(radii[0], radii[1], mesh.module, rack, shifts, working,
                          tuple(g.tip_radius for g in mesh.gears), references)
    continuous = ratio >= 1.0
    # ISO 6336-3 (tip load) and 6336-2, for eps_alpha >= 1; a pair below it carries the whole
    # load on one tooth at its tip (Y_eps = 1) and the pose is flagged
    ratio_used = np.clip(ratio, 1.0, 2.0)
    contact_share = 0.25 + 0.75 / ratio_used
    contact_eps = np.sqrt((4.0 - ratio_used) / 3.0)
    tangential = force * np.cos(alpha)
    forms, corrections, root, bending, valid, reasons = [], [], [], [], [], []
    for k, gear in enumerate(mesh.gears):
        form, correction, notch, settled = form_factors(teeth[k], gear.profile_shift, rack)
        stress = tangential / (mesh.face_width * mesh.module) * form * correction \
            * contact_share * factors.product
        endurance = gear.material.bending_endurance * (IDLER_BENDING_FACTOR
                                                       if gear.reversed_bending else 1.0)
        with np.errstate(divide="ignore"):
            bending.append(np.where(stress > 0, endurance / np.where(stress > 0, stress, 1.0),
                                    np.inf))
        in_range = (notch >= STRESS_CORRECTION_VALIDITY[0]) & \
            (notch < STRESS_CORRECTION_VALIDITY[1])
        for mask, reason in ((~settled, "pointed equivalent tooth or form factor unsettled"),
                             (settled & ~in_range, "q_s outside ISO 6336-3's 1 <= q_s < 8"),
                             (~continuous, "contact ratio below 1 (tip load on one tooth)")):
            if mask.any():
                reasons.append((k, reason, int(mask.sum())))
        valid.append(settled & in_range & continuous)
        forms.append(form)
        corrections.append(correction)
        root.append(stress)
    reduced = reduced_flank_radius(radii[0], radii[1], working)
    z_e = elasticity_factor(mesh.gears[0].material, mesh.gears[1].material)
    with np.errstate(invalid="ignore"):
        contact = z_e * contact_eps * np.sqrt(force * factors.product / (mesh.face_width * reduced))
    if np.isnan(reduced).any():
        reasons.append((0, "flanks conformal: the concave gear bends tighter than its mate",
                        int(np.isnan(reduced).sum())))
        valid = [v & ~np.isnan(reduced) for v in valid]
    contact_safety = []
    for gear in mesh.gears:
        limit = gear.material.contact_endurance
        if limit is None:
            contact_safety.append(np.full(pose.shape, np.nan))
            continue
        allowed = limit * gear.material.surface_factor
        with np.errstate(divide="ignore", invalid="ignore"):
            contact_safety.append(np.where(contact > 0, allowed / np.where(contact > 0, contact,
                                                                           1.0), np.inf))
    return MeshStrength(mesh.name, tuple(g.name for g in mesh.gears), pose, mesh.period, force,
                        teeth, ratio, np.array(forms), np.array(corrections), np.array(root),
                        contact, np.array(bending), np.array(contact_safety), np.array(valid),
                        tuple(reasons), mesh.load_source,
                        tuple(g.material for g in mesh.gears))
