"""Parts of an assembly: a solid in its body's frame, and the rigid poses that move the bodies.

A :class:`Part` is a manifold3d solid in the frame of the rigid body it rides on
(``carrier1``, ``gearbox2``, ``planter``, ...), placed there by ``local`` (a 4x4
transform that may depend on the pose, e.g. a gear turning on its shaft). A
mechanism's :class:`Assembly` knows each body's world transform at any carrier
angle and each part's local placement, so the same part meshes serve the STL
files, the assembly file at a chosen angle and the collision sweeps. Which copies of
a part exist (per arm, per side of carrier 1) is the assembly model's to say
(:func:`placed_assembly`, :mod:`cadgen.assembly.machine`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

__all__ = ["Part", "Assembly", "planar_transform", "gear_solid", "placed_assembly"]


def planar_transform(angle: float = 0.0, offset=(0.0, 0.0), z: float = 0.0) -> np.ndarray:
    """4x4 homogeneous transform: turn by ``angle`` (rad) about z, then move by ``(x, y, z)``."""
    c, s = np.cos(angle), np.sin(angle)
    transform = np.eye(4)
    transform[:2, :2] = [[c, -s], [s, c]]
    transform[:2, 3] = offset
    transform[2, 3] = z
    return transform


@dataclass
class Part:
    """One solid of an assembly.

    Attributes
    ----------
    name : str
        File stem of its STL (unique in the assembly).
    kind : str
        ``"gear"``, ``"housing"``, ``"cam"``, ``"planter"``, ``"blade"``,
        ``"rocker"``, ``"needle"``, ``"ground"``.
    body : str
        The rigid body it rides on (a key of the assembly's body poses).
    solid : manifold3d.Manifold
        In the part's own frame (a gear: its axis at the origin).
    local : callable
        ``phi -> (4, 4)`` placement of the part in its body's frame at carrier angle phi.
    instances : tuple
        ``(instance name, body, phase offset)`` of each placed copy (both arms
        use one part); empty for a single instance on ``body`` at phase 0.
    outline : (n, 2) float, optional
        The section a prism part was extruded from (gears), for exact 2D checks.
    footprint : (n, 2) float, optional
        The part seen along z (its silhouette in its own frame) when known in closed form: a
        housing half's flange outline. Pictures draw it instead of merging the triangles.
    bought : tuple of BoughtItem
        The bought items fixed in it, in its own frame (:mod:`cadgen.solids.bought`): the
        bearings in its seats, the keys in its keyseats, the screws in its holes. The assembly
        places them as solids riding with it (``Assembly.bought``).
    """

    name: str
    kind: str
    body: str
    solid: object
    local: Callable = field(default=lambda phi: np.eye(4))
    instances: tuple = ()     # ((instance name, body, phase offset rad), ...); empty: one at body
    outline: object = None    # (n, 2) section of a z-prism part (gears), for exact 2D checks
    footprint: object = None  # (n, 2) silhouette along z, when known (housing halves)
    bought: tuple = ()        # BoughtItem records of what is fixed in it (its own frame)
    _mesh: object = field(default=None, repr=False)

    @property
    def mesh(self):
        """The trimesh of the solid (converted once; watertight and positive, or SolidError)."""
        if self._mesh is None:
            from cadgen.solids.extrude import to_trimesh

            self._mesh = to_trimesh(self.solid, self.name)
        return self._mesh


@dataclass
class Assembly:
    """Parts and the poses of the bodies they ride on.

    ``body_pose(body, phi)`` gives the 4x4 world transform of a body at carrier
    angle ``phi``; a part instance with phase offset ``p`` rides on its body at
    ``phi + p`` (the second planting arm is the first at ``phi + pi``).
    """

    parts: list
    body_pose: Callable
    model: object = None   # the AssemblyModel whose placements the parts' instances are
    #: ``angles -> None``: solve the poses of many carrier angles at once (a mechanism whose
    #: pose needs an inverse solve); the default does nothing
    prepare: Callable = field(default=lambda angles: None, repr=False)
    #: the bought solids (:class:`~cadgen.solids.bought.BoughtPart`) riding on the parts' bodies,
    #: apart from ``parts`` (the made parts: their files, masses, bill rows)
    bought: list = field(default_factory=list)

    def placements(self, phi: float, *, bought: bool = False):
        """``[(instance name, part, 4x4 world transform)]`` at carrier angle ``phi`` (rad), of
        the made parts (and, ``bought``, the bought solids after them)."""
        out = []
        for part in list(self.parts) + (list(self.bought) if bought else []):
            instances = part.instances or ((part.name, part.body, 0.0),)
            for name, body, phase in instances:
                pose = self.body_pose(body, phi + phase) @ part.local(phi + phase)
                out.append((name, part, pose))
        return out


def placed_assembly(parts, body_pose, build_model, drivetrain, train, housings, *,
                    segments: int = 96) -> Assembly:
    """The assembly of ``parts``, each placed as often and where the assembly model says.

    ``build_model`` is :func:`cadgen.assembly.machine.planting_model` or
    :func:`~cadgen.assembly.machine.pricking_model`: it is given every made part's body and
    the housing records, and decides which copies exist (per arm, per side of carrier 1) and
    what bought items their joints need. Each part's ``instances`` are then the model's
    placements of it; a part the model does not know (the soil) stays one copy on its body.
    The items the parts hold (their ``bought``) are placed as solids with each copy
    (:func:`cadgen.solids.bought.bought_parts`, round features of ``segments`` sides).
    """
    from cadgen.solids.bought import bought_parts

    meshes = [tuple(stage.generated.pair.names) for stage in (train.stages if train else ())]
    model = build_model(drivetrain, meshes, bodies={part.name: part.body for part in parts},
                        housings=housings, kinds={part.name: part.kind for part in parts})
    for part in parts:
        part.instances = model.instances_of(part.name)
    for body in dict.fromkeys(p.body for p in model.placements):
        body_pose(body, 0.0)   # a body the mechanism does not move is a KeyError here, not later
    return Assembly(parts, body_pose, model, bought=bought_parts(parts, segments))


def gear_solid(profile, face_width: float, segments: int, path: str, chord_tolerance: float):
    """A gear extruded from its cut outline, with its bore, from z = 0 (its own frame): (solid, outline).

    The outline is the one the gear's DXF holds (thinned to ``chord_tolerance``, clear of
    the hole's reach), so the STL and the cutting file describe the same part. The bore is
    the profile's ``hole`` (bore with keyway or D-flat, body frame) when set, else a
    ``segments``-gon of ``bore_radius``.
    """
    from cadgen.machine.hubs import cutting_outline
    from cadgen.solids.extrude import extrude
    from cadgen.solids.outline import circle

    hole = getattr(profile, "hole", None)
    if hole is not None:
        holes = [np.asarray(hole, dtype=float)]
    else:
        holes = [circle(profile.bore_radius, segments, profile.centre)] if profile.bore_radius > 0 else []
    # the outline the gear's DXF holds, thinned and checked once for both
    outline = cutting_outline(profile, chord_tolerance).outline
    return extrude(outline, face_width, holes=holes, path=path,
                   outline_path=f"gear {profile.name!r} outline"), outline
