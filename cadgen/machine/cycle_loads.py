"""Loads over a carrier turn (the dynamics') on a shaft: torques, the beam, the bearings' equivalent load.

Where the dynamics ran, a shaft is sized from the forces it computed at every pose of the
turn instead of the assumed tip force (:mod:`cadgen.machine.loads`). One axis's
:class:`CycleLoads` holds, over the ``n`` poses: each gear's force on the shaft (the sum of
its meshes' tooth forces, N, world x-y) and moment about the axis (N mm), the rest of what
the shaft's bearings carry (the inertia and weight of the body, the planter's or a carried
housing's loads: the pin reaction the dynamics solved, less the gears' forces), and the
shaft's speed relative to its housing.

- **Strength** (shaft, keys, flange screws): the peak over the turn times the service factor
  (``[machine] service_factor``: shocks the model does not have, a stone in the soil). A
  section's torque is the running sum of the keyed gears' moments from the shaft's free end
  (the end away from what it drives or is driven by beyond its housing); the beam takes the
  forces with their directions at each pose, so ``M(z, phi)`` is a vector sum.
- **Life** (ISO 281, ball bearings): the cycle-equivalent load of variable load and speed,
  ``P_eq = (sum P^3 |n| / sum |n|)^(1/3)`` over the poses (uniform in time: the carrier turns
  at constant speed), ``n`` the bearing's speed at the pose, and the mean speed ``mean |n|``;
  no service factor (ISO 281's life is of the loads that recur every turn).

Forces in N, moments in N mm, lengths in mm, speeds in r/min.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from cadgen.machine.bearings import BALL_EXPONENT
from cadgen.machine.loads import AxisLoads, GearLoad

__all__ = ["CycleLoads", "ASSUMED_TIP_FORCE", "ESTIMATED_MASSES", "SOLID_MASSES",
           "equivalent_load", "cycle_beam", "section_torques", "cycle_axis_loads",
           "with_cycles", "cycle_size", "CYCLE_RULES"]

#: What a quantity's load came from, as the report says it.
ASSUMED_TIP_FORCE = "assumed tip force"
ESTIMATED_MASSES = "dynamics (estimated masses)"
SOLID_MASSES = "dynamics (solids' masses)"

CYCLE_RULES = {
    "strength": "peak over the carrier turn x service_factor (shocks): section torques are "
                "running sums of the keyed gears' tooth moments, the beam's moments the vector "
                "sums of the gears' tooth forces and the rest of the body's load at each pose",
    "bearing_life": "ISO 281 L10h = (C / P_eq)^3 1e6 / (60 n_mean), P_eq = (sum P^3 |n| / "
                    "sum |n|)^(1/3) over the turn (variable load and speed, exponent 3), "
                    "n_mean = mean |n|; no service factor",
    "rest": "the body's pin reaction less its gears' tooth forces (inertia, weight, what it "
            "carries): at the planter's plane (E), at the carried housing's mid-height (the "
            "hollow S and C, with the inner shaft's bearing in that housing's roof), else at "
            "the mean of the gears' planes",
}


@dataclass(frozen=True)
class CycleLoads:
    """One axis's loads at ``n`` poses of the carrier turn.

    Attributes
    ----------
    source : str
        :data:`ESTIMATED_MASSES` or :data:`SOLID_MASSES`.
    forces : dict
        ``{gear: (n, 2) float}`` N: the sum of the gear's tooth forces, on the shaft.
    moments : dict
        ``{gear: (n,) float}`` N mm: their moment about the axis.
    rest : (n, 2) float
        N: what else the bearings carry (the pin reaction less the gears' forces, negated).
    speed : (n,) float
        r/min, the shaft's speed relative to its housing (signed).
    free_speed : dict
        ``{gear: (n,) r/min}``: a gear running free on the shaft, its speed on it.
    """

    source: str
    forces: dict
    moments: dict
    rest: np.ndarray
    speed: np.ndarray
    free_speed: dict = dataclasses.field(default_factory=dict)

    @property
    def mean_speed(self) -> float:
        """``mean |n|`` (r/min): the turns the bearing makes per unit time."""
        return float(np.mean(np.abs(self.speed)))


def equivalent_load(load, speed) -> float:
    """ISO 281's equivalent load of a variable load at variable speed, exponent 3 (N).

    Parameters
    ----------
    load : (n,) float
        The bearing's radial load at each of ``n`` equally long time steps, N.
    speed : (n,) float
        Its speed at each step (any unit; only the weights matter, their signs not).

    Returns
    -------
    float
        ``(sum |P|^3 |n| / sum |n|)^(1/3)``; with no turning at all the largest load.
    """
    load = np.abs(np.asarray(load, dtype=float))
    weights = np.abs(np.broadcast_to(np.asarray(speed, dtype=float), load.shape))
    if load.ndim != 1 or not len(load):
        raise ValueError(f"equivalent_load needs a (n,) load, not shape {load.shape}")
    total = float(np.sum(weights))
    if total == 0.0:
        return float(load.max())
    return float((np.sum(load ** BALL_EXPONENT * weights) / total) ** (1.0 / BALL_EXPONENT))


def cycle_beam(z1: float, z2: float, loads) -> tuple:
    """The shaft on its two bearings under forces that turn over the cycle.

    Parameters
    ----------
    z1, z2 : float
        The bearings' heights, mm.
    loads : sequence of (z, (n, 2) float)
        Each force's height (mm) and its x-y components at every pose (N).

    Returns
    -------
    (float, (2, n) float, (2, n, 2) float)
        The largest bending moment magnitude over the poses and the load and bearing points
        (N mm); each bearing's radial load at each pose (N); the bearings' reactions on the
        shaft (N, vectors), which with the loads sum to zero.
    """
    z1, z2 = float(z1), float(z2)
    heights = np.array([float(z) for z, _ in loads])
    forces = np.stack([np.asarray(f, dtype=float) for _, f in loads])        # (k, n, 2)
    if not abs(z2 - z1) > 1e-9:
        raise ValueError(f"the bearings must be apart, not at z1 = {z1} and z2 = {z2}")
    # moments about the floor bearing vanish: R2 (z2 - z1) = -sum F (z - z1)
    roof = -np.einsum("k,knc->nc", heights - z1, forces) / (z2 - z1)
    floor = -forces.sum(axis=0) - roof
    points = np.concatenate([[z1, z2], heights])
    acting = np.concatenate([floor[None], roof[None], forces])               # (k + 2, n, 2)
    # the moment at z of the forces below it (a vector in the plane, perpendicular to them)
    arm = np.clip(points[:, None] - points[None, :], 0.0, None)              # (at, by)
    moment = np.einsum("ab,bnc->anc", arm, acting)
    bending = float(np.max(np.linalg.norm(moment, axis=-1)))
    radial = np.stack([np.linalg.norm(floor, axis=-1), np.linalg.norm(roof, axis=-1)])
    return bending, radial, np.stack([floor, roof])


def section_torques(moments, from_top: bool = False) -> np.ndarray:
    """The torque through each section of a shaft between its keyed gears, at every pose.

    ``moments`` are the keyed gears' (k, n) moments about the axis (N mm), bottom first; the
    running sum from the end opposite the shaft's outside drive or load (``from_top``: the
    outside load is below, at the input's coupling) gives each section's torque; the last
    is what leaves the shaft there. (k, n)."""
    moments = np.asarray(moments, dtype=float)
    if not len(moments):
        return np.zeros((0, 0))
    return np.cumsum(moments[::-1] if from_top else moments, axis=0)


def cycle_axis_loads(axis, cycle: CycleLoads, service_factor: float) -> AxisLoads:
    """An axis's :class:`~cadgen.machine.loads.AxisLoads` from the dynamics' cycle: each keyed
    gear's hub torque and every gear's radial load at their peaks times the service factor (the
    beam and the bearings read ``cycle`` itself), the shaft's torque the largest section's."""
    from cadgen.machine.layouts import _mount_fields
    from cadgen.machine.loads import FreeAxisLoads

    factor = float(service_factor)
    fields = [_mount_fields(m) for m in axis.mounts]
    keyed = [gear for gear, _, _, _, free in fields if not free]
    # the input is driven through its coupling below the frame: its sections count from the top
    sections = section_torques([cycle.moments[g] for g in keyed], from_top=axis.floor_through)
    torque = factor * float(np.max(np.abs(sections))) if sections.size else 0.0
    gears = {}
    for gear, _, _, _, free in fields:
        peak = float(np.max(np.linalg.norm(cycle.forces[gear], axis=-1)))
        hub = 0.0 if free else factor * float(np.max(np.abs(cycle.moments[gear])))
        # (no tangential force: the cycle's moments and forces stand for it; nan, never used)
        gears[gear] = GearLoad(gear, hub, float("nan"), factor * peak)
    external = None
    if axis.loads.external is not None:
        external = (axis.loads.external[0],
                    factor * float(np.max(np.linalg.norm(cycle.rest, axis=-1))))
    formulas = {"text": dict(CYCLE_RULES), "source": cycle.source,
                "service_factor": factor}
    common = (axis.name, torque, gears, cycle.mean_speed, external, formulas)
    if isinstance(axis.loads, FreeAxisLoads):
        frees = {g: float(np.mean(np.abs(s))) for g, s in cycle.free_speed.items()}
        return FreeAxisLoads(*common, cycle=cycle, free_speeds=frees)
    return AxisLoads(*common, cycle=cycle)


def with_cycles(axes, cycles: dict | None, service_factor: float) -> list:
    """The axes with their loads from ``cycles`` (``{axis name: CycleLoads}``) where given."""
    if not cycles:
        return list(axes)
    return [dataclasses.replace(axis, loads=cycle_axis_loads(axis, cycles[axis.name],
                                                             service_factor))
            if axis.name in cycles else axis for axis in axes]


def cycle_size(axis, z1: float, z2: float, mount_heights: dict, rest_height, service_factor: float,
               carried=None) -> tuple:
    """``(bending, life loads (2,), peak loads (2,), reactions (2, n, 2))`` of an axis over the
    cycle: the largest bending moment times the service factor (N mm), each bearing's ISO 281
    equivalent load and its peak (N, no factor), the reactions on the shaft at every pose.

    ``mount_heights`` ``{gear: z of its mid-plane}``; ``rest_height`` where the rest of the
    load acts (what the shaft carries: the planter's plane, a carried housing's mid-height;
    None: the mean of the gears' planes); ``carried`` (n, 2): the force an inner shaft's roof
    bearing puts on the housing this (hollow) shaft carries, added to the rest."""
    cycle = axis.loads.cycle
    loads = [(z, cycle.forces[gear]) for gear, z in mount_heights.items()]
    rest = cycle.rest if carried is None else cycle.rest + carried
    if rest_height is None:   # the body's own inertia and weight: where its gears are
        rest_height = float(np.mean(list(mount_heights.values())))
    loads.append((rest_height, rest))
    bending, radial, reactions = cycle_beam(z1, z2, loads)
    life = np.array([equivalent_load(p, cycle.speed) for p in radial])
    return float(service_factor) * bending, life, radial.max(axis=1), reactions
