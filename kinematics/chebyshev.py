"""Piecewise Chebyshev interpolants: spectral derivatives and integrals of piecewise-smooth functions.

A function that is analytic on each piece of a partition (a spline span, split
again at a mechanism's dead centres) is interpolated at Chebyshev points of the
first kind on every piece; a piece whose trailing coefficients have not decayed
to ``rtol`` is halved and fitted again. Derivatives and antiderivatives are
exact operations on the coefficients. The nodes never sit on a break point,
where such functions are typically evaluated least accurately.

A piece that has not converged when it is already narrower than ``min_width``
is never kept: its tail is a kink or a jump of the function (a clamped arccos,
a mis-placed break), and its derivative would be garbage that looks like a
number. The fit raises :class:`UnconvergedFit`, which says where.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as cheb

from .errors import ConvergenceError

__all__ = ["PiecewiseChebyshev", "UnconvergedFit"]


class UnconvergedFit(ConvergenceError):
    """Some pieces did not converge even at the narrowest width allowed.

    Attributes
    ----------
    intervals : (k, 2) float
        The unconverged pieces, in the function's argument.
    tail : float
        The largest trailing coefficient left, relative to the function's scale.
    """

    def __init__(self, intervals, tail: float, rtol: float):
        self.intervals = np.asarray(intervals, dtype=float).reshape(-1, 2)
        self.tail = float(tail)
        first = self.intervals[0]
        super().__init__(
            f"Chebyshev fit did not converge on {len(self.intervals)} piece(s), the first "
            f"[{first[0]:.9g}, {first[1]:.9g}]: trailing coefficients {self.tail:.1e} of the "
            f"scale, above rtol {rtol:.0e} (a kink or a jump of the function there)")


def _first_kind_nodes(degree: int) -> np.ndarray:
    k = np.arange(degree + 1)
    return np.cos(np.pi * (k + 0.5) / (degree + 1))[::-1]


def _transform(degree: int) -> np.ndarray:
    """Matrix taking values at the first-kind nodes to Chebyshev coefficients."""
    x = _first_kind_nodes(degree)
    basis = np.cos(np.outer(np.arccos(x), np.arange(degree + 1)))  # T_j(x_k)
    matrix = basis * (2.0 / (degree + 1))
    matrix[:, 0] *= 0.5
    return matrix


@dataclass(frozen=True)
class PiecewiseChebyshev:
    """A scalar function on ``[breaks[0], breaks[-1]]``, one Chebyshev series per piece.

    Attributes
    ----------
    breaks : (p + 1,) float
        Increasing piece boundaries.
    coefficients : (p, n + 1) float
        Chebyshev coefficients of each piece on its own ``[-1, 1]``.
    """

    breaks: np.ndarray
    coefficients: np.ndarray

    @classmethod
    def interpolate(cls, function, breaks, *, degree: int = 24, rtol: float = 1e-13,
                    max_pieces: int | None = None, min_width: float = 1e-7,
                    noise: float = 1.0) -> "PiecewiseChebyshev":
        """Fit ``function`` (vectorized) on every piece, halving pieces until converged.

        A piece still unconverged at ``min_width`` times the domain is not
        halved further: the fit fails, since a kink or jump inside it would make
        its derivatives meaningless (values carry about 2e-16 of round-off, far
        below ``rtol``, so this is never mere noise). ``noise`` > 1 keeps such
        pieces up to ``noise * rtol``, for a caller that takes no derivatives.

        Raises
        ------
        UnconvergedFit
            A piece at ``min_width`` whose tail is above ``noise * rtol``, with where.
        ConvergenceError
            If more than ``max_pieces`` pieces would be needed (the function is
            not piecewise smooth on the given breaks; default the larger of 4096
            and 16 a given piece).
        """
        breaks = np.asarray(breaks, dtype=float)
        if breaks.ndim != 1 or breaks.size < 2 or np.any(np.diff(breaks) <= 0):
            raise ValueError("breaks must be a strictly increasing 1-D array of at least 2 values")
        if max_pieces is None:  # room to halve every given piece a few times
            max_pieces = max(4096, 16 * breaks.size)
        nodes = _first_kind_nodes(degree)
        transform = _transform(degree)
        lows, highs = breaks[:-1], breaks[1:]
        done_lows, done_highs, done_coefficients = [], [], []
        scale = None
        failed, worst = [], 0.0
        while lows.size:
            points = 0.5 * (lows + highs)[:, None] + 0.5 * (highs - lows)[:, None] * nodes
            values = np.asarray(function(points.ravel()), dtype=float).reshape(points.shape)
            if not np.all(np.isfinite(values)):
                raise ConvergenceError("function is not finite on the interpolation nodes")
            if scale is None:
                scale = max(float(np.abs(values).max()), 1e-300)
            coefficients = values @ transform
            tail = np.abs(coefficients[:, -3:]).max(axis=1)
            narrow = highs - lows <= min_width * (breaks[-1] - breaks[0])
            stuck = narrow & (tail > noise * rtol * scale)
            if stuck.any():
                failed.append(np.stack([lows[stuck], highs[stuck]], axis=-1))
                worst = max(worst, float(tail[stuck].max()) / scale)
            good = (tail <= rtol * scale) | narrow
            done_lows.append(lows[good])
            done_highs.append(highs[good])
            done_coefficients.append(coefficients[good])
            middle = 0.5 * (lows[~good] + highs[~good])
            lows = np.concatenate([lows[~good], middle])
            highs = np.concatenate([middle, highs[~good]])
            if sum(len(x) for x in done_lows) + lows.size > max_pieces:
                raise ConvergenceError(
                    f"Chebyshev interpolation needs more than {max_pieces} pieces")
        if failed:
            intervals = np.concatenate(failed)
            raise UnconvergedFit(intervals[np.argsort(intervals[:, 0])], worst, rtol)
        lows = np.concatenate(done_lows)
        order = np.argsort(lows)
        edges = np.append(lows[order], np.concatenate(done_highs)[order][-1])
        return cls(edges, np.concatenate(done_coefficients)[order])

    # ------------------------------------------------------------ evaluation
    def _locate(self, u):
        u = np.asarray(u, dtype=float)
        piece = np.clip(np.searchsorted(self.breaks, u, side="right") - 1,
                        0, len(self.coefficients) - 1)
        low, high = self.breaks[piece], self.breaks[piece + 1]
        return u, piece, (2.0 * u - low - high) / (high - low)

    def __call__(self, u):
        """Values at ``u`` (any shape); points outside extend the end pieces."""
        u, piece, x = self._locate(u)
        # Clenshaw's recurrence, vectorized over points with their own pieces; one
        # coefficient column gathered at a time from the transposed (contiguous) table
        columns = self._columns
        b1 = np.zeros_like(x)
        b2 = np.zeros_like(x)
        twice = 2.0 * x
        for j in range(columns.shape[0] - 1, 0, -1):
            b1, b2 = twice * b1 - b2 + columns[j].take(piece), b1
        return x * b1 - b2 + columns[0].take(piece)

    @property
    def _columns(self) -> np.ndarray:
        cached = self.__dict__.get("_columns_cache")
        if cached is None:
            cached = np.ascontiguousarray(self.coefficients.T)
            object.__setattr__(self, "_columns_cache", cached)
        return cached

    def derivative(self) -> "PiecewiseChebyshev":
        widths = np.diff(self.breaks)[:, None]
        rows = cheb.chebder(self.coefficients, axis=1)
        derived = np.pad(rows, ((0, 0), (0, 1))) * (2.0 / widths)
        return PiecewiseChebyshev(self.breaks, derived)

    def antiderivative(self) -> "PiecewiseChebyshev":
        """The continuous antiderivative that is zero at ``breaks[0]``."""
        widths = np.diff(self.breaks)
        rows = cheb.chebint(self.coefficients, lbnd=-1, axis=1)
        rows *= (0.5 * widths)[:, None]
        totals = rows.sum(axis=1)  # T_n(1) = 1: each piece's integral is its row's sum
        rows[:, 0] += np.concatenate([[0.0], np.cumsum(totals)[:-1]])
        return PiecewiseChebyshev(self.breaks, rows)

    def integral(self) -> float:
        """Definite integral over the whole domain (``int T_n = 2 / (1 - n^2)``, n even)."""
        n = np.arange(self.coefficients.shape[1])
        weights = np.where(n % 2 == 0, 2.0 / (1.0 - n**2 + (n == 1)), 0.0)
        return float(0.5 * np.diff(self.breaks) @ (self.coefficients @ weights))

    @property
    def domain(self) -> tuple[float, float]:
        return float(self.breaks[0]), float(self.breaks[-1])
