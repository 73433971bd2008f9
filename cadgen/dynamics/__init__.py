"""Dynamics of a mechanism over one carrier turn: drive torque, joint and mesh forces.

The ``dynamics`` effect (a build stage of the same name) runs :func:`planting_dynamics`
(the pricking mechanism: :func:`pricking_dynamics`, :mod:`cadgen.dynamics.pricking`, the same
result and report):
every moving body's mass, centre of mass and inertia (from the solids when they were built,
else estimated from the parameters: :mod:`cadgen.dynamics.mass`), the known loads of
``[dynamics]`` (:mod:`cadgen.dynamics.loads`), and an inverse-dynamics solve on a uniform grid
of carrier angles by two routes that must agree (:mod:`kinematics.rigid_dynamics`).

The API the tooth-strength check reads
--------------------------------------
``result = planting_dynamics(params, mechanism, drivetrain, ...)`` (or the build stage's
value, ``run.values["dynamics"]``) is a :class:`DynamicsResult`:

* ``result.phi`` (n,) carrier angles (rad, uniform, 0 = arm 1 catching);
* ``result.meshes`` ``{(driver, driven, side): MeshLoad}``: every gear mesh, the gear names
  as the gear train's stages name them (``stage.generated.pair.names``, e.g.
  ``("central", "intermediate", 1)``, ``("gear D", "planet gear E", 2)``; the drive's two
  pairs, one for the machine, have side 0). A :class:`MeshLoad` holds, over ``result.phi``:

  - ``normal_force_n`` (n,) N, the tooth force along the line of action (>= 0; circular
    pairs: at the pressure angle from the common tangent; the non-circular pair: from the
    pitch curves' local tangent at the pitch point);
  - ``contact_angle[gear]`` (n,) rad: the polar angle of the pitch point in that gear's own
    frame (the gear as it sits at the catching pose, ``phi = 0``), for each of the two gears;
  - ``contact_radius[gear]`` (n,) mm: the pitch point's distance from that gear's axis;
  - ``line_of_action`` (n, 2): the unit direction of the force on the driven gear (world
    frame; its sign says which flank carries);
  - ``pitch_parameter`` (n,) rad for the non-circular pair: ``t`` of the central gear's pitch
    curve ``r1(t)`` at the contact (the intermediate's radius there is ``a - r1(t)``), None
    for a circular pair. The pricking mechanism's two meshes are keyed ``("sun",
    "intermediate 1", 0)`` and ``("intermediate 2", "planet", 0)``, and their
    ``pitch_parameter`` is the pair's cycle parameter ``tau``
    (:class:`~cadgen.gears.pairs.PitchPair`'s, the curve parameter from the outer dead
    centre): ``train_strength(..., mesh_forces={(driver, driven): (m.pitch_parameter,
    m.normal_force_n)})``.

  So the bending and contact stresses at each pose follow from ``normal_force_n`` and the
  local pitch radius and curvature at ``pitch_parameter`` (or ``contact_radius``).
* ``result.input_torque`` (n,) N m and ``result.input_power`` (n,) W at the input shaft
  (``result.input_rpm``), ``result.bearings`` ``{pin: (n, 2) N}``, ``result.shaking_force``,
  ``result.shaking_moment``, ``result.cam`` (the roller's contact and the spring's force).

:func:`dynamics_report` is report.json's ``dynamics``.
"""

from cadgen.dynamics.analysis import (DynamicsResult, MeshLoad, dynamics_report,
                                      motor_and_flywheel, planting_dynamics)
from cadgen.dynamics.pricking_analysis import pricking_dynamics

__all__ = ["DynamicsResult", "MeshLoad", "dynamics_report", "motor_and_flywheel",
           "planting_dynamics", "pricking_dynamics"]
