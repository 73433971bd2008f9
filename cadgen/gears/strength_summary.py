"""A train's tooth strength gathered per gear: its least safeties, where, and the failing checks.

:func:`train_strength_summary` takes the meshes' :class:`~cadgen.gears.strength.MeshStrength`
and the ``[machine]`` limits, and gives each gear its least bending and contact safety over
every mesh it is in and every pose (with the mesh and the cycle angle of the pose), and
a :class:`kinematics.errors.Problem` for each safety below its limit (failing) and each
gear with poses outside a formula's validity (a warning). ``report.json``
``gear_train.gears[*]`` and ``gear_train.strength`` are written from it
(:func:`strength_report`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kinematics.errors import Problem

from cadgen.gears.strength import MeshStrength

__all__ = ["GearStrength", "TrainStrength", "train_strength_summary", "strength_report",
           "METHOD"]

#: The method in one paragraph, for the report.
METHOD = ("ISO 6336-3 root bending with the load at the tooth tip (Y_Fa, Y_Sa from the basic "
          "rack at the equivalent tooth count z_v = 2 R / m, R the pitch curve's radius of "
          "curvature at the contact; internal-gear equations on a concave stretch) and "
          "Y_eps = 0.25 + 0.75 / eps_alpha; ISO 6336-2 Hertz contact at the pitch point with "
          "the flanks' radii R sin(alpha_w); each non-circular gear taken at every pose as "
          "the spur gear of its local pitch curvature")


@dataclass(frozen=True)
class GearStrength:
    """One gear's least safeties over the cycle (``contact_safety_min`` None: not rated)."""

    gear: str
    material: str
    bending_safety_min: float
    bending_mesh: str
    bending_at_deg: float
    root_stress_max_mpa: float
    contact_safety_min: float | None
    contact_mesh: str | None
    contact_at_deg: float | None
    contact_stress_max_mpa: float
    equivalent_teeth_min: float
    invalid_poses: int
    notes: tuple = ()

    def as_dict(self) -> dict:
        return {"gear": self.gear, "material": self.material,
                "bending_safety_min": self.bending_safety_min,
                "bending_safety_mesh": self.bending_mesh,
                "bending_safety_at_deg": self.bending_at_deg,
                "root_stress_max_mpa": self.root_stress_max_mpa,
                "contact_safety_min": self.contact_safety_min,
                "contact_safety_mesh": self.contact_mesh,
                "contact_safety_at_deg": self.contact_at_deg,
                "contact_stress_max_mpa": self.contact_stress_max_mpa,
                "equivalent_teeth_min": self.equivalent_teeth_min,
                "strength_invalid_poses": self.invalid_poses,
                "strength_notes": list(self.notes)}


@dataclass(frozen=True)
class TrainStrength:
    """Every mesh's strength, each gear's minima, the limits and the checks."""

    meshes: tuple
    gears: dict                     # name -> GearStrength
    limits: dict                    # {"bending": S_F min, "contact": S_H min}
    factors: dict
    load: str
    problems: tuple = ()            # failing
    warnings: tuple = ()
    extra: dict = field(default_factory=dict)


def _cycle_deg(mesh: MeshStrength, index: int) -> float:
    """The pose's place in the mesh's cycle, degrees (the carrier angle where the cycle is a
    carrier turn)."""
    return float(np.degrees(mesh.pose[index] * 2 * math.pi / mesh.period) % 360.0)


def train_strength_summary(meshes, bending_limit: float, contact_limit: float,
                           factors: dict, load: str, extra: dict | None = None) -> TrainStrength:
    """Each gear's least safeties over ``meshes`` (:class:`MeshStrength` each) and the checks
    against ``bending_limit`` (``machine.bending_safety_min``) and ``contact_limit``
    (``machine.contact_safety_min``): a safety below its limit fails."""
    rows: dict = {}
    for mesh in meshes:
        for k, name in enumerate(mesh.names):
            rows.setdefault(name, []).append((mesh, k))
    gears, problems, warnings = {}, [], []
    for name, places in rows.items():
        bending = min(((float(m.bending_safety[k].min()), m, int(m.bending_safety[k].argmin()))
                       for m, k in places), key=lambda item: item[0])
        rated = [(m, k) for m, k in places if not np.isnan(m.contact_safety[k]).all()]
        contact = min(((float(np.nanmin(m.contact_safety[k])), m,
                        int(np.nanargmin(m.contact_safety[k]))) for m, k in rated),
                      key=lambda item: item[0]) if rated else None
        invalid = sum(int((~m.valid[k]).sum()) for m, k in places)
        notes = tuple(f"{m.name}: {reason} at {count} poses" for m, k in places
                      for gear, reason, count in m.invalid_reasons if gear == k)
        material = places[0][0].materials[places[0][1]].name
        gear = GearStrength(
            name, material, bending[0], bending[1].name, _cycle_deg(bending[1], bending[2]),
            max(float(m.root_stress[k].max()) for m, k in places),
            None if contact is None else contact[0], None if contact is None else contact[1].name,
            None if contact is None else _cycle_deg(contact[1], contact[2]),
            max(float(np.nanmax(m.contact_stress)) for m, _ in places),
            min(float(np.abs(m.equivalent_teeth[k]).min()) for m, k in places), invalid, notes)
        gears[name] = gear
        if gear.bending_safety_min < bending_limit:
            problems.append(Problem(
                "machine.bending_safety_min", "tooth_bending_safety_low",
                f"the {name} gear's teeth ({material}) reach a root bending safety of "
                f"{gear.bending_safety_min:.2f} in the mesh {gear.bending_mesh!r} at "
                f"{gear.bending_at_deg:.1f} deg of its cycle (root stress up to "
                f"{gear.root_stress_max_mpa:.0f} MPa), below machine.bending_safety_min = "
                f"{bending_limit:g}: a larger module or face width (gears.face_width), a "
                "stronger material, or a lower design load (machine.tip_load_n)"))
        if gear.contact_safety_min is not None and gear.contact_safety_min < contact_limit:
            problems.append(Problem(
                "machine.contact_safety_min", "tooth_contact_safety_low",
                f"the {name} gear's flanks ({material}) reach a contact (pitting) safety of "
                f"{gear.contact_safety_min:.2f} in the mesh {gear.contact_mesh!r} at "
                f"{gear.contact_at_deg:.1f} deg of its cycle (Hertz stress up to "
                f"{gear.contact_stress_max_mpa:.0f} MPa), below machine.contact_safety_min = "
                f"{contact_limit:g}: a wider face (gears.face_width), larger gears, a harder "
                "material, or a lower design load (machine.tip_load_n)"))
        if contact is None:
            warnings.append(Problem("manufacturing.process", "tooth_contact_not_rated",
                                    f"the {name} gear's material ({material}) has no "
                                    "published pitting endurance: its flanks are not rated"))
        if invalid:
            warnings.append(Problem("gears", "tooth_strength_outside_validity",
                                    f"the {name} gear's strength figures at {invalid} poses lie "
                                    "outside the formulas' validity (" + "; ".join(notes) + ")"))
    return TrainStrength(tuple(meshes), gears, {"bending": bending_limit, "contact": contact_limit},
                         factors, load, tuple(problems), tuple(warnings), extra or {})


def _finite(value):
    return value if value is None or math.isfinite(value) else None


def strength_report(strength: TrainStrength) -> dict:
    """``report.json`` ``gear_train.strength``: method, load, factors, limits, materials, each
    mesh's extremes, the failing problems and the warnings."""
    meshes = []
    for mesh in strength.meshes:
        meshes.append({
            "mesh": mesh.name, "gears": list(mesh.names), "load": mesh.load_source,
            "poses": int(mesh.pose.size),
            "normal_force_n": [float(mesh.normal_force.min()), float(mesh.normal_force.max())],
            "contact_ratio": [float(mesh.contact_ratio.min()), float(mesh.contact_ratio.max())],
            "equivalent_teeth_min": [_finite(float(np.abs(z).min()))
                                     for z in mesh.equivalent_teeth],
            "root_stress_max_mpa": [float(s.max()) for s in mesh.root_stress],
            "contact_stress_max_mpa": float(np.nanmax(mesh.contact_stress)),
            "bending_safety_min": [float(s.min()) for s in mesh.bending_safety],
            "contact_safety_min": [None if np.isnan(s).all() else float(np.nanmin(s))
                                   for s in mesh.contact_safety]})
    materials = {}
    for mesh in strength.meshes:
        for material in mesh.materials:
            materials[material.name] = material.as_dict()
    return {"method": METHOD, "load": strength.load, "factors": strength.factors,
            "limits": {"bending_safety_min": strength.limits["bending"],
                       "contact_safety_min": strength.limits["contact"]},
            "materials": materials, "meshes": meshes,
            "problems": [p.as_dict() for p in strength.problems],
            "warnings": [p.as_dict() for p in strength.warnings], **strength.extra}
