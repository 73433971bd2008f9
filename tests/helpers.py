"""Small helpers shared by tests: edited copies of the reference parameter file, an FCL model,
a build started through the studio, the processes a command left (from /proc)."""

import re
from pathlib import Path

REFERENCE = Path(__file__).resolve().parents[1] / "params" / "xin2024-planter.toml"


def reference_text() -> str:
    return REFERENCE.read_text(encoding="utf-8")


def edited(**changes) -> str:
    """The reference file with ``key = value`` lines replaced (key names are unique in it)."""
    text = reference_text()
    for key, value in changes.items():
        text, count = re.subn(rf"(?m)^{re.escape(key)}\s*=\s*[^#\n]*", f"{key} = {value} ", text)
        assert count == 1, f"key {key!r} not found exactly once in the reference file"
    return text


def with_keys(text: str, table: str, **keys) -> str:
    """``text`` with ``key = value`` set in ``[table]``: a key already there is replaced, a
    missing one added under the header, a missing table appended (values are TOML text)."""
    header = re.search(rf"(?m)^\[{re.escape(table)}\][^\n]*\n", text)
    if header is None:
        return text + f"\n[{table}]\n" + "".join(f"{k} = {v}\n" for k, v in keys.items())
    start = header.end()
    following = re.search(r"(?m)^\[", text[start:])
    end = start + following.start() if following else len(text)
    body = text[start:end]
    for key, value in keys.items():
        body, count = re.subn(rf"(?m)^{re.escape(key)}\s*=\s*[^#\n]*", f"{key} = {value} ", body)
        if not count:
            body = f"{key} = {value}\n" + body
    return text[:start] + body + text[end:]


def fcl_bvh(mesh):
    """A python-fcl BVH model of a trimesh mesh (the scene builds its own; tests compare)."""
    import fcl
    import numpy as np

    model = fcl.BVHModel()
    model.beginModel(len(mesh.faces), len(mesh.vertices))
    model.addSubModel(np.asarray(mesh.vertices, dtype=np.float64),
                      np.asarray(mesh.faces, dtype=np.int32))
    model.endModel()
    return model


def gears_in_their_housings(assembly, housings, phi: float):
    """``(part, housing name, housing, 4x4 pose in the housing's body)`` of every gear of a
    planting assembly at carrier angle ``phi``: its housing is the one whose cavity holds its
    face (the central shaft's and the sleeve's gears turn in the frame though they ride on
    carrier 1's body), found from the world placements, not from the parts' bodies."""
    import numpy as np

    bodies = {"gearbox1": "carrier1", "gearbox2": "gearbox2", "frame": "frame"}
    boxes = dict(zip(("gearbox1", "gearbox2", "frame"), housings))
    world = {name: pose for name, _, pose in assembly.placements(phi)}
    for part in assembly.parts:
        if part.kind != "gear":
            continue
        first = part.instances[0] if part.instances else (part.name, part.body, 0.0)
        pose = world[first[0]]
        middle = pose[2, 3] + float(part.mesh.bounds[:, 2].mean())
        name = next(n for n, h in boxes.items()
                    if h.z_cavity_bottom <= middle <= h.z_cavity_bottom + h.cavity_height)
        yield part, name, boxes[name], np.linalg.solve(
            assembly.body_pose(bodies[name], phi + first[2]), pose)


def start_studio_build(url: str, moment: str | None, *, timeout: float,
                       effects: list | None = None) -> None:
    """Start a build through the studio at ``url`` (its URL with the token), of the design it
    opened (with the scene's ``effects`` if given); return once the build's events reach
    stage ``moment`` (``"done"``: its end; None: at once). AssertionError if the build ends
    before."""
    import json
    import urllib.request

    base, token = url.split("/?token=")
    headers = {"X-Cadgen-Token": token, "Content-Type": "application/json"}

    def call(path, body=None):
        request = urllib.request.Request(base + path, headers=headers, data=body,
                                         method="POST" if body else "GET")
        return urllib.request.urlopen(request, timeout=timeout)

    params = json.loads(call("/api/design").read())["params"]
    if effects is not None:
        params.setdefault("scene", {})["effects"] = list(effects)
    job = json.loads(call("/api/build", json.dumps({"params": params}).encode()).read())
    if moment is None:
        return
    for line in call(job["events"]):   # server-sent events: "data: {...}"
        event = json.loads(line[5:]) if line.startswith(b"data:") else {}
        if event.get("stage") == moment or event.get("type") == moment:
            return
    raise AssertionError(f"the build ended before {moment}")


#: The environment variable whose value tags the processes of one command a test starts:
#: every process it starts inherits it, whatever becomes of its parent.
TAG_VARIABLE = "CADGEN_TEST_TAG"


def tagged_processes(tag: str) -> list[str]:
    """The processes alive (zombies are dead) whose environment has :data:`TAG_VARIABLE`
    set to ``tag``, read from /proc (``"pid (name)"`` each)."""
    needle = f"{TAG_VARIABLE}={tag}".encode() + b"\0"
    alive = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if needle not in (entry / "environ").read_bytes():
                continue
            stat = (entry / "stat").read_text()
        except OSError:   # ended meanwhile, or not ours to read
            continue
        if stat[stat.rindex(")") + 2] != "Z":
            alive.append(stat[:stat.rindex(")") + 1])
    return alive


def stages_before_dynamics(path=REFERENCE):
    """A build of ``path`` run through the stages the dynamics reads (kinematics, metrics, cam,
    drivetrain), not the dynamics themselves: ``run.values`` holds their results."""
    from cadgen.params import load_params
    from cadgen.pipeline import build as pipeline
    from cadgen.pipeline.plan import check_build

    checked = check_build(load_params(path), effects=["dynamics"])
    run = pipeline._Build(checked.params, [s for s in checked.stages if s != "dynamics"], None)
    run.effects, run.parallel = checked.effects, False
    run.run(pipeline.STAGE_FUNCTIONS)
    return run


def exudyn_couple_error(exu, mbs, constraint: int, omega: float, grid, moment):
    """Solve an Exudyn system (not yet assembled) over one and a half turns at ``omega`` (rad/s)
    and compare the couple of its rotation ``constraint`` (its multiplier) with ``moment``
    (N m) given on the angle ``grid`` (rad, one turn): ``(largest difference over the last
    whole turn, peak of ours)``. The first half turn is left out: the solver starts from
    inconsistent accelerations, a transient its numerical damping removes."""
    import math

    import numpy as np
    from exudyn.utilities import SensorObject

    sensor = mbs.AddSensor(SensorObject(
        objectNumber=constraint, storeInternal=True,
        outputVariableType=exu.OutputVariableType.Force))
    mbs.Assemble()
    simulation = exu.SimulationSettings()
    period = 2 * math.pi / omega
    steps = 1500
    simulation.timeIntegration.numberOfSteps = steps
    simulation.timeIntegration.endTime = 1.5 * period
    simulation.timeIntegration.verboseMode = 0
    simulation.solutionSettings.sensorsWritePeriod = 1.5 * period / steps
    # some numerical damping: with none (the trapezoidal rule) an index-3 solver's
    # multipliers drift; they converge at second order with it
    simulation.timeIntegration.generalizedAlpha.spectralRadius = 0.6
    exu.SolveDynamic(mbs, simulation)
    data = mbs.GetSensorStoredData(sensor)          # [t, lambda]
    angle = omega * data[:, 0]
    theirs = data[:, 1]
    # ours on the exact same angles (periodic interpolation of the grid)
    ours = np.interp(np.mod(angle, 2 * np.pi), np.append(grid, 2 * np.pi),
                     np.append(moment, moment[0]))
    sign = np.sign(np.sum(ours * theirs))       # Exudyn's multiplier sense
    keep = angle >= np.pi
    return float(np.max(np.abs(sign * theirs[keep] - ours[keep]))), float(np.max(np.abs(ours)))


def exudyn_prescribe(mbs, ground_marker: int, node: int, coordinate: int, law):
    """Constrain a node's ``coordinate`` to its reference plus ``law(t)`` in an Exudyn system;
    returns the constraint (its multiplier is the force or couple that drives it)."""
    from exudyn.utilities import CoordinateConstraint, MarkerNodeCoordinate

    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=coordinate))
    return mbs.AddObject(CoordinateConstraint(
        markerNumbers=[ground_marker, marker],
        offsetUserFunction=lambda mbs_, t, item, offset: law(t)))
