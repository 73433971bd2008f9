"""The planting mechanism's design metrics against their targets (spec table), per plant spacing.

Seven metrics: trajectory height, hole width, hole verticality, entry/exit
attitude difference, arm distance, gearbox ground clearance, non-circular gear
module; plus the attitudes at catching, entry, lowest point and exit, the tip
speeds at the lowest and catching points, the catching-to-planting height, the
hole span and the number of soil penetrations per plant.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import tolerances as tol
from .clearance import HousingCircle, KinematicClearance
from .metrics import PlantEvents, hole_metrics, plant_events
from .planting import PlantingMechanism
from .sweep import Verdict

__all__ = ["Targets", "MetricResult", "PlantingEvaluation", "evaluate_planting"]


@dataclass(frozen=True)
class Targets:
    """The spec's targets (mm, deg); each a keyword so a file can override it."""

    trajectory_height_min: float = 500.0
    hole_width_max: float = 30.0
    hole_verticality_max: float = 10.0
    angle_difference_max_deg: float = 20.0
    arm_distance_min: float = 10.0
    ground_clearance_min: float = 20.0
    module_min: float = 2.5


@dataclass(frozen=True)
class MetricResult:
    """One metric's value against its target.

    ``verdict`` is ``passed`` spelled out, or ``"undecided"`` for a searched minimum
    whose certified gap ``[bound, value]`` straddles the target (then not passed).
    """

    key: str
    label: str
    value: float
    unit: str
    target: str
    passed: bool
    spacing: float | None = None
    verdict: str = ""
    bound: float | None = None     # a searched minimum's certified lower bound

    def __post_init__(self):
        # a plain comparison is certain; a search's verdict may be "undecided" (not passed)
        if not self.verdict:
            object.__setattr__(self, "verdict", Verdict.PASS if self.passed else Verdict.FAIL)


@dataclass(frozen=True)
class PlantingEvaluation:
    """Everything :func:`evaluate_planting` finds. Angles in degrees, lengths mm, speeds mm/s."""

    metrics: list
    events: PlantEvents
    holes: list
    attitudes_deg: dict
    speeds: dict
    catch_to_plant_height: float
    module: float
    perimeter: float
    arm_distance_at_deg: float
    ground_clearance_circle: HousingCircle
    housing_circles: list
    accuracy: dict
    carrier_speed_rpm: float = 30.0
    extras: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return all(m.passed for m in self.metrics)


def _searched(key, label, search, target) -> MetricResult:
    """A minimum that must exceed ``target``, judged on its certified gap ``[bound, value]``."""
    verdict = search.verdict_above(target)
    return MetricResult(key, label, search.value, "mm", f"> {target:g}",
                        verdict == Verdict.PASS, verdict=verdict, bound=search.bound)


def _deg(x):
    return float(np.degrees(x))


def evaluate_planting(mechanism: PlantingMechanism, *, teeth: int, depth: float,
                      spacings, housing_circles, carrier_speed_rpm: float = 30.0,
                      targets: Targets = Targets(),
                      steps: int = tol.STEPS_PER_REVOLUTION,
                      clearance_model=None, events: PlantEvents | None = None
                      ) -> PlantingEvaluation:
    """Evaluate every design metric of the planting mechanism.

    Parameters
    ----------
    mechanism : PlantingMechanism
    teeth : int
        Tooth count ``z`` of the non-circular gears.
    depth : float
        Planting depth (mm): the soil line is ``min(y_N) + depth``.
    spacings : sequence of float
        Plant spacings (mm).
    carrier_speed_rpm : float
        Carrier-1 speed for speeds in mm/s.
    housing_circles : list of HousingCircle
        The gearboxes' envelope circles (the housing code sizes them from the gears:
        ``cadgen.solids.housings``); the ground clearance is theirs.
    steps : int
        Screening samples per revolution before refinement.
    clearance_model : object, optional
        Supplies ``arm_distance`` and ``ground_clearance`` (see
        :class:`~kinematics.clearance.KinematicClearance`, the default, built
        on ``housing_circles``).
    events : PlantEvents, optional
        ``plant_events(mechanism.tip_path(), depth, steps=steps)`` when the caller has them
        already (validation computed them).
    """
    omega = 2.0 * np.pi * carrier_speed_rpm / 60.0
    closure = mechanism.closure
    perimeter = mechanism.pitch_perimeter
    module = mechanism.module(teeth)
    tip = mechanism.tip_path()
    events = events or plant_events(tip, depth, steps=steps)
    holes = [hole_metrics(tip, events, float(s), steps=steps) for s in spacings]
    circles = list(housing_circles)
    model = clearance_model or KinematicClearance(tuple(circles))
    arms = model.arm_distance(mechanism, steps)
    clearance, nearest = model.ground_clearance(mechanism, events.soil_level, steps)

    angles = np.array([0.0, events.entry, events.lowest, events.exit])
    psi = mechanism.attitude(angles)
    attitudes = {k: _deg(v) for k, v in zip(("catching", "entry", "lowest", "exit"), psi)}
    tip_motion = mechanism.motion(np.array([events.lowest, 0.0]), "N")
    relative = tip_motion.velocity * omega
    speeds = {
        "relative_lowest": relative[0].tolist(),
        "relative_catching": relative[1].tolist(),
        "absolute_lowest": {}, "absolute_catching": {},
    }
    for s in spacings:
        drift = np.array([s / np.pi * omega, 0.0])
        speeds["absolute_lowest"][float(s)] = (relative[0] + drift).tolist()
        speeds["absolute_catching"][float(s)] = (relative[1] + drift).tolist()
    catching_height = float(tip.height(np.array([0.0]))[0])
    angle_difference = abs(attitudes["exit"] - attitudes["entry"])

    t = targets
    metrics = [MetricResult("trajectory_height", "trajectory height", events.trajectory_height,
                            "mm", f"> {t.trajectory_height_min:g}",
                            events.trajectory_height > t.trajectory_height_min)]
    for hole in holes:
        metrics.append(MetricResult("hole_width", "hole width", hole.width, "mm",
                                    f"0-{t.hole_width_max:g}",
                                    0.0 <= hole.width <= t.hole_width_max, hole.spacing))
        metrics.append(MetricResult("hole_verticality", "hole verticality", hole.verticality, "mm",
                                    f"< {t.hole_verticality_max:g}",
                                    hole.verticality < t.hole_verticality_max, hole.spacing))
    metrics += [
        MetricResult("angle_difference", "entry/exit angle difference", angle_difference, "deg",
                     f"0-{t.angle_difference_max_deg:g}",
                     angle_difference <= t.angle_difference_max_deg),
        _searched("arm_distance", model.arm_label, arms, t.arm_distance_min),
        _searched("ground_clearance", model.ground_label, clearance, t.ground_clearance_min),
        MetricResult("module", "non-circular gear module", module, "mm",
                     f"> {t.module_min:g}", module > t.module_min),
        MetricResult("soil_penetrations", "soil penetrations per plant", float(events.penetrations),
                     "", "= 1", events.penetrations == 1),
    ]
    accuracy = {
        "closure_centre_distance_error_mm": closure.error_estimate,
        "closure_residual": closure.residual,
        "closure_nodes": closure.nodes,
        "ratio_fourier_modes": int(len(closure.law.coefficients)),
        "root_xtol_rad": tol.ROOT_XTOL,
        "refine_xatol_rad": tol.REFINE_XATOL,
        "steps_per_revolution": steps,
        "minimum_searches": {
            # the highest point is searched as the minimum of -y: reported as the height it
            # is, its certified bound then an upper one ("maximum": True)
            name: {"value": sign * r.value, "certified_bound": sign * r.bound,
                   "maximum": sign < 0, "certified": r.certified,
                   "gap": r.gap, "atol": r.atol, "budget_spent": r.budget_spent,
                   "refined_intervals": r.refined_intervals, "evaluations": r.evaluations}
            for name, r, sign in (("lowest_point", events.lowest_search, 1.0),
                                  ("highest_point", events.highest_search, -1.0),
                                  ("arm_distance", arms, 1.0), ("ground_clearance", clearance, 1.0))},
    }
    return PlantingEvaluation(
        metrics=metrics, events=events, holes=holes, attitudes_deg=attitudes, speeds=speeds,
        catch_to_plant_height=catching_height - events.lowest_height, module=module,
        perimeter=perimeter, arm_distance_at_deg=_deg(arms.argument),
        ground_clearance_circle=nearest, housing_circles=circles, accuracy=accuracy,
        carrier_speed_rpm=carrier_speed_rpm,
        extras={"hole_span": {h.spacing: h.span for h in holes},
                "ground_clearance_at_deg": _deg(clearance.argument),
                "clearance_method": model.method})
