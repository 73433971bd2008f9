"""Errors of the solids toolkit, in the project's one exception family.

A bad *design* (an outline that crosses itself, a wall thinner than the minimum)
is a :class:`kinematics.errors.DesignError` carrying :class:`~kinematics.errors.Problem`
records with field paths, like every other validator of the project. The errors
here are for what is left: a solid that came out of an engine broken
(:class:`SolidError`), a bad argument to a helper (:class:`SolidInputError`, also a
``ValueError``), and an export format that cannot be written (:class:`ExportFormatError`).
"""

from __future__ import annotations

from kinematics.errors import MechanismError

__all__ = ["SolidError", "SolidInputError", "ExportFormatError"]


class SolidError(MechanismError):
    """A solid that breaks an invariant every part must keep.

    Parameters
    ----------
    part : str
        The part's name, e.g. ``"gearbox 2 housing"``.
    invariant : str
        Which invariant failed: ``"not_empty"``, ``"engine_status"``, ``"watertight"``,
        ``"winding_consistent"``, ``"positive_volume"``, ``"area_preserved"``, ...
    detail : str
        A sentence with the offending value.
    """

    def __init__(self, part: str, invariant: str, detail: str):
        self.part = part
        self.invariant = invariant
        self.detail = detail
        super().__init__(f"{part}: {invariant} failed: {detail}")


class SolidInputError(SolidError, ValueError):
    """A helper was called with an argument it cannot use (a negative radius, two segments)."""

    def __init__(self, argument: str, detail: str):
        super().__init__(argument, "valid_argument", detail)


class ExportFormatError(MechanismError, ValueError):
    """An export format that is unknown, or that the installed libraries cannot write."""
