"""Mass properties of a part: volume, area, mass, centre of mass, inertia tensor.

Meshes are in mm and densities in kg/m^3 (the datasheet unit), so the density
is converted once, ``kg/m^3 * 1e-9 = kg/mm^3``; inertia comes out in kg mm^2.

The volume integrals are trimesh's (Eberly's polyhedral mass properties, for unit
density), evaluated on the mesh moved near the origin first: the inertia about
the centre of mass is a difference of two large terms for a part far from the
origin (a gear placed 200 mm out), and moving it there first avoids that loss.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.solids.errors import SolidError, SolidInputError

__all__ = ["KG_PER_MM3_PER_KG_PER_M3", "mass_properties"]

#: 1 kg/m^3 in kg/mm^3.
KG_PER_MM3_PER_KG_PER_M3 = 1e-9


def mass_properties(mesh, density_kg_m3: float) -> dict:
    """Mass properties of a closed mesh in mm at a uniform density.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Watertight, consistently wound, positive volume; vertices in mm.
    density_kg_m3 : float
        kg/m^3, finite and > 0 (e.g. 1240 for PLA, 7850 for steel).

    Returns
    -------
    dict
        ``volume_mm3`` : float,
        ``area_mm2`` : float,
        ``mass_kg`` : float,
        ``centre_of_mass_mm`` : (3,) float,
        ``inertia_kg_mm2`` : (3, 3) float, the inertia tensor about the centre of
        mass in the part's axes (diagonal: moments; off-diagonal: minus the
        products of inertia).

    Raises
    ------
    SolidInputError
        For a density that is not finite and > 0.
    SolidError
        For a mesh that is not a closed, consistently wound, positive volume.
    """
    from trimesh.triangles import mass_properties as integrate

    density = float(density_kg_m3)
    if not (math.isfinite(density) and density > 0.0):
        raise SolidInputError("density_kg_m3", f"density must be finite and > 0 kg/m^3, not {density!r}")
    name = str(mesh.metadata.get("name", "mesh"))
    # An open or inverted mesh still integrates to numbers, just wrong ones.
    if not mesh.is_watertight:
        raise SolidError(name, "watertight", "mass properties need a closed mesh")
    if not mesh.is_winding_consistent:
        raise SolidError(name, "winding_consistent", "mass properties need consistently wound faces")

    triangles = np.asarray(mesh.triangles, dtype=np.float64)
    shift = 0.5 * (triangles.reshape(-1, 3).min(axis=0) + triangles.reshape(-1, 3).max(axis=0))
    unit = integrate(triangles - shift, density=1.0)
    if not unit.volume > 0:
        raise SolidError(name, "positive_volume", f"the volume is {unit.volume!r} mm^3 (inside out?)")
    density_kg_mm3 = density * KG_PER_MM3_PER_KG_PER_M3
    return {
        "volume_mm3": float(unit.volume),
        "area_mm2": float(mesh.area),
        "mass_kg": float(unit.volume * density_kg_mm3),
        "centre_of_mass_mm": np.asarray(unit.center_mass, dtype=float) + shift,
        "inertia_kg_mm2": np.asarray(unit.inertia, dtype=float) * density_kg_mm3,
    }
