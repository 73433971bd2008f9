"""The generated gear: outline, pitch curve and bore in the gear's own frame (the exchange type)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["GearProfile"]


@dataclass(frozen=True)
class GearProfile:
    """One gear as it will be cut.

    Attributes
    ----------
    name : str
        e.g. ``"central"``, ``"intermediate 1"``; used in file names (spaces become ``-``).
    outline : (n, 2) float
        Closed tooth outline in the gear's body frame (mm), counter-clockwise, the
        first point not repeated at the end. Dense: consecutive points are at
        most a small fraction of a module apart.
    pitch_curve : (m, 2) float
        Closed pitch curve in the same frame, counter-clockwise, not repeated.
    teeth : int
    module : float
        mm.
    bore_radius : float
        Radius of the shaft bore at the body-frame origin (mm); 0 for none.
    centre : (2,) float
        Rotation centre in the body frame (the origin, normally).
    """

    name: str
    outline: np.ndarray
    pitch_curve: np.ndarray
    teeth: int
    module: float
    bore_radius: float = 0.0
    centre: tuple = (0.0, 0.0)
    notes: dict = field(default_factory=dict)

    @property
    def file_stem(self) -> str:
        return self.name.replace(" ", "-")

    def placed(self, angle: float, offset=(0.0, 0.0)):
        """Outline and pitch curve rotated by ``angle`` (rad) about the centre, then moved by ``offset``."""
        c, s = np.cos(angle), np.sin(angle)
        rotation = np.array([[c, -s], [s, c]])
        centre = np.asarray(self.centre, dtype=float)
        move = np.asarray(offset, dtype=float)
        return ((self.outline - centre) @ rotation.T + centre + move,
                (self.pitch_curve - centre) @ rotation.T + centre + move)
