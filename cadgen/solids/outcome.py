"""What a build's solids came to: the assembly, its housings' enclosure checks, mass properties.

The report section lists each part's mass properties at the file's density and, per
housing, whether its gears stay inside the cavity over a revolution; the files are
written by :func:`cadgen.export.meshes.write_solids`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SolidsOutcome", "solids_outcome", "solids_report", "enclosure_checks"]

@dataclass
class SolidsOutcome:
    assembly: object
    housings: dict           # housing part name -> Housing (cadgen.solids.shell)
    enclosure: list          # one dict per housing
    carrier_angle: float     # rad, the assembly file's pose
    density: float
    file_type: str


def solids_outcome(params, assembly, housings) -> SolidsOutcome:
    """The solids of a build with their enclosure checks and the file's output settings."""
    settings = params.solids
    return SolidsOutcome(assembly, housings, enclosure_checks(assembly, housings),
                         settings.assembly_carrier_angle_rad, settings.density_kg_m3,
                         settings.assembly_format)


def enclosure_checks(assembly, housings: dict) -> list:
    """Whether every gear stays inside its housing's cavity at every pose, with the margin.

    A gear turns about a fixed axis of its housing, so over a revolution it sweeps
    the disc of its largest outline radius about that axis: the gear stays inside
    at every pose exactly when that disc lies in the cavity outline and the gear's
    faces lie between the cavity's floor and roof. Reports the smallest radial
    margin (mm; negative: the gear cuts into the wall) and the gear it belongs to.
    """
    import shapely

    results = []
    for housing_name, housing in housings.items():
        cavity = shapely.Polygon(housing.cavity_outline)
        z_low, z_high = housing.z_cavity_bottom, housing.z_cavity_bottom + housing.cavity_height
        body = next(p.body for p in assembly.parts if p.name == housing_name)
        worst, worst_gear, axial_ok = np.inf, None, True
        for part in assembly.parts:
            if part.kind != "gear" or part.body != body:
                continue
            bottom, top = part.mesh.bounds[:, 2]
            local = part.local(0.0)
            reach = float(np.max(np.linalg.norm(part.outline, axis=1)))
            axial_ok &= bool(z_low <= bottom + local[2, 3] + 1e-9
                             and top + local[2, 3] <= z_high + 1e-9)
            axes = [local[:2, 3]]
            if any(b.endswith(":mirrored") for _, b, _ in part.instances):
                axes.append(-local[:2, 3])   # the same gear on the carrier's other side
            for axis in axes:
                point = shapely.Point(axis)
                distance = cavity.exterior.distance(point)
                margin = (distance if cavity.contains(point) else -distance) - reach
                if margin < worst:
                    worst, worst_gear = margin, part.name
        results.append({"housing": housing_name, "gears_enclosed": bool(worst >= 0 and axial_ok),
                        "smallest_margin_mm": float(worst) if worst_gear else None,
                        "nearest_gear": worst_gear, "axial_fit": bool(axial_ok)})
    return results


def solids_report(outcome: SolidsOutcome) -> dict:
    """Mass properties per part, the enclosure checks and the assembly's pose (report.json)."""
    from cadgen.solids.mass import mass_properties

    parts = []
    total = 0.0
    for part in outcome.assembly.parts:
        instances = part.instances or ((part.name, part.body, 0.0),)
        if part.kind == "ground":
            continue
        props = mass_properties(part.mesh, outcome.density)
        total += props["mass_kg"] * len(instances)
        parts.append({
            "part": part.name, "kind": part.kind, "instances": len(instances),
            "file": f"solids/{part.name}.stl", "triangles": int(len(part.mesh.faces)),
            "volume_mm3": props["volume_mm3"], "area_mm2": props["area_mm2"],
            "mass_kg": props["mass_kg"], "centre_of_mass_mm": props["centre_of_mass_mm"].tolist(),
            "inertia_kg_mm2": props["inertia_kg_mm2"].tolist(),
            "watertight": bool(part.mesh.is_watertight),
            "winding_consistent": bool(part.mesh.is_winding_consistent),
        })
    return {"density_kg_m3": outcome.density, "parts": parts, "total_mass_kg": total,
            "assembly": {"file": f"solids/assembly.{outcome.file_type}",
                         "carrier_angle_deg": float(np.degrees(outcome.carrier_angle))},
            "enclosure": outcome.enclosure,
            "frames": "each STL in its part's own frame (gears: axis at the origin, faces at "
                      "z = 0 and z = face width); the assembly places every instance"}
