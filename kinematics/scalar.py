"""Brent's two scalar methods: a bracketed root and a bounded minimum.

These are ports of scipy's ``brentq`` (Brent 1973, ``zeros.c``) and of the
bounded method of ``scipy.optimize.minimize_scalar`` (``fminbound``), with the
same arguments and results, so that the kinematics need not import
``scipy.optimize``: that import pulls in linear programming and linear algebra
and costs about 0.45 s, most of a metrics-only build's time budget (0.5 s).
``tests/test_scalar.py`` checks them against scipy's on a set of functions.
scipy is BSD-licensed; see its LICENSE for the original code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import ConvergenceError

__all__ = ["brentq", "minimize_scalar", "BoundedMinimum"]

_EPS = 2.220446049250313e-16


def brentq(f, a: float, b: float, *, xtol: float = 2e-12, rtol: float = 4 * _EPS,
           maxiter: int = 100) -> float:
    """A root of ``f`` in ``[a, b]`` (``f(a)`` and ``f(b)`` of opposite signs), to ``xtol + rtol |x|``.

    Raises
    ------
    ValueError
        When ``f(a)`` and ``f(b)`` have the same sign (as scipy's).
    ConvergenceError
        When ``maxiter`` iterations do not reach the tolerance.
    """
    x_pre, x_cur = float(a), float(b)
    f_pre, f_cur = float(f(x_pre)), float(f(x_cur))
    if f_pre == 0.0:
        return x_pre
    if f_cur == 0.0:
        return x_cur
    if math.copysign(1.0, f_pre) == math.copysign(1.0, f_cur):
        raise ValueError("f(a) and f(b) must have different signs")
    x_blk = f_blk = s_pre = s_cur = 0.0
    for _ in range(maxiter):
        if f_pre != 0.0 and f_cur != 0.0 and \
                math.copysign(1.0, f_pre) != math.copysign(1.0, f_cur):
            x_blk, f_blk = x_pre, f_pre
            s_pre = s_cur = x_cur - x_pre
        if abs(f_blk) < abs(f_cur):   # keep the best estimate in x_cur
            x_pre, x_cur, x_blk = x_cur, x_blk, x_cur
            f_pre, f_cur, f_blk = f_cur, f_blk, f_cur
        delta = (xtol + rtol * abs(x_cur)) / 2.0
        s_bis = (x_blk - x_cur) / 2.0
        if f_cur == 0.0 or abs(s_bis) < delta:
            return x_cur
        if abs(s_pre) > delta and abs(f_cur) < abs(f_pre):
            if x_pre == x_blk:   # secant
                s_try = -f_cur * (x_cur - x_pre) / (f_cur - f_pre)
            else:                # inverse quadratic interpolation
                d_pre = (f_pre - f_cur) / (x_pre - x_cur)
                d_blk = (f_blk - f_cur) / (x_blk - x_cur)
                s_try = -f_cur * (f_blk * d_blk - f_pre * d_pre) / (d_blk * d_pre * (f_blk - f_pre))
            if 2.0 * abs(s_try) < min(abs(s_pre), 3.0 * abs(s_bis) - delta):
                s_pre, s_cur = s_cur, s_try   # a good short step
            else:
                s_pre = s_cur = s_bis
        else:
            s_pre = s_cur = s_bis
        x_pre, f_pre = x_cur, f_cur
        x_cur += s_cur if abs(s_cur) > delta else (delta if s_bis > 0 else -delta)
        f_cur = float(f(x_cur))
    raise ConvergenceError(f"brentq did not converge in {maxiter} iterations on [{a}, {b}]")


@dataclass(frozen=True)
class BoundedMinimum:
    """Result of :func:`minimize_scalar`: ``x``, ``fun``, evaluations ``nfev``, ``success``."""

    x: float
    fun: float
    nfev: int
    success: bool


def minimize_scalar(fun, bounds, method: str = "bounded", options=None) -> BoundedMinimum:
    """A local minimum of ``fun`` on ``bounds`` by Brent's method (golden section and parabolas).

    Accepts ``options={"xatol": ..., "maxiter": ...}`` as scipy's bounded method.
    """
    if method != "bounded":
        raise ValueError(f"only the bounded method is provided, not {method!r}")
    options = options or {}
    xatol, maxfun = float(options.get("xatol", 1e-5)), int(options.get("maxiter", 500))
    a, b = (float(v) for v in bounds)
    if not a <= b:
        raise ValueError(f"bounds must be (lower, upper), got {bounds}")
    sqrt_eps = math.sqrt(2.2e-16)
    golden_mean = 0.5 * (3.0 - math.sqrt(5.0))
    fulc = a + golden_mean * (b - a)
    nfc = xf = fulc
    rat = e = 0.0
    fx = float(fun(xf))
    num = 1
    fu = math.inf
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = sqrt_eps * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    success = True
    while abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = True
        if abs(e) > tol1:   # try a parabola through the three best points
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r, e = e, rat
            if abs(p) < abs(0.5 * q * r) and q * (a - xf) < p < q * (b - xf):
                rat = p / q
                x = xf + rat
                if (x - a) < tol2 or (b - x) < tol2:
                    rat = tol1 * (_sign(xm - xf) or 1.0)
            else:
                golden = True
        if golden:
            e = a - xf if xf >= xm else b - xf
            rat = golden_mean * e
        x = xf + (_sign(rat) or 1.0) * max(abs(rat), tol1)
        fu = float(fun(x))
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if fu <= fnfc or nfc == xf:
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = sqrt_eps * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= maxfun:
            success = False
            break
    if math.isnan(xf) or math.isnan(fx) or math.isnan(fu):
        success = False
    return BoundedMinimum(x=xf, fun=fx, nfev=num, success=success)


def _sign(value: float) -> float:
    return (value > 0) - (value < 0)
