"""The assembly model: parts, the joints between them, and what the joint graph says.

No solids and no numpy: which parts move as one rigid body, the machine's planar mobility
(Kutzbach–Grübler with higher pairs), the parts nothing holds, where each made part's copies
are placed and what each joint is bought with. The solids are placed, the bill counted, the
GLB, the sweeps and the report's animation drawn from it.

Modules
-------
graph
    :class:`Joint`, :class:`Item`, :class:`Placement`, :class:`AssemblyModel` (bodies,
    mobility, unconnected parts, placed copies, bought items, reports).
machine
    The planting and pricking machines' models from their drivetrain records.
"""

from cadgen.assembly.graph import (FIXED, HIGHER_PAIRS, JOINT_KINDS, LOWER_PAIRS,
                                   MOBILITY_FORMULA, AssemblyModel, Item, Joint, Placement,
                                   connected_groups)

__all__ = ["AssemblyModel", "Joint", "Item", "Placement", "JOINT_KINDS", "FIXED", "LOWER_PAIRS",
           "HIGHER_PAIRS", "MOBILITY_FORMULA", "connected_groups"]
