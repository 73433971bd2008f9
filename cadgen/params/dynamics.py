"""The loads and settings of the dynamics effect (the optional ``[dynamics]`` table).

Every default is stated with its source or reasoning (docs/dynamics.md repeats them):

* gravity acts along -y: the mechanism's plane is vertical (spec: x forward, y up);
* ``seedling_mass_kg`` 0.03: a vegetable pot seedling with its plug from a 72- or
  128-cell tray weighs 15-40 g wet; it rides at the duckbill tip from the catch until the
  duckbill opens (its weight and its inertia);
* ``soil_force_n`` 50: the soil's resistance on the duckbill at the planting depth, growing
  in proportion to the depth below the surface (penetration resistance grows with depth)
  and against the tip's velocity over the ground; 50 N is the ``[machine]`` table's design
  tip load (the paper gives none: measure it in your soil);
* ``bearing_friction`` 0.0015: the SKF simplified friction coefficient of a sealed deep
  groove ball bearing, ``M = mu F d / 2``;
* ``mesh_friction`` 0.05: tooth sliding friction of lubricated steel spur gears (Niemann,
  0.04-0.08), on the mean sliding distance of a contact ratio near 1;
* ``speed_fluctuation`` 0.02: the coefficient Cs of a gear transmission (Shigley, table of
  fluctuation coefficients), for the flywheel;
* motor margins: rated torque at least 1.25 x the RMS (thermal reserve) and the peak at most
  1.6 x rated (IEC 60034-1's momentary excess torque of an induction motor).

The pricking mechanism reads the same table: its soil reaction acts on the needle's tip
(``soil_force_n`` at the vertical pricking depth), its seedling and plant spacing are unused.

``load_case = "none"`` leaves out every external load and loss (seedling, soil, the cam's
spring, friction); gravity stays. Over a carrier turn the mean input torque is then zero,
and the torque less its gravity part scales with the speed squared.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BeforeValidator, Field, field_validator

from cadgen.params._tables import _list_to_tuple, _no_repeats, _Table

__all__ = ["DynamicsParameters", "LOAD_CASES", "SAMPLES_RANGE"]

LOAD_CASES = ("planting", "none")
#: Poses per carrier turn: even (arm 2 is arm 1 half a turn later, on the same grid).
SAMPLES_RANGE = (36, 20000)


class DynamicsParameters(_Table):
    """Loads, friction, the speed sweep and the motor and flywheel rules of the dynamics."""

    load_case: Literal["planting", "none"] = Field(
        "planting", description='"planting": the working loads (planting mechanism: seedling, '
                                'soil, cam spring; pricking: soil on the needle) and friction; '
                                '"none": gravity only')
    seedling_mass_kg: float = Field(0.03, ge=0, le=10,
                                    description="pot seedling mass, kg (planting mechanism)")
    soil_force_n: float = Field(50.0, ge=0, le=1e5,
                                description="soil resistance on the duckbill (the pricking "
                                            "needle) at the depth, N (in proportion to depth)")
    plant_spacing: float | None = Field(
        None, gt=0, description="plant spacing for the tip's velocity over the ground, mm "
                                "(default: the first of field.plant_spacings; planting "
                                "mechanism: the pricking one's is field.forward_speed)")
    bearing_friction: float = Field(0.0015, ge=0, le=0.5,
                                    description="bearing friction coefficient, M = mu F d / 2")
    mesh_friction: float = Field(0.05, ge=0, le=0.5,
                                 description="tooth sliding friction coefficient")
    speeds_rpm: Annotated[tuple[Annotated[float, Field(gt=0, le=1000)], ...],
                          BeforeValidator(_list_to_tuple)] = Field(
        (15.0, 30.0, 45.0, 60.0), description="carrier speeds of the peak-torque sweep, r/min")
    samples: int = Field(720, ge=SAMPLES_RANGE[0], le=SAMPLES_RANGE[1],
                         description="poses per carrier turn (even)")
    speed_fluctuation: float = Field(0.02, gt=0, le=1,
                                     description="flywheel: allowed speed fluctuation Cs")
    rms_margin: float = Field(1.25, ge=1, le=10,
                              description="motor rated torque over the RMS torque, at least")
    overload_ratio: float = Field(1.6, ge=1, le=10,
                                  description="motor peak torque over its rated torque, at most")

    @field_validator("samples")
    @classmethod
    def _even(cls, samples: int) -> int:
        if samples % 2:
            raise ValueError(f"samples must be even (arm 2 runs half a turn later on the same "
                             f"grid), not {samples}")
        return samples

    @field_validator("speeds_rpm")
    @classmethod
    def _each_once(cls, speeds: tuple) -> tuple:
        return _no_repeats(speeds, "speed")
