"""The population screen: the seven planting metrics of N designs at once (pure numpy).

An optimiser asks for thousands of designs; the exact path
(:func:`kinematics.evaluation.evaluate_planting`: certified minima, Brent roots, FCL when
there are solids) takes tens of milliseconds each. The screen evaluates the same model
for a whole population in arrays ``(N, K)``: every parameter of the mechanism may differ
per design (the ten limacon coefficients, teeth, i12, i13, R, r, L1, L2, phi0, phic, n,
depth, the seven envelope-circle radii); the plant spacings and targets are shared.

Method, and what it gives up:

* the closure by Newton on the periodic trapezoid rule over the shared grid of ``K``
  carrier angles (:mod:`kinematics.population_closure`), checked against ``K/2``; the
  attitude from the ratio law's Fourier series (one inverse FFT on the grid);
* the tip path on the grid, its lowest and highest points polished by Newton on the
  closed-form slope, the soil crossings bracketed on the grid (with the polished lowest
  point in it) and located by safeguarded Newton (:mod:`kinematics.population_tip`);
* the ground clearance in closed form, the arm distance by its own grid search
  (:mod:`kinematics.population_clearance`).

A design whose grid does not resolve its ratio law is screened again on twice the grid
(up to ``max_samples``); what the screen still cannot evaluate is invalid with a reason
code and NaN metrics, never a plausible number: ``pointed_pitch_curve``,
``tiny_intermediate_radius`` (the cutting limits the file loader refuses),
``closure_not_converged``, ``closure_unresolved``, ``no_soil_crossing``. Two soil crossings
closer together than a grid step (a tangency of the soil line) are not seen: the
penetration count is the grid's.

``n`` (the central shaft's speed ratio) does not enter any metric (it sets the converted
ratios of train 1 only); it is accepted so a population can carry it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .population_cam import seedling_clearance
from .population_clearance import CIRCLE_AXES, arm_distance, ground_clearance
from .population_closure import LIMACON_FIELDS, pair_at, solve_pair
from .population_tip import TrainArrays, refine_crossing, refine_extreme, tip_at, tip_on_grid

__all__ = ["DESIGN_FIELDS", "CIRCLE_AXES", "REASONS", "TOLERANCES", "ScreenResult", "screen",
           "metric_keys", "spacing_key", "DEFAULT_SAMPLES", "MAX_SAMPLES"]

TWO_PI = 2.0 * np.pi

#: Every per-design input of :func:`screen` (angles in rad; ``circles`` is (N, 7) apart).
DESIGN_FIELDS = LIMACON_FIELDS + ("teeth", "i12", "i13", "R", "r", "L1", "L2", "phi0", "phic",
                                  "n", "depth")
#: The cam's events of :attr:`ScreenResult.events`.
EVENT_KEYS = ("lowest", "exit", "cleared", "seedling_room")
#: Why a design is invalid (the empty string: valid).
REASONS = ("pointed_pitch_curve", "tiny_intermediate_radius", "closure_not_converged",
           "closure_unresolved", "no_soil_crossing")
#: Grid samples per revolution: the accuracy knob (docs/accuracy.md: error against time).
DEFAULT_SAMPLES = 256
#: The screen's stated accuracy at the default grid, |screen - exact| per metric (mm, deg;
#: penetrations exactly): tests/test_population.py holds every design to it. Measured on
#: 1,000 random designs round the paper's (562 evaluated, 438 refused by both paths): at
#: most 3e-9 mm for the tip-path metrics and the ground clearance, 1e-9 mm for the module,
#: 4e-10 mm for the arm distance; on wilder designs whose arms nearly touch (a minimum with
#: a kink, its weak spot) the arm distance was within 2.2e-5 mm, always on the high side.
TOLERANCES = {"trajectory_height": 1e-6, "hole_width": 1e-6, "hole_verticality": 1e-6,
              "angle_difference": 1e-6, "arm_distance": 1e-4, "ground_clearance": 1e-6,
              "module": 1e-7, "soil_penetrations": 0.0}
#: The finest grid a design whose law the default grid does not resolve is screened on.
MAX_SAMPLES = 2048


def spacing_key(metric: str, spacing: float) -> str:
    """``hole_width@185``: a per-spacing metric's key, the spacing written ``%g`` (report.json)."""
    return f"{metric}@{spacing:g}"


def metric_keys(spacings) -> list:
    """The metric keys of the screen's values, in report.json's order."""
    keys = ["trajectory_height"]
    for s in spacings:
        keys += [spacing_key("hole_width", s), spacing_key("hole_verticality", s)]
    return keys + ["angle_difference", "arm_distance", "ground_clearance", "module",
                   "soil_penetrations"]


@dataclass(frozen=True)
class ScreenResult:
    """The screen's answer for N designs.

    Attributes
    ----------
    values : dict of (N,) float
        Metric values by key (:func:`metric_keys`): mm, deg (angle difference), count
        (soil penetrations); NaN where invalid.
    valid : (N,) bool
    reason : (N,) object
        "" where valid, else one of :data:`REASONS`.
    samples : (N,) int
        The grid each design was screened on.
    events : dict of (N,) float
        With a ``seedling_height`` column, what the cam's timing needs
        (:func:`kinematics.population_cam.seedling_clearance`): ``lowest``, ``exit``,
        ``cleared`` (rad, the catching revolution's frame) and ``seedling_room`` (mm).
    """

    values: dict
    valid: np.ndarray
    reason: np.ndarray
    samples: np.ndarray
    events: dict


def _columns(designs: dict) -> tuple[dict, np.ndarray, int]:
    missing = [k for k in DESIGN_FIELDS + ("circles",) if k not in designs]
    if missing:
        raise ValueError(f"designs lack the fields {missing}")
    count = max(np.size(designs[k]) for k in DESIGN_FIELDS)
    if callable(designs["circles"]):
        circles = designs["circles"]
    else:
        circles = np.atleast_2d(np.asarray(designs["circles"], dtype=float))
        count = max(count, circles.shape[0])
    columns = {}
    for k in DESIGN_FIELDS:
        value = np.asarray(designs[k], dtype=float)
        if value.size not in (1, count):
            raise ValueError(f"designs[{k!r}] has {value.size} values, not 1 or {count}")
        columns[k] = np.broadcast_to(value.reshape(-1), (count,)).copy()
    if "seedling_height" in designs:
        columns["seedling_height"] = np.broadcast_to(np.asarray(
            designs["seedling_height"], dtype=float).reshape(-1), (count,)).copy()
    if callable(circles):
        return columns, circles, count
    if circles.shape[1] != len(CIRCLE_AXES) or circles.shape[0] not in (1, count):
        raise ValueError(f"designs['circles'] must be (N, {len(CIRCLE_AXES)}), not {circles.shape}")
    fixed = np.broadcast_to(circles, (count, len(CIRCLE_AXES))).copy()
    return columns, (lambda rows, pair: fixed[rows]), count


def screen(designs: dict, spacings, *, samples: int = DEFAULT_SAMPLES,
           max_samples: int = MAX_SAMPLES) -> ScreenResult:
    """The planting metrics of every design in ``designs``.

    Parameters
    ----------
    designs : dict
        ``(N,)`` arrays (or scalars, broadcast) for every name of :data:`DESIGN_FIELDS`
        (``f1``, ``f2``, ``phi0``, ``phic`` in rad; optional ``seedling_height``, mm, for the
        cam's timing: :attr:`ScreenResult.events`), and ``circles``: the envelope circles'
        radii (mm) in the order of :data:`CIRCLE_AXES`, (N, 7), or, since a housing is
        sized round its gears, a callable ``circles(rows, pair) -> (len(rows), 7)`` given
        the designs' indices and their closed pairs: ``pair`` holds (len(rows),) arrays
        ``centre_distance``, ``radius_min``, ``radius_max`` and ``module`` (mm).
    spacings : sequence of float
        Plant spacings (mm), shared.
    samples : int
        Grid samples per revolution (a multiple of 4).
    max_samples : int
        Designs whose law ``samples`` does not resolve are screened again on doubled grids
        up to this.
    """
    columns, circles, count = _columns(designs)
    spacings = [float(s) for s in spacings]
    keys = metric_keys(spacings)
    values = {k: np.full(count, np.nan) for k in keys}
    events = {k: np.full(count, np.nan) for k in EVENT_KEYS} if "seedling_height" in columns \
        else {}
    reason = np.full(count, "", dtype=object)
    used = np.zeros(count, dtype=int)
    pending = np.arange(count)
    grid = samples
    while pending.size:
        part = {k: v[pending] for k, v in columns.items()}
        found, why = _screen_on_grid(part, circles, pending, spacings, grid)
        retry = (why == "closure_unresolved") & (grid * 2 <= max_samples)
        done = ~retry
        rows = pending[done]
        for k in keys:
            values[k][rows] = found[k][done]
        for k in events:
            events[k][rows] = found[k][done]
        reason[rows] = why[done]
        used[rows] = grid
        pending, grid = pending[retry], grid * 2
    valid = reason == ""
    for k in list(keys) + list(events):
        (values if k in values else events)[k][~valid] = np.nan
    return ScreenResult(values=values, valid=valid, reason=reason, samples=used, events=events)


def _screen_on_grid(designs: dict, circles, indices, spacings, samples: int):
    """The metrics of designs on one grid: ``({key: (n,)}, reason (n,))``."""
    count = len(designs["L1"])
    coefficients = {k: designs[k] for k in LIMACON_FIELDS}
    law = solve_pair(coefficients, designs["teeth"], samples)
    reason = law.reason.copy()
    out = {k: np.full(count, np.nan) for k in metric_keys(spacings) + list(EVENT_KEYS)}
    out["module"] = law.perimeter / (np.pi * designs["teeth"])
    rows = np.flatnonzero(reason == "")
    if rows.size == 0:
        return out, reason
    part = {k: v[rows] for k, v in designs.items()}
    train = TrainArrays(part, pair_at(law, rows))
    found, why = _tip_metrics(train, part["depth"], spacings, samples,
                              part.get("seedling_height"))
    pair = {"centre_distance": law.centre_distance[rows], "radius_min": law.radius_min[rows],
            "radius_max": law.radius_max[rows], "module": out["module"][rows]}
    radii = np.asarray(circles(indices[rows], pair), dtype=float)
    found["ground_clearance"] = ground_clearance(part, train, radii, found.pop("soil"))
    found["arm_distance"] = arm_distance(train, samples)
    reason[rows] = why
    for k, v in found.items():
        out[k][rows] = v
    return out, reason


def _tip_metrics(train: TrainArrays, depth, spacings, samples: int, seedling_height=None):
    """Trajectory height, holes, angle difference, penetrations and the soil level (and the
    cam's events with ``seedling_height``)."""
    h = TWO_PI / samples
    grid = tip_on_grid(train, samples)
    y = grid["y"]
    count = y.shape[0]
    rows = np.arange(count)
    low_k, high_k = y.argmin(axis=1), y.argmax(axis=1)
    lowest, y_low = refine_extreme(train, low_k * h, y[rows, low_k], 1.0, h)
    _, y_high = refine_extreme(train, high_k * h, y[rows, high_k], -1.0, h)
    height = y_high - y_low
    soil = y_low + depth
    reason = np.where(depth < height, "", "no_soil_crossing").astype(object)

    # the revolution centred on the lowest point, on the grid, the polished lowest point
    # standing in for its sample (so a shallow soil line below every sample is still crossed)
    half = samples // 2
    index = low_k[:, None] - half + np.arange(samples + 1)
    phi_window = index * h
    y_window = np.take_along_axis(y, np.mod(index, samples), axis=1)
    phi_window[:, half], y_window[:, half] = lowest, y_low
    above = y_window > soil[:, None]
    down = above[:, :-1] & ~above[:, 1:]
    up = ~above[:, :-1] & above[:, 1:]
    before = np.where(down[:, :half], np.arange(half), -1).max(axis=1)
    after = np.where(up[:, half:], np.arange(half, samples), samples).min(axis=1)
    reason[(reason == "") & ((before < 0) | (after >= samples))] = "no_soil_crossing"
    ok = reason == ""
    entry_k = np.where(ok, before, 0)
    exit_k = np.where(ok, after, half)
    brackets = np.stack([entry_k, exit_k], axis=1)
    low = np.take_along_axis(phi_window, brackets, axis=1)
    high = np.take_along_axis(phi_window, brackets + 1, axis=1)
    g_low = np.take_along_axis(y_window, brackets, axis=1) - soil[:, None]
    g_high = np.take_along_axis(y_window, brackets + 1, axis=1) - soil[:, None]
    crossing = refine_crossing(train, low, high, g_low, g_high, soil[:, None])

    events = np.concatenate([crossing, lowest[:, None]], axis=1)     # entry, exit, lowest
    at = tip_at(train, events)
    x, psi = at["x"], at["psi"]
    out = {"trajectory_height": height, "soil": soil,
           "angle_difference": np.degrees(np.abs(psi[:, 1] - psi[:, 0])),
           "soil_penetrations": down.sum(axis=1).astype(float)}
    for s in spacings:
        absolute = x + (s / np.pi) * events
        out[spacing_key("hole_width", s)] = np.abs(absolute[:, 1] - absolute[:, 0])
        out[spacing_key("hole_verticality", s)] = np.abs(
            0.5 * (absolute[:, 0] + absolute[:, 1]) - absolute[:, 2])
    if seedling_height is not None:
        found = seedling_clearance(train, y, lowest, crossing[:, 1], soil, seedling_height)
        out.update(zip(EVENT_KEYS, found))
    for k in out:
        if k != "soil":
            out[k] = np.where(ok, out[k], np.nan)
    return out, reason
