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
