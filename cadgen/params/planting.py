"""Mechanism kind 1, ``mechanism = "planting"``: the differential planetary planting mechanism.

Tables ``[pitch_curve]``, ``[train]``, ``[planter]``, ``[field]`` and the optional
``[housing]``, ``[targets]``, ``[resolution]``; :class:`PlantingParameters` holds them
all. Only rules that need no kinematics are checked here (``2*e2`` whole, no repeated
plant spacing); :func:`cadgen.params.feasibility.design_problems` judges the rest.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal, Union

from pydantic import BeforeValidator, Field, field_validator
from pydantic_core import PydanticCustomError

from cadgen.params.cam import CamParameters
from cadgen.params.cutting import PlantingCuttingParameters
from cadgen.params.scene import SceneParameters
from cadgen.params.solids import GroundParameters, ShellParameters, SolidsParameters
from cadgen.params.machine import MachineParameters, ManufacturingParameters
from cadgen.params.dynamics import DynamicsParameters
from cadgen.params._tables import NAME_MAX_LENGTH, NAME_PATTERN, _list_to_tuple, _no_repeats, _Table

__all__ = [
    "LimaconParameters",
    "PitchCurve",
    "TrainParameters",
    "PlanterParameters",
    "FieldParameters",
    "Gearbox1Envelope",
    "Gearbox2Envelope",
    "HousingParameters",
    "DesignTargets",
    "ResolutionParameters",
    "PlantingParameters",
    "MIN_TEETH",
    "MAX_TEETH",
    "STEPS_PER_REVOLUTION_RANGE",
    "CLOSURE_RTOL_RANGE",
    "E2_WHOLE_ABS_TOL",
]

MIN_TEETH = 6
# What a build can cut in about ten times its usual time: cutting grows with the teeth beyond
# a few hundred (the paper's curve, teeth stage alone: 22 teeth 2.1 s, 352 5.6 s, 704 11.9 s;
# its full build at 704 teeth 19.6 s against 6 s at 22), and 1000 teeth on a planting gear
# are a module of a tenth of a millimetre.
MAX_TEETH = 1000
STEPS_PER_REVOLUTION_RANGE = (36, 1_000_000)
CLOSURE_RTOL_RANGE = (1e-15, 1e-6)
# 2*e2 must be a whole number; this absorbs the rounding of a decimal such as 1.5 in TOML.
E2_WHOLE_ABS_TOL = 1e-9


class LimaconParameters(_Table):
    """Pascal limacon variant, the pitch curve of the central non-circular gear.

    ``x(t) = a1 (e1 cos t)^2 + b1 cos(t + f1) + g1``,
    ``y(t) = c1 cos(e2 t) sin(e2 t) + d1 cos(t + f2) + g2``, ``r1 = |(x, y)|``.
    """

    kind: Literal["limacon"] = Field(description="pitch curve kind")
    a1: float = Field(description="a1, mm")
    b1: float = Field(description="b1, mm")
    c1: float = Field(description="c1, mm")
    d1: float = Field(description="d1, mm")
    e1: float = Field(description="e1, dimensionless")
    e2: float = Field(gt=0, description="e2, dimensionless; 2*e2 a whole number")
    f1_rad: float = Field(description="phase f1, rad")
    f2_rad: float = Field(description="phase f2, rad")
    g1: float = Field(description="g1, mm")
    g2: float = Field(description="g2, mm")
    teeth: int = Field(ge=MIN_TEETH, le=MAX_TEETH,
                       description="tooth count z of the non-circular gears")

    @field_validator("e2")
    @classmethod
    def _e2_closes(cls, e2: float) -> float:
        # cos(e2 t) sin(e2 t) = sin(2 e2 t)/2 has period pi/e2: one gear turn (2 pi)
        # holds a whole number of periods only if 2*e2 is whole.
        twice = 2.0 * e2
        # Distance of 2*e2 from the nearest whole number, through fmod (exact, finite):
        # 2.0 * e2 overflows to inf above ~9e307 and round(inf) raises OverflowError.
        offset = math.fmod(e2, 0.5)
        if 2.0 * min(offset, 0.5 - offset) > E2_WHOLE_ABS_TOL:
            raise PydanticCustomError(
                "inconsistent",
                "e2 = {e2} makes 2*e2 = {twice} not a whole number, so the pitch curve "
                "does not close over one turn of the gear",
                {"e2": e2, "twice": twice},
            )
        return e2


PitchCurve = Annotated[Union[LimaconParameters], Field(discriminator="kind")]
"""Every pitch curve kind, told apart by ``kind``."""


class TrainParameters(_Table):
    """Planetary gear train: ratios, radii, catching-position directions, speed ratio."""

    i12: float = Field(gt=0, description="ratio i12 (sets A at R(1+i12))")
    i13: float = Field(gt=0, description="ratio i13")
    R: float = Field(gt=0, description="base radius R of carrier 1, mm")
    r: float = Field(gt=0, description="radius r of the circular gears in gearbox 2, mm")
    phi0_deg: float = Field(description="direction phi0 of O->C at catching, deg")
    phic_deg: float = Field(description="direction phic of C->E at catching, deg")
    n: float = Field(gt=1, description="central shaft speed / carrier-1 speed")

    @property
    def phi0_rad(self) -> float:
        """phi0 in radians."""
        return math.radians(self.phi0_deg)

    @property
    def phic_rad(self) -> float:
        """phic in radians."""
        return math.radians(self.phic_deg)


class PlanterParameters(_Table):
    """Planting arm lengths, and the planter shell's sizes for the solids."""

    L1: float = Field(gt=0, description="L1: E to P1, mm")
    L2: float = Field(gt=0, description="L2: P1 to the duckbill tip N, mm")
    arm_width: float = Field(28.0, gt=0, description="width of the arm plate from E to P1, mm")
    arm_thickness: float = Field(8.0, gt=0, description="thickness of the arm plate, mm")
    shell_wall: float = Field(2.5, gt=0, description="wall of the planter tube and blades, mm")


class FieldParameters(_Table):
    """Operating case: planting depth, plant spacings, carrier speed."""

    depth: float = Field(ge=0.1, description="planting depth b, mm")
    plant_spacings: Annotated[
        tuple[Annotated[float, Field(gt=0)], ...], BeforeValidator(_list_to_tuple)
    ] = Field(min_length=1, description="plant spacings S, mm")
    carrier_speed_rpm: float = Field(30.0, ge=0.01, description="carrier-1 speed, r/min")

    @field_validator("plant_spacings")
    @classmethod
    def _no_duplicates(cls, spacings: tuple[float, ...]) -> tuple[float, ...]:
        return _no_repeats(spacings, "plant spacing")



class _Envelope(_Table):
    """Explicit envelope radii of a gearbox about its gear axes, mm (each optional)."""

    def get(self, axis: str, default: float | None = None) -> float | None:
        """The radius given for ``axis`` (e.g. ``"C"``), or ``default`` when not given.

        Dict-like on purpose: callers merge explicit radii over derived ones with
        ``envelope.get(axis, derived_radius)``.
        """
        radius = getattr(self, axis, None) if axis in type(self).model_fields else None
        return default if radius is None else radius


class Gearbox1Envelope(_Envelope):
    """Explicit envelope radii of gearbox 1 about the axes O, A, B, C, mm (each optional)."""

    O: float | None = Field(None, gt=0)
    A: float | None = Field(None, gt=0)
    B: float | None = Field(None, gt=0)
    C: float | None = Field(None, gt=0)


class Gearbox2Envelope(_Envelope):
    """Explicit envelope radii of gearbox 2 about the axes C, D, E, mm (each optional)."""

    C: float | None = Field(None, gt=0)
    D: float | None = Field(None, gt=0)
    E: float | None = Field(None, gt=0)


class HousingParameters(ShellParameters):
    """The gearbox housings: shells round their gears, and optional explicit envelope radii.

    The kinematic envelope circle about each axis is the largest gear tip there plus
    ``clearance`` plus ``wall``: the outside of the solid housing.
    """

    gearbox1: Gearbox1Envelope | None = None
    gearbox2: Gearbox2Envelope | None = None


class DesignTargets(_Table):
    """The agronomic targets the metrics are checked against (the spec's defaults)."""

    trajectory_height_min: float = Field(500.0, gt=0, description="mm")
    hole_width_max: float = Field(30.0, gt=0, description="mm")
    hole_verticality_max: float = Field(10.0, gt=0, description="mm")
    angle_difference_max_deg: float = Field(20.0, gt=0, le=180, description="deg")
    arm_distance_min: float = Field(10.0, ge=0, description="mm")
    ground_clearance_min: float = Field(20.0, ge=0, description="mm")
    module_min: float = Field(2.5, gt=0, description="mm")


class ResolutionParameters(_Table):
    """Numerical resolution knobs."""

    steps_per_revolution: int = Field(
        3600, ge=STEPS_PER_REVOLUTION_RANGE[0], le=STEPS_PER_REVOLUTION_RANGE[1]
    )
    closure_rtol: float = Field(1e-13, ge=CLOSURE_RTOL_RANGE[0], le=CLOSURE_RTOL_RANGE[1])
    sweep_atol: float = Field(1e-6, ge=1e-12, le=1.0,
                              description="the FCL sweeps' certified minima within this, mm")


class PlantingParameters(_Table):
    """Mechanism kind 1: the differential planetary planting mechanism."""

    mechanism: Literal["planting"]
    name: str = Field(pattern=NAME_PATTERN, min_length=1, max_length=NAME_MAX_LENGTH)
    pitch_curve: PitchCurve
    train: TrainParameters
    planter: PlanterParameters
    field: FieldParameters
    housing: HousingParameters = HousingParameters()
    targets: DesignTargets = DesignTargets()
    resolution: ResolutionParameters = ResolutionParameters()
    gears: PlantingCuttingParameters = PlantingCuttingParameters()
    cam: CamParameters = CamParameters()
    ground: GroundParameters = GroundParameters()
    solids: SolidsParameters = SolidsParameters()
    machine: MachineParameters = MachineParameters()
    manufacturing: ManufacturingParameters = ManufacturingParameters()
    dynamics: DynamicsParameters = DynamicsParameters()
    scene: SceneParameters = SceneParameters()
