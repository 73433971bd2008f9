"""Named numerical tolerances and engineering limits, in one place.

Each is a default; functions take them as keyword arguments so a caller (or a
benchmark) can trade accuracy for time explicitly.
"""

__all__ = [
    "CLOSURE_RTOL",
    "CLOSURE_MIN_NODES",
    "CLOSURE_MAX_NODES",
    "FOURIER_TAIL_RTOL",
    "ROOT_XTOL",
    "MIN_PITCH_RADIUS_MODULES",
    "STEPS_PER_REVOLUTION",
    "REFINE_XATOL",
    "MINIMUM_SEARCH_EVALUATIONS",
    "ARM_DISTANCE_ATOL",
    "ARM_DISTANCE_EVALUATIONS",
]

#: Relative change of the centre distance between two node doublings that ends the
#: closure quadrature (periodic trapezoid rule, spectrally convergent).
CLOSURE_RTOL = 1e-13
#: Node counts the closure quadrature starts from and may not exceed.
CLOSURE_MIN_NODES = 256
CLOSURE_MAX_NODES = 2**22
#: The Fourier series of the ratio law is trusted once its top half of modes is
#: below this fraction of its mean (the discarded tail bounds the error in F).
FOURIER_TAIL_RTOL = 1e-13
#: Absolute tolerance (rad) of carrier angles found by root finding (soil crossings).
ROOT_XTOL = 1e-13
#: Absolute tolerance (rad) of the bounded 1-D minimisation that refines extrema.
REFINE_XATOL = 1e-11
#: A pitch radius below this many modules cannot be cut: a circle of 3 m holds 6
#: teeth, and the dedendum (1.25 m) would leave no rim round the shaft.
MIN_PITCH_RADIUS_MODULES = 3.0
#: Default carrier-angle samples per revolution for screening before refinement.
STEPS_PER_REVOLUTION = 3600
#: Budget of function evaluations of one certified minimum search. A smooth minimum
#: certifies in a few thousand with a curvature bound (3600 steps), in about 110,000
#: with the first-order bound alone (atol 1e-9); the budget stops a search that cannot
#: close (a distance with a kink where two bodies touch), which then reports its gap.
MINIMUM_SEARCH_EVALUATIONS = 250_000
#: The kinematic arm distance is certified to within this (mm).
ARM_DISTANCE_ATOL = 1e-9
#: Its budget: a clear minimum certifies in about 2,000 evaluations, one within 1e-4 mm
#: of touching in under 90,000 (0.2 s); closer than that, the gap is reported.
ARM_DISTANCE_EVALUATIONS = 100_000
