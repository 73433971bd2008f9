"""Parameter files: TOML format, schema and all-problems-at-once validation.

A parameter file names its mechanism kind and holds one table per part of the design:

* ``mechanism = "planting"`` (kind 1, :class:`PlantingParameters`): the differential
  planetary planting mechanism, tables ``[pitch_curve]``, ``[train]``, ``[planter]``,
  ``[field]`` and the optional ``[housing]``, ``[targets]``, ``[resolution]``, ``[gears]``,
  ``[cam]``, ``[ground]``, ``[solids]``, ``[machine]``, ``[manufacturing]``;
* ``mechanism = "pricking"`` (kind 2, :class:`PrickingParameters`): the inclined
  hole-pricking mechanism, inverse-designed from its needle-tip loop, tables
  ``[trajectory]``, ``[linkage]``, ``[field]`` and the optional ``[gears]``,
  ``[resolution]``, ``[housing]``, ``[ground]``, ``[solids]``, ``[machine]``,
  ``[manufacturing]``. Only the structure of the
  type-value points is checked here (at least 5 pairs of finite numbers); their geometry
  (repeated points, self-intersection, the sun centre inside the loop) is the kinematic
  model's to judge.

The schema is a set of frozen pydantic models, strict about types (a quoted ``"36"``
is not a number, ``true`` is not a number, an integer is accepted where a float is
asked), finite floats no larger than :data:`MAX_MAGNITUDE` (1e6) in magnitude, and no
unknown keys. :func:`load_params` and :func:`validate_text` never stop at the first
problem: they raise one :class:`ParameterError` that lists every problem found, each a
:class:`~kinematics.errors.Problem` with a dotted field path (``train.R``,
``field.plant_spacings.1``; a key that cannot be bare in TOML is quoted as TOML
quotes it, ``planter."L 1"``), a short code and a sentence naming the bad value.

Problem codes raised here:

==================  =====================================================================
code                meaning
==================  =====================================================================
file_not_found      the file does not exist
not_readable        the path is a directory or cannot be read
not_utf8            the file is not UTF-8 text
toml_syntax         the text is not valid TOML (message has line and column)
too_deep            arrays or inline tables nested hundreds of levels deep (valid TOML, but
                    more than the reader's stack holds)
missing             a required key or table is absent
unknown_key         a key or table the schema does not know (with "did you mean")
wrong_type          e.g. a string or boolean where a number is asked
out_of_range        a number outside its allowed interval; an integer of more than 4300
                    digits is reported alone, like a syntax error (at its path; a decimal
                    one, which the TOML reader refuses, at its line and column)
not_finite          nan or inf
empty               an array that must not be empty
invalid_name        the design name cannot name an output folder
unknown_mechanism   ``mechanism`` names no known mechanism kind
unknown_kind        a ``kind`` (e.g. ``pitch_curve.kind``) names no known kind
inconsistent        a value contradicts a rule that needs no kinematics (``2*e2`` whole)
duplicate           a plant spacing or an inclination given twice (reported at the repeat)
not_allowed         a value outside a fixed set of choices: ``trajectory.degree`` not 3 or 5,
                    ``gears.split_exponent`` a string other than ``"equal-perimeter"``
wall_too_thin       ``housing.wall`` below the 2-mm minimum (:data:`MIN_WALL`)
==================  =====================================================================

And ``profile_shift_changes_centre_distance``: two ``gears.profile_shift`` values in one
chain of meshes that do not alternate in sign (V-zero), at the second one, naming the pair
(:mod:`cadgen.params.cutting`; the feasibility checks add ``profile_shift_pointed``).

Where array problems are reported: an array item at its index
(``field.inclinations_deg.1``); a type-value point that is not a pair of two finite
numbers once, at the point's index (``trajectory.points.3``: ``wrong_type`` for a
wrong shape or a non-number item, ``not_finite`` for nan or inf); too few points at
the array itself (``trajectory.points``, ``out_of_range``).

Once the file is structurally valid, :func:`cadgen.params.feasibility.design_problems`
adds the problems that need the kinematic model (their codes are its own). Those of
one build stage (the duckbill linkage and cam timing: stage ``cam``) do not refuse
the file: they come back attached to the parameters (:func:`stage_problems`) and a
build refuses the design only when its scene runs that stage (otherwise they are
warnings in its report).
Validation never writes anything.

Modules: :mod:`~cadgen.params.planting` and :mod:`~cadgen.params.pricking` (the tables
of each mechanism kind), :mod:`~cadgen.params.loading` (reading, parsing, validating,
:class:`ParameterError`), ``_problems`` (pydantic errors to problems and their
sentences) and ``_tables`` (the base model and shared validators). The public names
are re-exported here: import them from :mod:`cadgen.params`.
"""

from __future__ import annotations

from cadgen.params._tables import MAX_MAGNITUDE, NAME_PATTERN
from cadgen.params.loading import (
    MECHANISM_KINDS,
    DesignParameters,
    ParameterError,
    load_params,
    stage_problems,
    validate_data,
    validate_text,
)
from cadgen.params.planting import (
    CLOSURE_RTOL_RANGE,
    MAX_TEETH,
    MIN_TEETH,
    STEPS_PER_REVOLUTION_RANGE,
    DesignTargets,
    FieldParameters,
    Gearbox1Envelope,
    Gearbox2Envelope,
    HousingParameters,
    LimaconParameters,
    PitchCurve,
    PlanterParameters,
    PlantingParameters,
    ResolutionParameters,
    TrainParameters,
)
from cadgen.params.pricking import (
    EQUAL_PERIMETER,
    INCLINATION_MAX_DEG,
    INVERSE_GRID_RANGE,
    MIN_TYPE_VALUE_POINTS,
    SPLIT_EXPONENT_RANGE,
    TRAJECTORY_DEGREES,
    GearParameters,
    LinkageParameters,
    PrickingFieldParameters,
    PrickingParameters,
    PrickingResolutionParameters,
    SplitExponent,
    TrajectoryParameters,
)
from cadgen.params.cam import CamParameters, CamTimingParameters, DuckbillParameters, LeverParameters
from cadgen.params.cutting import (PROFILE_SHIFT_RANGE, CuttingParameters,
                                   PlantingCuttingParameters, PlantingShifts, PrickingShifts)
from cadgen.params.solids import MIN_WALL, GroundParameters, ShellParameters, SolidsParameters
from cadgen.params.machine import (DEFAULT_BUILD_VOLUME, PROCESSES, MachineParameters,
                                   ManufacturingParameters, PrickingMachineParameters,
                                   PrickingShaftDiameters, ShaftDiameters)
from cadgen.params.dynamics import DynamicsParameters

__all__ = [
    "ParameterError",
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
    "TrajectoryParameters",
    "LinkageParameters",
    "GearParameters",
    "PrickingFieldParameters",
    "PrickingResolutionParameters",
    "PrickingParameters",
    "SplitExponent",
    "CuttingParameters",
    "PlantingCuttingParameters",
    "PlantingShifts",
    "PrickingShifts",
    "PROFILE_SHIFT_RANGE",
    "CamParameters",
    "DuckbillParameters",
    "LeverParameters",
    "CamTimingParameters",
    "ShellParameters",
    "GroundParameters",
    "SolidsParameters",
    "MachineParameters",
    "DynamicsParameters",
    "ManufacturingParameters",
    "ShaftDiameters",
    "PrickingMachineParameters",
    "PrickingShaftDiameters",
    "PROCESSES",
    "DEFAULT_BUILD_VOLUME",
    "MIN_WALL",
    "DesignParameters",
    "MECHANISM_KINDS",
    "NAME_PATTERN",
    "MAX_MAGNITUDE",
    "MIN_TEETH",
    "MAX_TEETH",
    "STEPS_PER_REVOLUTION_RANGE",
    "CLOSURE_RTOL_RANGE",
    "EQUAL_PERIMETER",
    "TRAJECTORY_DEGREES",
    "MIN_TYPE_VALUE_POINTS",
    "SPLIT_EXPONENT_RANGE",
    "INCLINATION_MAX_DEG",
    "INVERSE_GRID_RANGE",
    "load_params",
    "validate_text",
    "validate_data",
    "stage_problems",
]
