"""Housing and gear-blank dimensions derived from the gears (light: no teeth are generated).

A gearbox housing is a split shell round the hull of its gears' envelope discs:
the largest tip radius about each axis plus ``clearance``, then ``wall``, then the
bolt flange of the base/cover joint. The kinematic envelope circles of the
clearance checks are those discs grown by the wall and the flange, i.e. the
housing's outermost edge, so the kinematic and the solid checks see the same
housing. Each dimension left out of the file is derived from the module of
the gears the housing holds (:class:`cadgen.params.solids.ShellParameters`).
"""

from __future__ import annotations

from dataclasses import dataclass

from kinematics.clearance import HousingCircle
from kinematics.planting import PlantingMechanism

from cadgen.gears.circular import planting_modules

__all__ = ["ShellSize", "planting_shells", "housing_circles", "envelope_circles"]


@dataclass(frozen=True)
class ShellSize:
    """One housing's dimensions (mm) and the module they were derived from."""

    clearance: float
    wall: float
    axial_gap: float
    module: float
    flange: float = 0.0     # the base/cover joint's flange beyond the wall

    @property
    def allowance(self) -> float:
        """Gear tip to the housing's side wall's outside."""
        return self.clearance + self.wall

    @property
    def envelope(self) -> float:
        """Gear tip to the housing's outermost edge (its flange's): the envelope circles'."""
        return self.clearance + self.wall + self.flange


def flange_width(params, wall: float) -> float:
    """The bolt flange's width (mm) of a housing with side ``wall``: its bolt's clearance hole
    (:func:`cadgen.solids.machine_parts.housing_bolt`) times :data:`FLANGE_WIDTH_HOLES`."""
    from cadgen.solids.machine_parts import housing_bolt
    from cadgen.solids.tolerances import FLANGE_WIDTH_HOLES

    return FLANGE_WIDTH_HOLES * housing_bolt(params, wall)[1]


def planting_shells(params, mechanism) -> dict:
    """``{"gearbox1": ShellSize, "gearbox2": ShellSize}`` of a planting design.

    Gearbox 2 holds the non-circular gears (the larger module); gearbox 1 the
    circular train.
    """
    housing = params.housing
    module_nc, module_c = planting_modules(mechanism, params.pitch_curve.teeth,
                                           params.gears.circular_module)
    size = {}
    for name, module in (("gearbox1", module_c), ("gearbox2", max(module_nc, module_c))):
        wall = housing.wall_for(module)
        size[name] = ShellSize(housing.clearance_for(module), wall, housing.axial_gap, module,
                               flange_width(params, wall))
    return size


def housing_circles(params, mechanism) -> list:
    """Envelope circles: derived from the gear sizes, with any explicit radius in the file winning."""
    shells = planting_shells(params, mechanism)
    circles = envelope_circles(
        mechanism, mechanism.module(params.pitch_curve.teeth), shells["gearbox2"].envelope,
        circular_module=shells["gearbox1"].module, gearbox1_allowance=shells["gearbox1"].envelope,
        shifts=params.gears.profile_shift.resolved(),
        holding=_holding_set(params, mechanism))
    explicit = {"gearbox1": params.housing.gearbox1 or {}, "gearbox2": params.housing.gearbox2 or {}}
    return [HousingCircle(c.gearbox, c.point, float(explicit[c.gearbox].get(c.point, c.radius)))
            for c in circles]


def _holding_set(params, mechanism):
    """Set I as the teeth stage cuts it (:func:`cadgen.gears.circular.holding_set_design`), or
    None when it cannot be cut."""
    from cadgen.gears.circular import holding_set_design
    from kinematics.errors import DesignError

    try:
        return holding_set_design(mechanism, params.gears.circular_module,
                                  params.gears.pressure_angle_rad)
    except DesignError:
        return None


def envelope_circles(mechanism: PlantingMechanism, module: float, allowance: float, *,
                            circular_module: float | None = None,
                            gearbox1_allowance: float | None = None, shifts=None,
                            holding=None):
    """Envelope circles of both gearboxes: the largest gear tip about each axis plus ``allowance``.

    Gearbox 2 holds the non-circular pair and the 1:1 pair: at C the central
    gear's largest tip radius, at D the larger of the intermediate gear's
    (``a - min r1`` plus one module) and the circular gear's, at E the planet
    gear. Gearbox 1 (carrier 1) uses the first train's gear set with converted
    ratio -1 (sun R, idlers R i12 and R i13, planet R) with the circular
    module's addendum; the other set is not modelled, so pass explicit radii
    when it is larger. ``allowance`` (mm) is the housing's clearance plus wall;
    ``gearbox1_allowance`` defaults to it, ``circular_module`` to ``module``.
    ``shifts`` (``gears.profile_shift`` key -> x, resolved) moves a gear's tip out by its
    positive shift, ``x m``; a negative one leaves the housing as for the standard gear.
    """
    closure = mechanism.closure
    a = closure.centre_distance
    r_min, r_max = closure.radius_min[1], closure.radius_max[1]
    r = mechanism.r
    m_c = module if circular_module is None else circular_module
    outer1 = allowance if gearbox1_allowance is None else gearbox1_allowance
    shifts = shifts or {}

    def tip(key, m):   # the addendum, grown by a positive profile shift (unshifted: m exactly)
        shift = max(shifts.get(key, 0.0), 0.0)
        return m + shift * m if shift else m

    box2 = {"C": r_max + tip("central", module) + allowance,
            "D": max(a - r_min + tip("intermediate", module), r + tip("gear_D", m_c)) + allowance,
            "E": r + tip("planet_gear_E", m_c) + allowance}
    from cadgen.gears.circular import train1_set_radii

    two = train1_set_radii(mechanism, "II")
    box1 = {"O": two[0] + tip("sun", m_c) + outer1, "A": two[1] + tip("idler_1", m_c) + outer1,
            "B": two[2] + tip("idler_2", m_c) + outer1,
            "C": two[3] + tip("train_1_planet", m_c) + outer1}
    if holding is not None:   # set I (it holds the central gear) shares the axes: the larger
        for axis, radius, key, shift in zip("OABC", holding.reference_radii,
                                            ("sun_I", "idler_1_I", "idler_2_I", "planet_I"),
                                            holding.shifts):
            # its tip: the reference radius plus one module, grown by a positive shift (its
            # own, computed for the axis distances, or the file's)
            grown = holding.module * max(shift, shifts.get(key, 0.0), 0.0)
            box1[axis] = max(box1[axis], radius + holding.module + grown + outer1)
    return ([HousingCircle("gearbox1", p, v) for p, v in box1.items()]
            + [HousingCircle("gearbox2", p, v) for p, v in box2.items()])
