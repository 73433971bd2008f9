"""Planar vector helpers shared by the kinematic models (arrays of 2-vectors in the last axis)."""

from __future__ import annotations

import numpy as np

__all__ = ["unit", "perp", "cross"]


def unit(angle):
    """``u(t) = (cos t, sin t)``: shape ``angle.shape + (2,)``."""
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def perp(vectors):
    """Vectors ``(..., 2)`` turned by +90 degrees."""
    return np.stack([-vectors[..., 1], vectors[..., 0]], axis=-1)


def cross(u, v):
    """z component of ``u x v`` for ``(..., 2)`` arrays."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
