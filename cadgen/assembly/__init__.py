"""The assembly model: parts, the joints between them, and what the joint graph says.

Standard library only, no solids: which parts move as one rigid body, the machine's
planar mobility (Kutzbach–Grübler with higher pairs), and the parts nothing holds.

Modules
-------
graph
    :class:`Joint`, :class:`AssemblyModel` (bodies, mobility, unconnected parts, reports).
"""

from cadgen.assembly.graph import (FIXED, HIGHER_PAIRS, JOINT_KINDS, LOWER_PAIRS,
                                   MOBILITY_FORMULA, AssemblyModel, Joint, connected_groups)

__all__ = ["AssemblyModel", "Joint", "JOINT_KINDS", "FIXED", "LOWER_PAIRS", "HIGHER_PAIRS",
           "MOBILITY_FORMULA", "connected_groups"]
