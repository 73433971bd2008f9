"""Housing and gear-blank dimensions derived from the gears (light: no teeth are generated).

A gearbox housing is a closed shell round the hull of its gears' envelope discs:
the largest tip radius about each axis plus ``clearance``, then ``wall``. The
kinematic envelope circles of the clearance checks are those discs grown by the
wall, i.e. the housing's outside, so the kinematic and the solid checks see the
same housing. Each dimension left out of the file is derived from the module of
the gears the housing holds (:class:`cadgen.params.solids.ShellParameters`).
"""

from __future__ import annotations

from dataclasses import dataclass

from kinematics.clearance import HousingCircle
from kinematics.errors import DesignError
from kinematics.evaluation import default_housing_circles

__all__ = ["MIN_CIRCULAR_TEETH", "circular_module", "planting_circular_radii", "ShellSize",
           "planting_shells", "housing_circles"]

#: Circular gears get at least this many teeth: a standard rack undercuts fewer (2/sin^2(20 deg)).
MIN_CIRCULAR_TEETH = 17


def circular_module(radii, requested=None) -> float:
    """The requested module, or the largest 0.05-mm step (5 mm down) giving whole tooth counts.

    Only modules that give every circular gear at least ``MIN_CIRCULAR_TEETH``
    teeth are considered, so no circular gear is undercut.
    """
    if requested is not None:
        counts = [2 * r / requested for r in radii]
        if not all(abs(c - round(c)) < 1e-6 for c in counts):
            raise DesignError.single(
                "gears.circular_module", "fractional_teeth",
                f"module {requested:g} mm gives tooth counts {', '.join(f'{c:.3f}' for c in counts)}"
                f" for the circular gears of radii {', '.join(f'{r:g}' for r in radii)} mm: "
                "choose a module that divides every pitch diameter")
        return float(requested)
    for step in range(100, 9, -1):
        module = step * 0.05
        counts = [2 * r / module for r in radii]
        if all(abs(c - round(c)) < 1e-6 and round(c) >= MIN_CIRCULAR_TEETH for c in counts):
            return round(module, 10)
    raise DesignError.single("gears.circular_module", "fractional_teeth",
                             f"no module from 0.5 to 5 mm gives whole tooth counts for the circular "
                             f"gears of radii {', '.join(f'{r:g}' for r in radii)} mm; set one")



def planting_circular_radii(mechanism) -> list:
    """Pitch radii of the planting mechanism's circular gears: train 1's set (sun, idlers,
    planet) and gearbox 2's 1:1 gear ``r``."""
    R = mechanism.R
    return [R, R * mechanism.i12, R * mechanism.i13, R, mechanism.r]


@dataclass(frozen=True)
class ShellSize:
    """One housing's dimensions (mm) and the module they were derived from."""

    clearance: float
    wall: float
    axial_gap: float
    module: float

    @property
    def allowance(self) -> float:
        """Gear tip to the housing's outside."""
        return self.clearance + self.wall


def planting_shells(params, mechanism) -> dict:
    """``{"gearbox1": ShellSize, "gearbox2": ShellSize}`` of a planting design.

    Gearbox 2 holds the non-circular gears (the larger module); gearbox 1 the
    circular train.
    """
    housing = params.housing
    module_nc = mechanism.module(params.pitch_curve.teeth)
    try:
        module_c = circular_module(planting_circular_radii(mechanism), params.gears.circular_module)
    except DesignError:
        # no whole-tooth module: the teeth stage says so; the envelopes (and the kinematic
        # metrics) size the circular gears as if they had the non-circular gears' module
        module_c = params.gears.circular_module or module_nc
    size = {}
    for name, module in (("gearbox1", module_c), ("gearbox2", max(module_nc, module_c))):
        size[name] = ShellSize(housing.clearance_for(module), housing.wall_for(module),
                               housing.axial_gap, module)
    return size


def housing_circles(params, mechanism) -> list:
    """Envelope circles: derived from the gear sizes, with any explicit radius in the file winning."""
    shells = planting_shells(params, mechanism)
    circles = default_housing_circles(
        mechanism, mechanism.module(params.pitch_curve.teeth), shells["gearbox2"].allowance,
        circular_module=shells["gearbox1"].module, gearbox1_allowance=shells["gearbox1"].allowance)
    explicit = {"gearbox1": params.housing.gearbox1 or {}, "gearbox2": params.housing.gearbox2 or {}}
    return [HousingCircle(c.gearbox, c.point, float(explicit[c.gearbox].get(c.point, c.radius)))
            for c in circles]
