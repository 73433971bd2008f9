"""The planting mechanism as a design problem: free parameters, the targets as constraints.

:class:`PlantingProblem` states a planting study for the optimiser (the DesignProblem
protocol of :mod:`cadgen.optimize.problem`). A population ``X`` is mapped to the
parameter arrays of the population screen (:func:`kinematics.population.screen`, some
thousands of designs a second on one core), every target of the base file becomes a
constraint ``G = -(normalised margin) <= 0`` (:mod:`kinematics.margins`, the studio's
margins), so does each of the duckbill's checks that ``cadgen build`` refuses a design for
(build stage "cam": the linkage in closed form, the cam's timing from the screened events,
:mod:`kinematics.population_cam`), and the finals are certified by the exact path
(:meth:`PlantingProblem.certify`: ``cadgen.validate_data`` then ``cadgen.evaluate``, what
``cadgen build`` uses, with the stage problems validation attaches).

The housings are sized round their gears, so the envelope circles of the ground
clearance change with the design: :class:`HousingRule` computes them as
:func:`cadgen.solids.housings.housing_circles` does (the gears' modules, the default
clearance and wall, the flange of the wall's bolt, any explicit radius in the file
winning), vectorised, from the pair the screen closes.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from kinematics.evaluation import Targets
from kinematics.margins import bounds_of, is_equality, margins, min_margin
from kinematics.population import CIRCLE_AXES, DEFAULT_SAMPLES, metric_keys, screen
from kinematics.population_cam import (LINKAGE_CHECKS, TIMING_CHECKS, linkage_margins,
                                       timing_margins)

__all__ = ["PlantingProblem", "HousingRule", "supported_paths", "INVALID", "CAM_LABELS"]

#: F and G of a design the screen cannot evaluate (pymoo needs finite numbers).
INVALID = 1e6

#: The duckbill's checks (build stage "cam"), one constraint each: ``cadgen build`` refuses a
#: design that fails one (see :mod:`kinematics.population_cam`).
CAM_LABELS = tuple(f"cam:{check}" for check in LINKAGE_CHECKS + TIMING_CHECKS)
#: The label of the linkage's checks that no free path changes, when the base file fails one.
CAM_FIXED = "cam:linkage_fixed"
#: The linkage problems L1 and L2 change (the others are judged once, on the base file).
_LINKAGE_CODES = {"blade_too_long", "lever_does_not_fit", "lever_angle_too_large",
                  "push_rod_inverted"}

#: Free paths of the mechanism: the screen's column each sets and the factor into it (deg to
#: rad as math.radians does, so the screen and the file see the same angle).
_MECHANISM_PATHS = {
    **{f"pitch_curve.{k}": (k, 1.0) for k in ("a1", "b1", "c1", "d1", "e1", "g1", "g2")},
    "pitch_curve.f1_rad": ("f1", 1.0), "pitch_curve.f2_rad": ("f2", 1.0),
    **{f"train.{k}": (k, 1.0) for k in ("i12", "i13", "R", "r")},
    "train.phi0_deg": ("phi0", math.pi / 180.0), "train.phic_deg": ("phic", math.pi / 180.0),
    "planter.L1": ("L1", 1.0), "planter.L2": ("L2", 1.0),
    "field.depth": ("depth", 1.0),
}
_TARGET_FIELDS = ("trajectory_height_min", "hole_width_max", "hole_verticality_max",
                  "angle_difference_max_deg", "arm_distance_min", "ground_clearance_min",
                  "module_min")
_HOUSING_PATHS = (("housing.clearance", "housing.wall")
                  + tuple(f"housing.{box}.{axis}" for box, axis in CIRCLE_AXES))
#: Why a path the schema has is not a free variable of the screen.
_REFUSED = {
    "pitch_curve.e2": "2*e2 must stay a whole number (the pitch curve closes only then)",
    "pitch_curve.teeth": "an integer (the search is continuous)",
    "train.n": "it changes no metric (only train 1's sets and the drive, the housings round "
               "them not yet screened)",
    "field.carrier_speed_rpm": "it changes no metric (only the speeds in mm/s)",
    "housing.axial_gap": "it changes no metric (the envelope circles are radial)",
}


def supported_paths(base_params=None) -> list[str]:
    """Every dotted parameter path a planting study may set free (numbers the screen models)."""
    return (list(_MECHANISM_PATHS) + [f"targets.{k}" for k in _TARGET_FIELDS]
            + list(_HOUSING_PATHS))


def _refusal(path: str) -> str:
    reason = _REFUSED.get(path)
    if reason is None:
        reason = "the planting screen does not model it (it changes no screened metric)"
    return (f"free path {path!r} cannot be searched: {reason}; the planting screen searches "
            f"{', '.join(supported_paths())}")


class HousingRule:
    """The envelope circles' radii of N designs, as :func:`cadgen.solids.housings.housing_circles`.

    Gearbox 1 holds the circular train (module ``m_c``: the file's
    ``gears.circular_module``, or the largest 0.05-mm step from 5 mm giving every circular
    gear a whole count of at least 17 teeth, or, when none does, the non-circular module);
    gearbox 2 the non-circular pair (module ``max(m_nc, m_c)``); gearbox 1's circles the
    larger of set II's and set I's gears on each axis (:meth:`holding_tips`). Each housing's
    envelope is
    its clearance (given, or ``max(2, 0.75 m)``) + wall (given, or ``max(3, 1.5 m)``) + the
    flange of the wall's bolt. Called by the screen with the closed pairs of some rows.
    """

    def __init__(self, base_params, columns: dict):
        from cadgen.solids.housings import flange_width
        from cadgen.solids.machine_parts import BOLT_BY_WALL

        housing = base_params.housing
        self.requested = base_params.gears.circular_module
        self.n = float(base_params.train.n)
        self.pressure_angle = base_params.gears.pressure_angle_rad
        self.shifts = base_params.gears.profile_shift.resolved()
        self.columns = {k: np.asarray(v, dtype=float) for k, v in columns.items()}
        # the flange by the wall's bolt: one width per bolt size (a given bolt: one for all)
        self.wall_steps = np.array([below for below, _ in BOLT_BY_WALL])
        walls = np.concatenate([[self.wall_steps[0] / 2.0], self.wall_steps])
        self.flanges = np.array([flange_width(base_params, float(w)) for w in walls])
        self.given = {"clearance": housing.clearance, "wall": housing.wall}
        self.explicit = {(box, axis): (getattr(housing, box).get(axis)
                                       if getattr(housing, box) is not None else None)
                         for box, axis in CIRCLE_AXES}

    def circular_module(self, rows, module_nc):
        """``m_c`` of the rows (see :func:`cadgen.gears.circular.planting_modules`)."""
        if self.requested is not None:
            return np.full(len(rows), float(self.requested))
        from cadgen.gears.circular import MIN_CIRCULAR_TEETH

        radii = np.stack(self.set_two(rows) + [self.columns["r"][rows]], axis=1)
        steps = np.arange(100, 9, -1)
        counts = 2.0 * radii[:, None, :] / (steps[None, :, None] * 0.05)
        whole = ((np.abs(counts - np.round(counts)) < 1e-6)
                 & (np.round(counts) >= MIN_CIRCULAR_TEETH)).all(axis=2)
        first = whole.argmax(axis=1)
        module = np.round(steps[first] * 0.05, 10)
        return np.where(whole.any(axis=1), module, module_nc)

    def set_two(self, rows) -> list:
        """Set II's radii (sun, idlers on A and B, planet) of the rows, as
        :func:`cadgen.gears.circular.train1_set_radii`: ``q = 2 / (n - 1)``, ``r_s = 2 R q /
        (1 + q)`` (R, R i12, R i13, R for n = 3)."""
        R, i12, i13 = (self.columns[k][rows] for k in ("R", "i12", "i13"))
        q = 2.0 / (self.n - 1.0)
        sun = 2.0 * R * q / (1.0 + q)
        idler_a = R * (1.0 + i12) - sun
        idler_b = R * (i12 + i13) - idler_a
        return [sun, idler_a, idler_b, sun / q]

    def holding_tips(self, rows) -> np.ndarray:
        """(N, 4) tip radii of train 1's set I on O, A, B, C (its module, its computed shifts
        or the file's, as :func:`cadgen.solids.housings.envelope_circles`); 0 where the set
        cannot be cut. Row by row: the set's teeth and shifts are a small search each."""
        from cadgen.gears.circular import TrainAxes, holding_set_design
        from kinematics.errors import DesignError

        keys = ("sun_I", "idler_1_I", "idler_2_I", "planet_I")
        out = np.zeros((len(rows), 4))
        R, i12, i13 = (self.columns[k][rows] for k in ("R", "i12", "i13"))
        done = {}   # rows with the same train (R, i12, i13 not searched) share one answer
        for row, axes in enumerate(zip(R, i12, i13)):
            axes = tuple(float(v) for v in axes)
            if axes not in done:
                try:
                    design = holding_set_design(TrainAxes(*axes, self.n), self.requested,
                                                self.pressure_angle)
                except DesignError:
                    done[axes] = 0.0
                else:
                    done[axes] = [radius + design.module * (
                        1.0 + max(shift, self.shifts.get(key, 0.0), 0.0))
                        for radius, shift, key in zip(design.reference_radii, design.shifts,
                                                      keys)]
            out[row] = done[axes]
        return out

    def _envelope(self, module, rows, field: str, low: float, factor: float):
        """The housing's clearance or wall: searched, given in the file, or from the module."""
        searched = self.columns.get(f"housing.{field}")
        if searched is not None:
            return searched[rows]
        if self.given[field] is not None:
            return np.full(len(rows), float(self.given[field]))
        return np.maximum(low, factor * module)

    def __call__(self, rows, pair) -> np.ndarray:
        rows = np.asarray(rows)
        module_nc = pair["module"]
        module_c = self.circular_module(rows, module_nc)
        envelope = {}
        for box, module in (("gearbox1", module_c), ("gearbox2", np.maximum(module_nc, module_c))):
            clearance = self._envelope(module, rows, "clearance", 2.0, 0.75)
            wall = self._envelope(module, rows, "wall", 3.0, 1.5)
            flange = self.flanges[np.searchsorted(self.wall_steps, wall, side="right")]
            envelope[box] = clearance + wall + flange
        R, i12, i13, r = (self.columns[k][rows] for k in ("R", "i12", "i13", "r"))
        a, r_min, r_max = pair["centre_distance"], pair["radius_min"], pair["radius_max"]
        out1, out2 = envelope["gearbox1"], envelope["gearbox2"]
        one = self.holding_tips(rows)   # set I's tips on O, A, B, C where it is larger
        two = self.set_two(rows)
        derived = {("gearbox1", "O"): np.maximum(two[0] + module_c, one[:, 0]) + out1,
                   ("gearbox1", "A"): np.maximum(two[1] + module_c, one[:, 1]) + out1,
                   ("gearbox1", "B"): np.maximum(two[2] + module_c, one[:, 2]) + out1,
                   ("gearbox1", "C"): np.maximum(two[3] + module_c, one[:, 3]) + out1,
                   ("gearbox2", "C"): r_max + module_nc + out2,
                   ("gearbox2", "D"): np.maximum(a - r_min + module_nc, r + module_c) + out2,
                   ("gearbox2", "E"): r + module_c + out2}
        columns = []
        for box, axis in CIRCLE_AXES:
            given = self.columns.get(f"housing.{box}.{axis}")
            if given is not None:
                columns.append(given[rows])
            elif self.explicit[(box, axis)] is not None:
                columns.append(np.full(len(rows), float(self.explicit[(box, axis)])))
            else:
                columns.append(derived[(box, axis)])
        return np.stack(columns, axis=1)


class PlantingProblem:
    """A planting study: free parameter paths in a box, objectives, the base file's targets.

    Parameters
    ----------
    base_params : PlantingParameters
        The validated base design.
    free : sequence of (path, low, high)
        Dotted parameter paths (:func:`supported_paths`) and their bounds.
    objectives : sequence of (key, "max" | "min")
        ``"min_margin"`` or a metric key (:meth:`objective_keys`).
    samples : int
        The screen's grid samples per revolution (its accuracy knob).
    """

    kind = "planting"

    def __init__(self, base_params, free, objectives, *, samples: int = DEFAULT_SAMPLES):
        if getattr(base_params, "mechanism", None) != "planting":
            raise ValueError("PlantingProblem needs planting parameters, not "
                             f"{getattr(base_params, 'mechanism', type(base_params).__name__)!r}")
        free = [(str(p), float(lo), float(hi)) for p, lo, hi in free]
        allowed = set(supported_paths())
        bad = [p for p, _, _ in free if p not in allowed]
        if bad:
            raise ValueError("; ".join(_refusal(p) for p in bad))
        if not free:
            raise ValueError("a planting study needs at least one free path")
        for path, lo, hi in free:
            if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                raise ValueError(f"free path {path!r}: bounds [{lo:g}, {hi:g}] are not finite "
                                 "and increasing")
        keys = self.objective_keys(base_params)
        objectives = [(str(k), str(s)) for k, s in objectives]
        unknown = [k for k, s in objectives if k not in keys]
        senses = [s for _, s in objectives if s not in ("max", "min")]
        if unknown or senses or not objectives:
            raise ValueError(f"objectives {objectives!r}: each key must be one of {keys} "
                             "and each sense 'max' or 'min'")
        self.base_params = base_params
        self.free = free
        self.variables = [p for p, _, _ in free]
        self.lower = np.array([lo for _, lo, _ in free])
        self.upper = np.array([hi for _, _, hi in free])
        self.objectives = objectives
        self.samples = int(samples)
        self.spacings = [float(s) for s in base_params.field.plant_spacings]
        self.constraint_labels = metric_keys(self.spacings)
        # the "= 1" target (soil penetrations) counts in min_margin only when it fails
        self.equality = np.array([is_equality(k) for k in self.constraint_labels])
        self.metric_count = len(self.constraint_labels)
        self.cam, self.timing, self.cam_fixed = _cam_of(base_params)
        self.constraint_labels += list(CAM_LABELS) + ([CAM_FIXED] if self.cam_fixed else [])

    # ------------------------------------------------------------------ names
    @classmethod
    def objective_keys(cls, base_params) -> list[str]:
        """``"min_margin"`` and every metric key (``hole_width@185``) of the base file."""
        return ["min_margin"] + metric_keys(base_params.field.plant_spacings)

    @staticmethod
    def supported_paths(base_params=None) -> list[str]:
        return supported_paths(base_params)

    # ------------------------------------------------------------- the screen
    def _base_columns(self) -> dict:
        p = self.base_params
        curve, train = p.pitch_curve, p.train
        return {"a1": curve.a1, "b1": curve.b1, "c1": curve.c1, "d1": curve.d1, "e1": curve.e1,
                "e2": curve.e2, "f1": curve.f1_rad, "f2": curve.f2_rad, "g1": curve.g1,
                "g2": curve.g2, "teeth": float(curve.teeth), "i12": train.i12, "i13": train.i13,
                "R": train.R, "r": train.r, "L1": p.planter.L1, "L2": p.planter.L2,
                "phi0": math.radians(train.phi0_deg), "phic": math.radians(train.phic_deg),
                "n": train.n, "depth": p.field.depth}

    def designs_of(self, X) -> tuple[dict, dict]:
        """``(screen columns, targets)`` of the population ``X`` (N, n): (N,) arrays."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] != len(self.variables):
            raise ValueError(f"X must have {len(self.variables)} columns, not {X.shape[1]}")
        count = X.shape[0]
        columns = {k: np.full(count, float(v)) for k, v in self._base_columns().items()}
        targets = {k: np.full(count, float(getattr(self.base_params.targets, k)))
                   for k in _TARGET_FIELDS}
        housing = {}
        for j, path in enumerate(self.variables):
            if path in _MECHANISM_PATHS:
                name, factor = _MECHANISM_PATHS[path]
                columns[name] = X[:, j] * factor
            elif path.startswith("targets."):
                targets[path.split(".", 1)[1]] = X[:, j].copy()
            else:
                housing[path] = X[:, j].copy()
        columns["circles"] = HousingRule(self.base_params, {**housing, **{
            k: columns[k] for k in ("R", "i12", "i13", "r")}})
        return columns, targets

    def envelope_radii(self, X) -> np.ndarray:
        """The envelope circles' radii (N, 7) of the designs ``X`` (order of
        :data:`kinematics.population.CIRCLE_AXES`), as the screen sizes them (NaN where
        the pair does not close)."""
        from kinematics.population_closure import LIMACON_FIELDS, solve_pair

        columns, _ = self.designs_of(X)
        law = solve_pair({k: columns[k] for k in LIMACON_FIELDS}, columns["teeth"], self.samples)
        rows = np.arange(len(law.reason))
        pair = {"centre_distance": law.centre_distance, "radius_min": law.radius_min,
                "radius_max": law.radius_max,
                "module": law.perimeter / (np.pi * columns["teeth"])}
        radii = columns["circles"](rows, pair)
        radii[law.reason != ""] = np.nan
        return radii

    def constraints(self, values: dict, targets: dict) -> tuple[np.ndarray, np.ndarray]:
        """``(G, normalised margins)`` of the targets, each (N, m): ``G = -margin / scale``;
        where a bound is 0 (no scale) the margin itself, in its unit."""
        count = len(next(iter(values.values())))
        # the targets may be free variables: a bound per design (Targets holds the arrays)
        per_design = Targets(**targets)
        labels = self.constraint_labels[:self.metric_count]
        G = np.empty((count, len(labels)))
        normalised = np.empty_like(G)
        for j, label in enumerate(labels):
            margin, scale = margins(values[label], *bounds_of(label, per_design))
            with np.errstate(invalid="ignore", divide="ignore"):
                normalised[:, j] = margin / scale
            G[:, j] = np.where(np.isfinite(scale), -normalised[:, j], -margin)
        return G, normalised

    def _cam_constraints(self, L1, L2, lowest, cleared, room) -> np.ndarray:
        """G (N, len(CAM_LABELS) [+ 1]) of the duckbill's checks: minus the normalised margins."""
        found = {**linkage_margins(L1, L2, self.cam),
                 **timing_margins(lowest, cleared, room, self.timing)}
        columns = [-np.broadcast_to(found[k][0], np.shape(L1)) / found[k][1]
                   for k in LINKAGE_CHECKS + TIMING_CHECKS]
        if self.cam_fixed:
            columns.append(np.ones(np.shape(L1)))
        return np.stack(columns, axis=1)

    def evaluate(self, X) -> dict:
        """Screen the population ``X`` (N, n): F, G, values, valid (and the reason codes)."""
        columns, targets = self.designs_of(X)
        columns["seedling_height"] = self.timing["seedling_height"]
        result = screen(columns, self.spacings, samples=self.samples)
        values = dict(result.values)
        G, normalised = self.constraints(values, targets)
        values["min_margin"] = min_margin(normalised, self.equality)
        events = result.events
        G = np.concatenate([G, self._cam_constraints(
            columns["L1"], columns["L2"], events["lowest"], events["cleared"],
            events["seedling_room"])], axis=1)
        F = np.stack([-values[k] if sense == "max" else values[k]
                      for k, sense in self.objectives], axis=1)
        valid = result.valid & np.isfinite(F).all(axis=1) & np.isfinite(G).all(axis=1)
        F[~valid], G[~valid] = INVALID, INVALID
        return {"F": F, "G": G, "values": values, "valid": valid,
                "errors": [str(r) for r in result.reason]}

    # ------------------------------------------------------------ exact path
    def tables_at(self, x) -> dict:
        """The base file's tables (every table, defaults included) with ``x`` applied."""
        x = np.asarray(x, dtype=float).reshape(-1)
        if x.size != len(self.variables):
            raise ValueError(f"x must have {len(self.variables)} values, not {x.size}")
        tables = copy.deepcopy(self.base_params.model_dump(mode="json", exclude_none=True))
        for path, value in zip(self.variables, x):
            *parents, leaf = path.split(".")
            table = tables
            for name in parents:
                table = table.setdefault(name, {})
            table[leaf] = float(value)
        return tables

    def certify(self, x) -> dict:
        """The exact path on ``x``: validate the file, evaluate it as ``cadgen build`` does."""
        import cadgen
        from cadgen.design import build_mechanism
        from cadgen.report.content import report_dict

        try:
            params = cadgen.validate_data(self.tables_at(x))
        except cadgen.ParameterError as error:
            return {"values": {}, "margins": {}, "passed": False, "objectives": {},
                    "metrics": [], "problems": [p.as_dict() for p in error.problems],
                    "stage_problems": []}
        evaluation = cadgen.evaluate(params)
        mechanism = build_mechanism(params)
        metrics = report_dict(params, mechanism, evaluation)["metrics"]
        targets = Targets(**params.targets.model_dump())
        values, found, normalised = {}, {}, []
        for metric in metrics:
            key = metric["key"] if metric["spacing_mm"] is None else \
                f"{metric['key']}@{metric['spacing_mm']:g}"
            values[key] = float(metric["value"])
            margin, scale = margins(values[key], *bounds_of(key, targets))
            found[key] = float(margin / scale) if math.isfinite(scale) else float(margin)
            normalised.append(float(margin / scale))
        equality = [is_equality(k) for k in values]
        values["min_margin"] = float(min_margin(np.array(normalised), equality))
        cam = self._cam_constraints(
            np.array([params.planter.L1]), np.array([params.planter.L2]),
            *_exact_cam_events(params, mechanism, evaluation.events, self.timing))[0]
        found.update(zip(self.constraint_labels[self.metric_count:], (-g for g in cam)))
        staged = [p.as_dict() for p in cadgen.stage_problems(params)]
        return {"values": values, "margins": found,
                "passed": bool(evaluation.passed) and not staged,
                "objectives": {k: values[k] for k, _ in self.objectives},
                "metrics": metrics, "problems": [], "stage_problems": staged}



def _cam_of(base_params) -> tuple[dict, dict, list]:
    """The duckbill's fixed dimensions, the cam's timing (rad) and the linkage problems of
    the base file that no free path changes (:func:`cadgen.cam.design.linkage_of`)."""
    from cadgen.cam.design import linkage_of
    from kinematics.duckbill import DuckbillLinkage
    from kinematics.errors import DesignError

    cam, planter = base_params.cam, base_params.planter
    d0, blade = cam.closed_half_angle_rad, cam.duckbill.blade_length
    mouth = cam.pot_diameter + 2.0 * cam.mouth_clearance
    opening = (float(DuckbillLinkage.opening_for_mouth(mouth, blade, d0))
               if cam.opening_angle_deg is None else math.radians(cam.opening_angle_deg))
    rod_arm = cam.lever.rod_arm
    # the push rod's stroke does not depend on L1 or L2 (the hinges move with them)
    stroke = DuckbillLinkage(
        L1=planter.L1, L2=planter.L2, blade_length=blade, closed_half_angle=d0,
        blade_crank=cam.duckbill.blade_crank, blade_link=cam.duckbill.blade_link,
        base_radius=cam.base_radius, roller_arm=cam.lever.roller_arm,
        rod_arm=planter.L1 - cam.base_radius if rod_arm is None else rod_arm,
        opening_angle=opening, required_mouth=mouth).stroke if math.isfinite(opening) else 0.0
    # (no opening gives the mouth: a fixed problem, CAM_FIXED fails every design; the lever's
    # margin is then taken for no stroke, so it stays a number)
    dimensions = {"blade_length": blade, "closed_half_angle": d0,
                  "blade_crank": cam.duckbill.blade_crank, "blade_link": cam.duckbill.blade_link,
                  "base_radius": cam.base_radius, "roller_arm": cam.lever.roller_arm,
                  "rod_arm": rod_arm, "stroke": stroke}
    t = cam.timing
    timing = {"seedling_height": cam.seedling_height,
              "opening_offset": math.radians(t.opening_offset_deg),
              "opening_duration": math.radians(t.opening_duration_deg),
              "closing_delay": math.radians(t.closing_delay_deg),
              "closing_duration": math.radians(t.closing_duration_deg),
              "closed_before_catch": math.radians(t.closed_before_catch_deg)}
    try:
        linkage_of(base_params)
        fixed = []
    except DesignError as error:
        fixed = [p.code for p in error.problems if p.code not in _LINKAGE_CODES]
    return dimensions, timing, fixed


def _exact_cam_events(params, mechanism, events, timing) -> tuple:
    """``(lowest, cleared, room)`` (1,) arrays of the exact path, for the cam's margins.

    ``cleared`` as :func:`kinematics.cam.cam_timing` finds it (with every phase of length 0,
    so only the seedling can stop it); ``room`` the highest the tip rises after the exit (a
    scan, polished by Brent's method), above the soil plus the seedling height.
    """
    from kinematics.cam import cam_timing
    from kinematics.errors import DesignError

    try:
        cleared = cam_timing(mechanism, events, seedling_height=timing["seedling_height"],
                             opening_offset=0.0, opening_duration=0.0, closing_delay=0.0,
                             closing_duration=0.0, closed_before_catch=0.0
                             ).events["seedling_cleared"]
    except DesignError:
        cleared = math.nan
    from kinematics.scalar import minimize_scalar

    def height(phi):
        return mechanism.positions(np.atleast_1d(phi), points=("N",))["N"][:, 1]

    scan = np.linspace(events.exit, 2.0 * math.pi, 7201)
    heights = height(scan)
    k = int(heights.argmax())
    highest = float(heights[k])
    if 0 < k < len(scan) - 1:       # between two samples: the maximum itself (Brent)
        found = minimize_scalar(lambda phi: -float(height(phi)[0]),
                                bounds=(scan[k - 1], scan[k + 1]), options={"xatol": 1e-12})
        highest = max(highest, -found.fun)
    room = highest - events.soil_level - timing["seedling_height"]
    return np.array([events.lowest]), np.array([cleared]), np.array([room])
