"""The torque chain: from the tool's tip load to every gear's torque and mesh force, and speeds.

The design load is a force at the tool's tip (the soil's resistance on the duckbill
or the needle) times the service factor, ``F = tip_load_n * service_factor``. It
is taken at its worst lever (the whole tip reach, perpendicular) and passed back
through the gears at their worst contact radii, so every torque below is an upper
bound over the cycle. A mesh's tangential force ``Ft`` loads both gears' shafts
with the resultant ``Ft / cos(alpha)`` (alpha the pressure angle). Torques are in
N mm, forces in N, speeds in r/min relative to the housing the shaft turns in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["GearLoad", "AxisLoads", "design_load", "mesh_resultant", "planting_loads",
           "planting_speeds", "pricking_radius_ratios", "pricking_loads", "pricking_speeds",
           "PRICKING_SAMPLES"]

#: Samples of the carrier cycle the pricking pitch radii are evaluated on.
PRICKING_SAMPLES = 4096


@dataclass(frozen=True)
class GearLoad:
    """What one gear puts on its shaft: hub torque (N mm), mesh tangential and radial force (N)."""

    gear: str
    torque_nmm: float
    tangential_n: float
    radial_n: float


@dataclass(frozen=True)
class AxisLoads:
    """Every load on one axis: its gears, the largest torque it carries, an external load.

    ``external`` is ``(where, force_n)`` or None: a load applied beyond the housing
    (``"roof"``: above the roof's outer face) by what the shaft carries there.
    """

    axis: str
    torque_nmm: float
    gears: dict
    speed_rpm: float
    external: tuple | None = None
    formulas: dict = field(default_factory=dict)
    cycle: object = None          # cycle_loads.CycleLoads: the dynamics' loads over the turn


def design_load(machine) -> float:
    """``F = tip_load_n * service_factor`` (N), from ``params.machine``."""
    return float(machine.tip_load_n) * float(machine.service_factor)


def mesh_resultant(tangential_n: float, pressure_angle: float) -> float:
    """The shaft load of a spur mesh: ``Ft / cos(alpha)`` (N); ``alpha`` in radians."""
    return float(tangential_n) / math.cos(pressure_angle)


# ------------------------------------------------------------------ planting
def planting_speeds(mechanism, carrier_rpm: float, drive=None) -> dict:
    """Mean speed of each shaft relative to its housing (r/min), ``omega`` the carrier-1 speed.

    Gearbox 2: ``C2``, ``D``, ``E`` make one relative turn per carrier turn (the
    non-circular pair closes 1:1, the circular pair is 1:1): ``omega``. Gearbox 1
    (relative to carrier 1, the suns turn at ``(n - 1) omega``): ``O`` that, and each axis
    its set-II gear's speed (``A``, ``B`` the idlers' ``(n - 1) omega r_sun / r``, ``C`` the
    planet's ``2 omega``); ``C2`` (planet I, still) ``omega`` against carrier 1. The frame
    (fixed): ``S`` (the sleeve, carrier 1) ``omega``, ``input`` ``omega z4 / z3`` (the drive's
    pair 2); ``O`` turns in the frame at ``n omega`` but its bearings are the frame floor's
    and gearbox 1's roof's: the larger relative speed, ``n omega``, sizes them.
    """
    from cadgen.gears.circular import train1_set_radii

    omega = float(carrier_rpm)
    relative = (mechanism.n - 1.0) * omega
    sun, idler_a, idler_b, planet = train1_set_radii(mechanism, "II")
    speeds = {"O": mechanism.n * omega, "A": relative * sun / idler_a,
              "B": relative * sun / idler_b, "C": relative * sun / planet, "C2": omega,
              "D": omega, "E": omega, "S": omega}
    if drive is not None:
        speeds["input"] = float(drive.input_speed_rpm)
    return speeds


def free_speeds(mechanism, carrier_rpm: float) -> dict:
    """Speeds (r/min) of each axis's two idlers relative to each other (one keyed to the shaft,
    the other free on it): ``(n - 1) omega |r_s1 / r_1 - r_s2 / r_2|``."""
    from cadgen.gears.circular import train1_set_radii

    relative = (mechanism.n - 1.0) * float(carrier_rpm)
    two, one = train1_set_radii(mechanism, "II"), train1_set_radii(mechanism, "I")
    return {"idler 1-I": relative * abs(one[0] / one[1] - two[0] / two[1]),
            "idler 2-I": relative * abs(one[0] / one[2] - two[0] / two[2])}


@dataclass(frozen=True)
class FreeAxisLoads(AxisLoads):
    """An axis with gears running free on it: their speeds relative to the shaft."""

    free_speeds: dict = field(default_factory=dict)


def planting_loads(mechanism, machine, pressure_angle: float, carrier_rpm: float,
                   drive=None) -> dict:
    """``{axis: AxisLoads}`` of the planting mechanism (both trains and the drive), one arm.

    With ``F`` the design load, ``a`` the centre distance, ``r1`` the central gear's
    pitch radius, ``r`` the 1:1 circular gears', ``r_s``, ``r_p`` the suns' and planets' of
    train 1's sets (II: carries gearbox 2; I: holds the central gear):

    - E (planet gear E, the planter on it): ``T_E = F sqrt(L1^2 + L2^2)``; an
      external radial load ``F`` at the planter plate's plane (above the roof);
    - D: ``T_D = T_E``; gear D's mesh ``Ft = T_E / r``; the intermediate gear's
      mesh ``Ft = T_D / (a - max r1)`` (its smallest radius);
    - C2 (inner shaft: planet I and the central gear): ``T_C2 = T_D max(r1 / (a - r1))``;
      set I's mesh ``Ft_I = T_C2 / r_pI``;
    - C (hollow shaft: set II's planet, carrying gearbox 2): the moments about C on the arm
      (gearbox 2, its gears and the planter) balance, so ``T_C <= F |CN| + T_C2`` with
      ``|CN| <= a + 2 r + sqrt(L1^2 + L2^2)``; mesh ``Ft_II = T_C / r_pII``; the tool's load
      ``F`` reaches it through gearbox 2's housing, above its roof;
    - O (the central shaft, both suns): ``T_O = T_C r_sII / r_pII + T_C2 r_sI / r_pI``: the two
      arms are half a turn apart and each is in the soil for a short part of the turn, so one
      arm loads the suns at a time; the drive's gear on it ``Ft = T_O / r_2``;
    - A, B (set II's idlers keyed, set I's free on them): no torque, radial ``2 Ft`` per idler;
    - S (the sleeve carrying gearbox 1, the transmission driven gear on it): the moments about
      O on carrier 1: ``T_S = F (Rc + |CN|) + T_O``, mesh ``Ft = T_S / r_4``; ``F`` at the
      planter's plane;
    - input: ``T_in = T_O z1 / z2 + T_S z3 / z4`` (the drive's pairs), both meshes.
    """
    from cadgen.gears.circular import train1_set_radii

    F = design_load(machine)
    closure = mechanism.closure
    a, r = float(mechanism.centre_distance), float(mechanism.r)
    r1_max = float(closure.radius_max[1])
    ratio_max = float(closure.ratio_max)
    set2, set1 = train1_set_radii(mechanism, "II"), train1_set_radii(mechanism, "I")
    T_E = F * math.hypot(mechanism.L1, mechanism.L2)
    T_D = T_E
    Ft_circular = T_E / r
    Ft_noncircular = T_D / (a - r1_max)
    T_C2 = T_D * ratio_max
    reach_C = a + 2.0 * r + math.hypot(mechanism.L1, mechanism.L2)
    T_C = F * reach_C + T_C2
    Ft_2 = T_C / set2[3]
    Ft_1 = T_C2 / set1[3]
    T_sun2, T_sun1 = T_C * set2[0] / set2[3], T_C2 * set1[0] / set1[3]
    T_O = T_sun2 + T_sun1
    speeds = planting_speeds(mechanism, carrier_rpm, drive)

    def load(gear, torque, tangential, meshes=1):
        return GearLoad(gear, torque, tangential, meshes * mesh_resultant(tangential,
                                                                         pressure_angle))

    frees = free_speeds(mechanism, carrier_rpm)
    axes = {
        "O": AxisLoads("O", T_O, {"sun": load("sun", T_sun2, Ft_2),
                                  "sun I": load("sun I", T_sun1, Ft_1)}, speeds["O"]),
        "A": FreeAxisLoads("A", 0.0, {"idler 1": load("idler 1", 0.0, Ft_2, meshes=2),
                                      "idler 1-I": load("idler 1-I", 0.0, Ft_1, meshes=2)},
                           speeds["A"], free_speeds={"idler 1-I": frees["idler 1-I"],
                                                     "idler 1": frees["idler 1-I"]}),
        "B": FreeAxisLoads("B", 0.0, {"idler 2": load("idler 2", 0.0, Ft_2, meshes=2),
                                      "idler 2-I": load("idler 2-I", 0.0, Ft_1, meshes=2)},
                           speeds["B"], free_speeds={"idler 2-I": frees["idler 2-I"],
                                                     "idler 2": frees["idler 2-I"]}),
        "C": AxisLoads("C", T_C, {"train-1 planet": load("train-1 planet", T_C, Ft_2)},
                       speeds["C"], external=("roof", F)),
        "C2": AxisLoads("C2", T_C2, {"planet I": load("planet I", T_C2, Ft_1),
                                     "central": load("central", T_C2, Ft_noncircular)},
                        speeds["C2"]),
        "D": AxisLoads("D", T_D, {"intermediate": load("intermediate", T_D, Ft_noncircular),
                                  "gear D": load("gear D", T_D, Ft_circular)}, speeds["D"]),
        "E": AxisLoads("E", T_E, {"planet gear E": load("planet gear E", T_E, Ft_circular)},
                       speeds["E"], external=("roof", F)),
    }
    values = {"F_n": F, "T_E_nmm": T_E, "T_C2_nmm": T_C2, "T_C_nmm": T_C, "T_O_nmm": T_O,
              "a_mm": a, "r1_max_mm": r1_max, "ratio_max": ratio_max}
    if drive is not None:
        z1, z2, z3, z4 = drive.teeth
        r2, r4 = drive.radii[1], drive.radii[3]
        T_S = F * (mechanism.carrier_radii["C"] + reach_C) + T_O
        T_in = T_O * z1 / z2 + T_S * z3 / z4
        Ft_d1, Ft_d2 = T_O / r2, T_S / r4
        axes["O"].gears["central shaft gear"] = load("central shaft gear", T_O, Ft_d1)
        axes["S"] = AxisLoads("S", T_S, {"transmission driven gear": load(
            "transmission driven gear", T_S, Ft_d2)}, speeds["S"], external=("roof", F))
        axes["input"] = AxisLoads("input", T_in, {
            "input gear 1": load("input gear 1", T_O * z1 / z2, Ft_d1),
            "input gear 2": load("input gear 2", T_S * z3 / z4, Ft_d2)}, speeds["input"])
        values.update({"T_S_nmm": T_S, "T_input_nmm": T_in})
    formulas = {"F": "tip_load_n * service_factor", "T_E": "F sqrt(L1^2 + L2^2)",
                "T_D": "T_E", "Ft_D-E": "T_E / r", "Ft_nc": "T_D / (a - max r1)",
                "T_C2": "T_D max(r1 / (a - r1))", "T_C": "F (a + 2 r + sqrt(L1^2 + L2^2)) + T_C2",
                "Ft_II": "T_C / r_pII", "Ft_I": "T_C2 / r_pI",
                "T_O": "T_C r_sII / r_pII + T_C2 r_sI / r_pI (one arm in the soil at a time)",
                "idlers": "radial 2 Ft / cos(alpha) each, no torque",
                "T_S": "F (Rc + a + 2 r + sqrt(L1^2 + L2^2)) + T_O (moments about O on carrier 1)",
                "T_input": "T_O z1 / z2 + T_S z3 / z4",
                "resultant": "Ft / cos(alpha)"}
    info = {"formulas": formulas, "values": values}
    out = {}
    for name, v in axes.items():
        extra = {"free_speeds": v.free_speeds} if isinstance(v, FreeAxisLoads) else {}
        kind = FreeAxisLoads if extra else AxisLoads
        out[name] = kind(v.axis, v.torque_nmm, v.gears, v.speed_rpm, v.external, info, **extra)
    return out


# ------------------------------------------------------------------ pricking
def _cycle_grid(design, samples: int):
    functions, _ = design.cycle_functions()
    tau = np.linspace(0.0, design.motion.period, int(samples), endpoint=False)
    return functions, tau


def pricking_radius_ratios(design, samples: int = PRICKING_SAMPLES) -> dict:
    """Extremes of the pricking gears' contact radii over the cycle (dense grid).

    Returns ``{"int2_over_planet": max rho_int2 / rho_planet, "sun_over_int1": max
    rho_sun / rho_int1, "planet_min", "int1_min", "sun_min", "int2_min": the smallest
    contact radii (mm)}``, sampled on ``samples`` points of the carrier cycle.
    """
    functions, tau = _cycle_grid(design, samples)
    rho = {name: np.asarray(functions[name](tau)[0], dtype=float) for name in functions}
    return {"int2_over_planet": float(np.max(rho["intermediate 2"] / rho["planet"])),
            "sun_over_int1": float(np.max(rho["sun"] / rho["intermediate 1"])),
            "planet_min": float(rho["planet"].min()), "int1_min": float(rho["intermediate 1"].min()),
            "sun_min": float(rho["sun"].min()), "int2_min": float(rho["intermediate 2"].min())}


def pricking_speeds(design, carrier_rpm: float, samples: int = PRICKING_SAMPLES) -> dict:
    """Mean speed of each pricking shaft relative to the gear case (r/min).

    The case turns about the sun at ``omega``, so the sun's shaft turns at ``omega``
    relative to it. The intermediate and the planet turn relative to the case by
    ``|delta psi|`` per carrier turn (``psi`` the contact's polar angle in the gear's
    frame, whose change over a cycle is the gear's turn relative to the line of
    centres, fixed in the case): mean speed ``|delta psi| / 2 pi * omega``.
    """
    omega = float(carrier_rpm)
    functions, _ = _cycle_grid(design, samples)
    period = design.motion.period
    ends = np.array([0.0, period * (1.0 - 1e-12)])

    def turns(name):
        psi = np.asarray(functions[name](ends)[2], dtype=float)
        return abs(float(psi[1] - psi[0])) / (2 * math.pi)

    return {"sun": omega, "intermediate": turns("intermediate 1") * omega,
            "planet": turns("planet") * omega}


def pricking_loads(design, machine, pressure_angle: float, carrier_rpm: float,
                   samples: int = PRICKING_SAMPLES) -> dict:
    """``{axis: AxisLoads}`` of the pricking gear case.

    With ``F`` the design load and ``l`` the tip reach from B (``design.linkage.l``):

    - planet: ``T_planet = F l``; an external radial load ``F`` at the rocker's plane;
      stage-2 mesh ``Ft2 = T_planet / min rho_planet``;
    - intermediate (both intermediate gears, one shaft):
      ``T_int = T_planet max(rho_int2 / rho_planet)``; stage-1 mesh
      ``Ft1 = T_int / min rho_int1``;
    - sun (fixed to the frame): ``T_sun = T_int max(rho_sun / rho_int1)``, mesh ``Ft1``.

    Each maximum is over the cycle on ``samples`` points, each bound taken
    separately (conservative).
    """
    F = design_load(machine)
    ratios = pricking_radius_ratios(design, samples)
    speeds = pricking_speeds(design, carrier_rpm, samples)
    T_planet = F * float(design.linkage.l)
    T_int = T_planet * ratios["int2_over_planet"]
    T_sun = T_int * ratios["sun_over_int1"]
    Ft2 = T_planet / ratios["planet_min"]
    Ft1 = T_int / ratios["int1_min"]

    def load(gear, torque, tangential):
        return GearLoad(gear, torque, tangential, mesh_resultant(tangential, pressure_angle))

    formulas = {"F": "tip_load_n * service_factor", "T_planet": "F l",
                "T_int": "T_planet max(rho_int2 / rho_planet)",
                "T_sun": "T_int max(rho_sun / rho_int1)", "Ft2": "T_planet / min rho_planet",
                "Ft1": "T_int / min rho_int1", "resultant": "Ft / cos(alpha)"}
    values = {"F_n": F, "l_mm": float(design.linkage.l), "T_planet_nmm": T_planet,
              "T_int_nmm": T_int, "T_sun_nmm": T_sun, **ratios}
    info = {"formulas": formulas, "values": values}
    return {
        "sun": AxisLoads("sun", T_sun, {"sun": load("sun", T_sun, Ft1)}, speeds["sun"],
                         formulas=info),
        "intermediate": AxisLoads(
            "intermediate", T_int,
            {"intermediate 1": load("intermediate 1", T_int, Ft1),
             "intermediate 2": load("intermediate 2", T_int, Ft2)},
            speeds["intermediate"], formulas=info),
        "planet": AxisLoads("planet", T_planet, {"planet": load("planet", T_planet, Ft2)},
                            speeds["planet"], external=("roof", F), formulas=info),
    }
