"""The pricking mechanism as a design problem: move the type-value points, keep the gears cuttable.

A drawn loop like kernel-a inverts cleanly but gives concave gears; moving its points a
few millimetres may make all four pitch curves convex. :class:`PrickingProblem` states
that search for the optimiser (the DesignProblem protocol of
:mod:`cadgen.optimize.problem`): the variables are the displacements (dx, dy) of the
chosen type-value points within a square box, and every design is the exact inverse
design of ``cadgen build`` (:func:`cadgen.design.pricking_design` on the moved points),
about 60 ms each. There is no vectorised screen for this kind: the runner spreads a
population over processes.

What decides the verdict, and so the constraints (``G <= 0`` feasible), are the
design's failing findings: a concave stretch of any pitch curve fails the report
(``concave_pitch_curve``, whatever ``gears.cutter`` says: a pinion cutter can follow a
gentle concave stretch, but the report counts it as a failure all the same), a tip loop
the tabulated pitch curves do not reproduce (``forward_check_deviation``), and a total
ratio that falls to ``gears.min_ratio`` (the design refuses it: ``ratio_not_positive``).
A design the exact path refuses for any other reason is invalid, never a number.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping

import numpy as np

from kinematics.errors import MechanismError
from kinematics.pricking import FORWARD_TOLERANCE

__all__ = ["PrickingProblem", "OBJECTIVE_KEYS", "GEAR_NAMES", "VALUE_KEYS", "INVALID",
           "BOX_TOL"]

#: The objectives a pricking study may name, each a key of ``values``.
OBJECTIVE_KEYS = ("convexity", "ratio_margin", "min_margin", "displacement")
#: The four non-circular gears, in the train's order (report.json's ``pitch_curves``).
GEAR_NAMES = ("sun", "intermediate 1", "intermediate 2", "planet")
#: Every key of ``values``, in the order of the tables.
VALUE_KEYS = (*(f"curvature_min@{name.replace(' ', '_')}" for name in GEAR_NAMES), "convexity",
              "ratio_min", "ratio_margin", "forward_deviation", "forward_margin", "min_margin",
              "displacement")
#: F and G of a design the exact path cannot evaluate (pymoo needs finite numbers).
INVALID = 1e6
#: A displacement may pass the box by this fraction of it (round-off of the optimiser's
#: repair); anything further is refused, not clipped.
BOX_TOL = 1e-9
#: The design's own test is ``ratio_min > gears.min_ratio``; the screen asks only for a
#: positive ratio (a gear exists at all) so that a low ratio is graded by its constraint
#: instead of being a cliff. The values are the same: min_ratio is read by that test alone.
_SCREEN_MIN_RATIO = 0.0


def _label(gear_name: str) -> str:
    return gear_name.replace(" ", "_")


def _point_indices(free, count: int) -> tuple[float, list[int]]:
    """``(box, 0-based indices)`` from the study's ``{box = 3.0, points = [3, 4]}`` spec."""
    if isinstance(free, Mapping) and "trajectory.points" in free:
        free = free["trajectory.points"]
    elif isinstance(free, (list, tuple)) and len(free) == 1 and len(free[0]) == 2:
        path, free = free[0]
        if path != "trajectory.points":
            raise ValueError(f"a pricking study moves trajectory.points, not {path!r}")
    if not isinstance(free, Mapping) or "box" not in free:
        raise ValueError(f"the free points need a spec {{box = 3.0, points = [...]}}, not {free!r}")
    box = free["box"]
    if isinstance(box, bool) or not isinstance(box, (int, float)) or not (
            math.isfinite(box) and box > 0):
        raise ValueError(f"box = {box!r} must be a positive number of mm")
    numbers = free.get("points", list(range(1, count + 1)))
    bad = [n for n in numbers if isinstance(n, bool) or not isinstance(n, int)
           or not 1 <= n <= count]
    if bad or len(set(numbers)) != len(numbers) or not numbers:
        raise ValueError(f"points = {numbers!r} must be distinct numbers from 1 to {count} "
                         f"(Q1..Q{count}, 1-based)")
    return float(box), [n - 1 for n in numbers]


class PrickingProblem:
    """Move chosen type-value points of a pricking design within a box (DesignProblem).

    Parameters
    ----------
    base_params : PrickingParameters
        The validated base design.
    free : mapping
        ``{"box": 3.0}`` (every point) or ``{"box": 3.0, "points": [3, 4, 5]}`` (1-based,
        Q1..Qm); ``{"trajectory.points": {...}}`` is read the same.
    objectives : list of (key, "max" | "min")
        Keys from :data:`OBJECTIVE_KEYS`.

    Figures (``values``), all from the exact design:

    - ``curvature_min@<gear>``: each pitch curve's smallest signed curvature (1/mm,
      > 0 convex), as report.json's ``curvature_min_per_mm``;
    - ``convexity``: the smallest over the four gears of curvature times the gear's mean
      radius (its pitch perimeter / 2 pi): dimensionless, 1 for a circle, so gears and
      designs of any size compare; > 0 means all four convex;
    - ``ratio_min``, ``ratio_margin = (ratio_min - min_ratio) / min_ratio``;
    - ``forward_deviation`` (mm), ``forward_margin = (tol - deviation) / tol``;
    - ``min_margin``: the smallest of convexity, ratio_margin and forward_margin (every
      requirement with the most room, as for the planting kind);
    - ``displacement``: the largest distance a point moved, mm.
    """

    kind = "pricking"

    def __init__(self, base_params, free, objectives):
        if getattr(base_params, "mechanism", None) != "pricking":
            raise ValueError("PrickingProblem needs a pricking design, not "
                             f"{getattr(base_params, 'mechanism', type(base_params).__name__)!r}")
        self.base_params = base_params
        self._base_points = np.asarray(base_params.trajectory.points, dtype=float)
        self.box, self._moved = _point_indices(free, len(self._base_points))
        self.variables = [f"Q{k + 1}.{axis}" for k in self._moved for axis in ("x", "y")]
        self.lower = np.full(len(self.variables), -self.box)
        self.upper = np.full(len(self.variables), self.box)
        self.objectives = [(key, sense) for key, sense in objectives]
        known = self.objective_keys(base_params)
        for key, sense in self.objectives:
            if key not in known:
                raise ValueError(f"unknown pricking objective {key!r}: one of {', '.join(known)}")
            if sense not in ("max", "min"):
                raise ValueError(f"objective {key!r}: sense {sense!r} must be 'max' or 'min'")
        self.constraint_labels = ([f"convex@{_label(g)}" for g in GEAR_NAMES]
                                  + ["ratio_min", "forward_check"])
        self.min_ratio = float(base_params.gears.min_ratio)

    @classmethod
    def objective_keys(cls, base_params) -> list[str]:
        return list(OBJECTIVE_KEYS)

    # -- the moved design --------------------------------------------------------------

    def _checked(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.shape != (len(self.variables),):
            raise ValueError(f"a design needs {len(self.variables)} displacements "
                             f"({', '.join(self.variables[:4])}...), not shape {x.shape}")
        limit = self.box * (1.0 + BOX_TOL)
        outside = np.flatnonzero(~(np.abs(x) <= limit))   # NaN is outside too
        if outside.size:
            k = int(outside[0])
            raise ValueError(f"{self.variables[k]} = {x[k]!r} mm is outside the box "
                             f"[-{self.box:g}, {self.box:g}] mm")
        return x

    def points_at(self, x) -> np.ndarray:
        """The type-value points with the displacements ``x`` applied, (m, 2) mm, to 1e-9 mm:
        a file holds a point as a person writes it (-3.14, not the -3.1399999999999997 that
        -5.0 + 1.86 gives), and the screen and the exact path read the same points."""
        x = self._checked(x)
        points = self._base_points.copy()
        points[self._moved] += x.reshape(-1, 2)
        return np.round(points, 9)

    def tables_at(self, x) -> dict:
        """The base design's tables (every value, as a file would hold it) with ``x`` applied."""
        tables = copy.deepcopy(self.base_params.model_dump(mode="json", exclude_none=True))
        tables["trajectory"]["points"] = [[float(px), float(py)] for px, py in self.points_at(x)]
        return tables

    def _screen_params(self, x):
        """The base model with the moved points: what :func:`pricking_design` reads.

        ``model_copy`` skips validation (the points are finite pairs by construction);
        the gears keep every setting but the refusal threshold (see _SCREEN_MIN_RATIO).
        """
        params = self.base_params
        points = tuple((float(px), float(py)) for px, py in self.points_at(x))
        return params.model_copy(update={
            "trajectory": params.trajectory.model_copy(update={"points": points}),
            "gears": params.gears.model_copy(update={"min_ratio": _SCREEN_MIN_RATIO})})

    # -- figures -----------------------------------------------------------------------

    def _figures(self, design, x) -> dict:
        """Every value of one design, from its exact :class:`PrickingDesign`."""
        return self._figures_of(
            {gear.name: (gear.curvature_min, gear.perimeter) for gear in design.gears},
            design.ratio_min, design.forward_deviation, x)

    def _figures_of(self, curves: Mapping, ratio_min: float, forward_deviation: float,
                    x) -> dict:
        """The values from ``{gear: (curvature_min 1/mm, perimeter mm)}`` and the checks."""
        values = {}
        normalised = []
        for name in GEAR_NAMES:
            curvature, perimeter = curves[name]
            values[f"curvature_min@{_label(name)}"] = float(curvature)
            normalised.append(float(curvature) * float(perimeter) / (2.0 * math.pi))
        values["convexity"] = min(normalised)
        values["ratio_min"] = float(ratio_min)
        values["ratio_margin"] = (float(ratio_min) - self.min_ratio) / self.min_ratio
        values["forward_deviation"] = float(forward_deviation)
        values["forward_margin"] = (FORWARD_TOLERANCE - forward_deviation) / FORWARD_TOLERANCE
        values["min_margin"] = min(values["convexity"], values["ratio_margin"],
                                   values["forward_margin"])
        moves = self.points_at(x) - self._base_points   # as written: to 1e-9 mm
        values["displacement"] = float(np.hypot(moves[:, 0], moves[:, 1]).max())
        values["_normalised"] = normalised
        return values

    def _constraints(self, values) -> np.ndarray:
        """Minus the normalised margins, in :attr:`constraint_labels`' order."""
        return -np.array(values["_normalised"] + [values["ratio_margin"],
                                                  values["forward_margin"]])

    def _objectives(self, values) -> np.ndarray:
        return np.array([values[key] if sense == "min" else -values[key]
                         for key, sense in self.objectives])

    # -- the protocol ------------------------------------------------------------------

    def evaluate(self, X) -> dict:
        """Every row of ``X`` (N, n) through the exact inverse design, one after another.

        Returns ``{"F": (N, k), "G": (N, m), "values": {key: (N,)}, "valid": (N,),
        "errors": [code or ""]}``; an invalid design has F and G of :data:`INVALID` and
        NaN values, and the error code that refused it.
        """
        from cadgen.design import pricking_design, pricking_field

        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != len(self.variables):
            raise ValueError(f"X must have shape (N, {len(self.variables)}), not {X.shape}")
        for row in X:                      # refuse the whole batch before any work
            self._checked(row)
        count = len(X)
        F = np.full((count, len(self.objectives)), INVALID)
        G = np.full((count, len(self.constraint_labels)), INVALID)
        valid = np.zeros(count, dtype=bool)
        errors = [""] * count
        columns = {key: np.full(count, np.nan) for key in VALUE_KEYS}
        for n, x in enumerate(X):
            params = self._screen_params(x)
            try:
                # unwrapped: the cache would hold a design per candidate for nothing
                design = pricking_design.__wrapped__(params)
                pricking_field(params, design)     # validation runs it too: a field that
            except MechanismError as error:        # cannot be computed refuses the file
                problems = getattr(error, "problems", None)
                errors[n] = problems[0].code if problems else type(error).__name__
                continue
            values = self._figures(design, x)
            for key in VALUE_KEYS:
                columns[key][n] = values[key]
            F[n], G[n], valid[n] = self._objectives(values), self._constraints(values), True
        return {"F": F, "G": G, "values": columns, "valid": valid, "errors": errors}

    def certify(self, x) -> dict:
        """The exact path of ``cadgen build``: validate the moved file, evaluate, report.

        ``metrics`` holds report.json's pricking sections (linkage, gears, verification,
        field, findings); ``passed`` is the report's verdict on the design: no problem, no
        failing finding (``undercut`` is a prediction the teeth stage decides: a warning),
        no ``stage_problems`` (what validation attaches for a build stage to refuse).
        The figures are read back from those sections, not from the screen.
        """
        import cadgen
        from cadgen.design import pricking_field
        from cadgen.report.content import PREDICTED_FINDINGS
        from cadgen.report.pricking import pricking_report

        tables = self.tables_at(x)
        try:
            params = cadgen.validate_data(tables, source="optimised design")
        except cadgen.ParameterError as error:
            problems = [{"path": p.path, "code": p.code, "message": p.message}
                        for p in error.problems]
            return {"values": {}, "margins": {}, "objectives": {}, "passed": False,
                    "metrics": {}, "findings": [], "problems": problems, "stage_problems": []}
        design = cadgen.evaluate(params)
        sections = pricking_report(params, design, pricking_field(params, design))
        curves = {g["name"]: (g["curvature_min_per_mm"], g["perimeter_mm"])
                  for g in sections["gears"]["pitch_curves"]}
        values = self._figures_of(curves, sections["gears"]["total_ratio_min"],
                                  sections["verification"]["forward_deviation_mm"],
                                  self._checked(x))
        margins = dict(zip(self.constraint_labels, (-self._constraints(values)).tolist()))
        failing = [f for f in sections["findings"] if f["code"] not in PREDICTED_FINDINGS]
        # problems a build stage would refuse the file for (none known for this kind today:
        # the pricking checks raise or are findings), kept so a build of best.toml agrees
        staged = [p.as_dict() for p in cadgen.stage_problems(params)]
        passed = bool(sections["verified"] and not failing and not staged
                      and all(m >= 0.0 for m in margins.values()))
        values.pop("_normalised")
        return {"values": values, "margins": margins,
                "objectives": {key: values[key] for key, _ in self.objectives},
                "passed": passed, "metrics": sections, "findings": sections["findings"],
                "problems": [], "stage_problems": staged}
