"""The duckbill's checks of N planting designs as margins: the linkage and the cam's timing.

The file loader attaches these problems to a design as build-stage problems (stage
``cam``: :meth:`kinematics.duckbill.DuckbillLinkage.design` and
:func:`kinematics.cam.cam_timing`), and ``cadgen build`` refuses a design that has them, so
an optimiser must see them as constraints. Each check becomes a margin, >= 0 where the
exact check passes, with a scale that normalises it (as :mod:`kinematics.margins`):

* linkage, closed forms in L1 and L2 (the blades' own checks, mouth, crank and link, do
  not depend on them: a study judges them once, on its base file):
  ``blade_fits`` ``L2 - blade_length`` (scale blade_length); ``lever_fits`` the rod arm
  ``L1 - base_radius`` (scale base_radius); ``lever_angle`` ``rod_arm sin 45deg - stroke``
  (scale stroke); ``push_rod`` ``-roller_arm - top``, ``top`` the push-rod end's height
  ``-L2 + l_b cos d0 + sqrt(ell^2 - (e - c)^2)`` (scale roller_arm);
* timing, from the tip path: ``seedling`` the highest the tip rises after its exit up to
  the next catch, above ``soil + seedling_height`` (scale seedling_height, or 1 mm);
  ``opening_start`` ``lowest + offset`` (rad, scale 2 pi); ``phase_order`` ``cleared +
  delay - (lowest + offset + opening)``; ``closes_in_time`` ``2 pi - closed_before_catch
  - (cleared + delay + closing)``, ``cleared`` where the tip first clears the seedling.
"""

from __future__ import annotations

import numpy as np

from .population_tip import TrainArrays, refine_crossing, refine_extreme

__all__ = ["LINKAGE_CHECKS", "TIMING_CHECKS", "seedling_clearance", "linkage_margins",
           "timing_margins"]

TWO_PI = 2.0 * np.pi
#: The lever may turn at most this much (rad), as kinematics.duckbill.
MAX_LEVER_ANGLE = np.radians(45.0)
LINKAGE_CHECKS = ("blade_fits", "lever_fits", "lever_angle", "push_rod")
TIMING_CHECKS = ("seedling", "opening_start", "phase_order", "closes_in_time")


def seedling_clearance(train: TrainArrays, y_grid, lowest, exit_, soil, seedling_height):
    """Where the tip first clears the seedling after its exit, and how high it rises.

    As :func:`kinematics.cam.cam_timing`: from the exit up to the next catch (carrier angle
    2 pi, the revolution whose lowest point is in [0, 2 pi)), the first angle where the
    tip is ``seedling_height`` above the soil, located by safeguarded Newton in its grid
    bracket; ``room`` is how far the tip rises after the exit above that level, its
    highest sample polished by Newton (< 0: never cleared, and ``cleared`` is NaN).

    Returns
    -------
    lowest, exit, cleared, room : (N,) float
        Angles in the frame of the catching revolution (rad); room in mm.
    """
    count, samples = y_grid.shape
    h = TWO_PI / samples
    shift = lowest - np.mod(lowest, TWO_PI)
    lowest, exit_ = lowest - shift, exit_ - shift
    target = soil + seedling_height
    phi = np.arange(samples + 1) * h
    y = np.concatenate([y_grid, y_grid[:, :1]], axis=1)            # 2 pi is the catch again
    after = phi[None, :] > exit_[:, None]
    room = _highest_after(train, y, after) - target
    reached = after & (y >= target[:, None])
    cleared_any = reached.any(axis=1)
    first = np.where(cleared_any, reached.argmax(axis=1), samples)
    rows = np.arange(count)
    previous = np.maximum(first - 1, 0)
    # the bracket starts at the exit itself when the sample before is not after it
    from_exit = phi[previous] <= exit_
    low = np.where(from_exit, exit_, phi[previous])
    g_low = np.where(from_exit, soil - target, y[rows, previous] - target)
    high, g_high = phi[first], y[rows, first] - target
    cleared = refine_crossing(train, low[:, None], high[:, None], g_low[:, None],
                              g_high[:, None], target[:, None])[:, 0]
    cleared = np.where(g_low >= 0.0, low, cleared)
    return lowest, exit_, np.where(cleared_any, cleared, np.nan), room


def _highest_after(train, y, after):
    """The highest of the samples ``after`` (N, K+1), polished by Newton on the closed-form
    slope when it is a local maximum between two samples after too (at the window's ends it
    stays a sample: the exact check's scan ends there as well)."""
    rows = np.arange(y.shape[0])
    samples = y.shape[1] - 1
    masked = np.where(after, y, -np.inf)
    k = masked.argmax(axis=1)
    best = masked[rows, k]
    left = masked[rows, np.maximum(k - 1, 0)]
    right = masked[rows, np.minimum(k + 1, samples)]
    inside = (k > 0) & (k < samples) & (left <= best) & (right <= best)
    h = TWO_PI / samples
    _, polished = refine_extreme(train, k * h, best, -1.0, h)
    return np.where(inside, polished, best)


def linkage_margins(L1, L2, cam: dict) -> dict:
    """``{check: (margin, scale)}`` of the linkage checks that depend on L1 and L2.

    ``cam`` holds ``blade_length``, ``closed_half_angle`` (rad), ``blade_crank``,
    ``blade_link``, ``base_radius``, ``roller_arm``, ``rod_arm`` (None: ``L1 - base_radius``)
    and ``stroke`` (the push rod's travel, which L1 and L2 do not change).
    """
    L1, L2 = np.asarray(L1, dtype=float), np.asarray(L2, dtype=float)
    blade, d0 = cam["blade_length"], cam["closed_half_angle"]
    crank, link = cam["blade_crank"], cam["blade_link"]
    rod_arm = L1 - cam["base_radius"] if cam["rod_arm"] is None else np.full_like(L1, cam["rod_arm"])
    reach = blade * np.sin(d0) - crank
    top = -L2 + blade * np.cos(d0) + np.sqrt(max(link**2 - reach**2, 0.0))
    return {"blade_fits": (L2 - blade, blade),
            "lever_fits": (rod_arm, cam["base_radius"]),
            "lever_angle": (rod_arm * np.sin(MAX_LEVER_ANGLE) - cam["stroke"],
                            max(cam["stroke"], 1e-9)),
            "push_rod": (-cam["roller_arm"] - top, cam["roller_arm"])}


def timing_margins(lowest, cleared, room, timing: dict) -> dict:
    """``{check: (margin, scale)}`` of the cam's timing (angles rad, ``room`` mm).

    ``timing`` holds ``seedling_height`` (mm), ``opening_offset``, ``opening_duration``,
    ``closing_delay``, ``closing_duration``, ``closed_before_catch`` (rad). Where the tip
    never clears the seedling the phases are undefined: their margins are then the
    seedling's, normalised (failing with it).
    """
    seedling_scale = timing["seedling_height"] or 1.0
    opening_end = lowest + timing["opening_offset"] + timing["opening_duration"]
    closing_start = cleared + timing["closing_delay"]
    closing_end = closing_start + timing["closing_duration"]
    undefined = np.isnan(cleared)
    stand_in = TWO_PI * room / seedling_scale          # normalises to room / seedling_scale
    return {"seedling": (room, seedling_scale),
            "opening_start": (lowest + timing["opening_offset"], TWO_PI),
            "phase_order": (np.where(undefined, stand_in, closing_start - opening_end), TWO_PI),
            "closes_in_time": (np.where(undefined, stand_in, TWO_PI - timing["closed_before_catch"]
                                        - closing_end), TWO_PI)}
