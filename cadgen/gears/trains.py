"""Every gear of a mechanism's trains: generated, phased, checked, meshed, drawn.

Planting mechanism: gearbox 2's non-circular pair (central gear -> intermediate)
and its 1:1 circular pair (D -> E), and train 1's two sets on the axes O, A, B, C
(each sun -> idler -> idler -> planet: set II, converted ratio -2/(n - 1), carries
gearbox 2; set I, -1/(n - 1), holds the central gear still). Pricking mechanism: stage 1 (sun ->
first intermediate) and stage 2 (second intermediate -> planet). Every stage is
phased at the mechanism's start position; a gear in two meshes is cut once.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from kinematics.errors import DesignError

from kinematics.profile_shift import shift_key

from cadgen.gears.advice import advise_train, planting_hints, pricking_hints
from cadgen.gears.circular import (TRAIN1_SETS, _radius_hint, circular_module, holding_set_design,
                                   planting_circular_radii, planting_drive)
from cadgen.gears.pairs import (FAILING_PROBLEMS, MIN_ROOT_THICKNESS, PitchPair, circle_pair,
                                generate_pair)
from cadgen.gears.meshing import meshing_check, relieve_interference
from cadgen.gears.teeth import ToothSystem

__all__ = ["GearStage", "GearTrain", "planting_pair", "planting_train", "pricking_train",
           "train_report", "set_report"]


@dataclass(frozen=True)
class GearStage:
    name: str
    generated: object
    meshing: object
    placement: tuple  # (frame angle rad, drive centre (x, y)) of the pair frame at the start
    relief: dict | None = None


@dataclass(frozen=True)
class GearTrain:
    stages: tuple
    failures: tuple = ()   # (stage name, Problem) for stages whose gears cannot be cut
    rims: tuple = ()       # cadgen.machine.hubs.RimCheck per gear, once bored for its shaft
    # train 1's parallel sets (planting): their ratios and each mesh's axis distance
    sets: tuple = ()       # ({"name", "key", "converted_ratio", "axes": (O, A, B, C)}, ...)
    drive: object = None   # cadgen.gears.drive.DriveDesign of the frame's two pairs (planting)
    # cadgen.gears.strength_summary.TrainStrength: every gear's tooth strength over the cycle
    strength: object = None
    # the gear cache the train was cut with (or None): its files are looked up there too
    cache: object = field(default=None, repr=False, compare=False)

    @property
    def gears(self):
        """Each distinct gear once: (profile, check, stage, index in its pair)."""
        seen, out = set(), []
        for stage in self.stages:
            for k, (profile, check) in enumerate(zip(stage.generated.profiles,
                                                     stage.generated.checks)):
                if profile.name not in seen:
                    seen.add(profile.name)
                    out.append((profile, check, stage, k))
        return out


def _system(cutting, module) -> ToothSystem:
    return ToothSystem(module, pressure_angle=cutting.pressure_angle_rad, addendum=cutting.addendum,
                       dedendum=cutting.dedendum, tip_radius=cutting.tip_radius,
                       backlash=cutting.backlash if cutting.backlash is not None else 0.0)


def _shift_table(cutting) -> dict:
    """``{gears.profile_shift key: x}`` of every gear, each mate's shift filled in (V-zero):
    :meth:`cadgen.params.cutting.ShiftTable.resolved`; empty for a table without shifts."""
    table = getattr(cutting, "profile_shift", None)
    return dict(table.resolved()) if table is not None else {}


def _shifts(table: dict, pair) -> tuple:
    """The (drive, driven) profile shifts of ``pair``'s gears."""
    return tuple(float(table.get(shift_key(name), 0.0)) for name in pair.names)


#: Poses of the meshing check over one tooth pitch of a circular pair.
CIRCULAR_PITCH_POSES = 32


def _stage(name, pair, teeth, system, cutting, placement, drive=None, circular=False, cache=None,
           shifts=(0.0, 0.0), working=None, shortening=(0.0, 0.0)):
    """One pair cut, checked and meshed (tip relief if needed); looked up in ``cache`` first
    (a :class:`~cadgen.gears.cache.GearCache` or None) and stored there once computed.
    ``shifts``: the (drive, driven) profile shifts (V-zero, or any two on circular gears cut
    on ``pair``'s reference circles and meshed on ``working``, the pair of rolling circles at
    the working centre distance)."""
    bore = cutting.bore_diameter / 2
    force_shaper = cutting.cutter == "shaper"
    counts = (teeth, teeth) if np.isscalar(teeth) else tuple(teeth)
    # a circular pair's mesh repeats every tooth pitch: one pitch, finely, checks every pose
    span = pair.period / counts[0] if circular else None
    poses = cutting.meshing_poses or (CIRCULAR_PITCH_POSES if circular
                                      else max(96, 8 * max(counts)))
    key = None
    if cache is not None:
        from cadgen.gears.cache import stage_key

        key = stage_key(name, working or pair, teeth, system, flank_points=cutting.flank_points,
                        bore_radius=bore, force_shaper=force_shaper, poses=poses, span=span,
                        circular=circular, drive=drive, shifts=shifts
                        if not any(shortening) else tuple(shifts) + tuple(shortening))
        stored = cache.get(key)
        if stored is not None:
            generated, report, relief = stored
            # the pair's contact functions are closures, never stored: the caller's, re-attached
            return GearStage(name, dataclasses.replace(generated, pair=working or pair), report,
                             placement, relief)
    stage = _cut_stage(name, pair, teeth, system, bore, force_shaper, cutting.flank_points,
                       placement, drive, poses, span, shifts, working, shortening)
    if cache is not None:   # a stage that raised (DesignError) never gets here: not cached
        cache.put(key, (dataclasses.replace(stage.generated, pair=None), stage.meshing,
                        stage.relief))
    return stage


def _cut_stage(name, pair, teeth, system, bore, force_shaper, flank_points, placement, drive,
               poses, span, shifts=(0.0, 0.0), working=None, shortening=(0.0, 0.0)):
    options = dict(system=system, bore_radius=bore, flank_points=flank_points,
                   force_shaper=force_shaper, shifts=shifts, shortening=shortening)
    if drive is not None:
        generated = generate_pair(pair, teeth, drive_phase=drive[0], drive_gear=drive[1],
                                  **options)
    else:
        generated = generate_pair(pair, teeth, **options)
    if working is not None:   # cut on the reference circles, meshed at the working distance
        generated = dataclasses.replace(generated, pair=working)
        pair = working
    report = meshing_check(generated.profiles[0], generated.profiles[1], pair, poses=poses,
                           span=span)
    relief = None
    # relieve only a drive cut for this mesh alone: a drive that already meshes elsewhere (an
    # idler of train 1) is not re-cut here; any interference there stays in the report
    if report.overlap_area_max > 0.0 and drive is None:
        # tip interference (a shaper-cut concave stretch against a tight convex one, say):
        # relieve the drive's tips by what its mate sweeps there, then check again
        original = generated.profiles[0]
        outline, area, depth = relieve_interference(original, generated.profiles[1], pair,
                                                    report)
        relieved = dataclasses.replace(generated.profiles[0], outline=outline)
        generated = dataclasses.replace(generated, profiles=(relieved, generated.profiles[1]))
        before = report
        # the relief changes the drive's tips near a few poses: the others keep their results
        report = meshing_check(relieved, generated.profiles[1], pair, poses=poses, span=span,
                               previous=(before, original.outline))
        relief = {"gear": relieved.name, "removed_area_mm2": area, "depth_mm": depth,
                  "overlap_before_mm2": before.overlap_area_max,
                  "interfering_poses_before": before.interference_poses}
    return GearStage(name, generated, report, placement, relief)


def _carry(generated):
    """A pair's driven gear, to drive the next mesh: the body angle of one of its tooth
    centres (arc lengths of the two meshes start at different contacts) and the cut gear."""
    from cadgen.gears.pairs import angle_at_arc

    return (angle_at_arc(generated.curves[1], generated.phases[1]),
            (generated.profiles[1], generated.checks[1], generated.spaces[1]))


def planting_pair(mechanism) -> PitchPair:
    """Gearbox 2's non-circular pair as contact functions of the central gear's turn."""
    closure = mechanism.closure
    curve, law, a = mechanism.pitch_curve, closure.law, closure.centre_distance

    def central(t):
        r, dr, _ = curve.radius_derivatives(t)
        t = np.asarray(t, dtype=float)
        return r, dr, t, np.ones_like(t)

    def intermediate(t):
        r, dr, _ = curve.radius_derivatives(t)
        w, _ = law.ratio(t)
        return a - r, -dr, np.pi - law.integral(t), -w

    return PitchPair(("central", "intermediate"), a, 2 * np.pi, central, intermediate)


def _report_to(progress, total):
    """``progress(done, total, pair name)`` after each pair, or nothing (``progress=None``)."""
    done = [0]

    def cut(name):
        done[0] += 1
        if progress is not None:
            progress(done[0], total, name)
    return cut


def planting_train(params, mechanism, progress=None, cache=None, drive=None) -> GearTrain:
    """The planting mechanism's gears at the catching position (phi = 0).

    ``progress(done, total, pair name)``, optional, is called as each of the ten pairs is cut.
    ``cache``, a :class:`~cadgen.gears.cache.GearCache` or None, answers pairs cut before.
    ``drive``: the frame's :class:`~cadgen.gears.drive.DriveDesign` as the drivetrain sized
    it (``Drivetrain.drive``); None designs it from the parameters alone.
    """
    cut = _report_to(progress, 10)
    cutting = params.gears
    shifts = _shift_table(cutting)
    a = mechanism.centre_distance
    teeth = params.pitch_curve.teeth
    pair = planting_pair(mechanism)
    box = mechanism.phic
    C = np.asarray(mechanism.positions(np.array([0.0]), points=("C",))["C"][0])
    module_nc = mechanism.module(teeth)   # the spec: module from perimeter and z
    stages = [_stage("non-circular pair", pair, teeth, _system(cutting, module_nc), cutting,
                     (box, C), cache=cache, shifts=_shifts(shifts, pair))]
    cut(stages[-1].name)
    # circular gears: gearbox 2's 1:1 pair and train 1's set with converted ratio -1
    radii = planting_circular_radii(mechanism)
    try:
        module = circular_module(radii, cutting.circular_module)
    except DesignError:   # again, naming the base radii that would work too
        module = circular_module(radii, cutting.circular_module, hint=_radius_hint(mechanism))
    system = _system(cutting, module)
    z = [int(round(2 * x / module)) for x in radii]
    D = C + a * np.array([math.cos(box), math.sin(box)])
    pair = circle_pair(("gear D", "planet gear E"), mechanism.r, mechanism.r)
    stages.append(_stage("1:1 pair (D to E)", pair, (z[4], z[4]), system, cutting, (box, D),
                         circular=True, cache=cache, shifts=_shifts(shifts, pair)))
    cut(stages[-1].name)
    carrier = mechanism.phi0
    line = np.array([math.cos(carrier), math.sin(carrier)])
    axes = [0.0] + [mechanism.carrier_radii[axis] for axis in ("A", "B", "C")]
    sets = []
    for key, set_name, _, names in TRAIN1_SETS:
        design = None
        if key == "II":
            set_radii, set_system = radii[:4], system
        else:
            design = holding_set_design(mechanism, cutting.circular_module,
                                        cutting.pressure_angle_rad)
            set_radii, set_system = design.reference_radii, _system(cutting, design.module)
        counts = [int(round(2 * x / set_system.module)) for x in set_radii]
        carried = None   # a gear cut in one mesh, carried into the next
        for k in range(3):
            pair = circle_pair((names[k], names[k + 1]), set_radii[k], set_radii[k + 1])
            working, mesh_shifts, short = None, _shifts(shifts, pair), (0.0, 0.0)
            if design is not None and design.shifted:   # V pairs at the axis distances
                working = circle_pair(pair.names, *design.working_radii(k))
                mesh_shifts = design.shifts[k], design.shifts[k + 1]
                short = design.shortening[k], design.shortening[k + 1]
            stage = _stage(f"train 1 set {key}: {names[k]} to {names[k + 1]}", pair,
                           (counts[k], counts[k + 1]), set_system, cutting,
                           (carrier, axes[k] * line), drive=carried, circular=True, cache=cache,
                           shifts=mesh_shifts, working=working, shortening=short)
            stages.append(stage)
            cut(stage.name)
            carried = _carry(stage.generated)
        ratio = (-2.0 if key == "II" else -1.0) / (mechanism.n - 1.0)
        sets.append({"key": key, "name": set_name, "converted_ratio": ratio,
                     "rule": design.rule if design is not None else
                     "standard gears: whole teeth at the axis distances",
                     "axes": ("O", "A", "B", "C"), "axis_distances": tuple(
                         float(axes[k + 1] - axes[k]) for k in range(3)),
                     "stages": tuple(s.name for s in stages[-3:])})
    # the frame's drive: the input shaft turns the central shaft and carrier 1 the same way;
    # the drivetrain's (designed round the shafts it sized) when given
    if drive is None:
        drive = planting_drive(mechanism, module, cutting.circular_module,
                               params.field.carrier_speed_rpm, cutting.pressure_angle_rad)
    drive_system = _system(cutting, drive.module_1)
    origin = np.array([-drive.centre_distance, 0.0])
    for k, names in enumerate((("input gear 1", "central shaft gear"),
                               ("input gear 2", "transmission driven gear"))):
        pair = circle_pair(names, drive.radii[2 * k], drive.radii[2 * k + 1])
        stage = _stage(f"drive: {names[0]} to {names[1]}", pair,
                       (drive.teeth[2 * k], drive.teeth[2 * k + 1]), drive_system, cutting,
                       (0.0, origin), circular=True, cache=cache, shifts=_shifts(shifts, pair))
        stages.append(stage)
        cut(stage.name)
    train = GearTrain(tuple(stages), cache=cache, sets=tuple(sets), drive=drive)
    return advise_train(train, planting_hints(mechanism, teeth, cutting))


def pricking_train(params, design, progress=None, cache=None) -> GearTrain:
    """The pricking mechanism's two non-circular stages at the outer dead centre.

    ``progress(done, total, stage name)``, optional, is called as each stage is cut (or found
    not cuttable). ``cache``: as for :func:`planting_train` (a stage not cuttable is not stored).
    """
    cut = _report_to(progress, 2)
    cutting = params.gears
    shifts = _shift_table(cutting)
    motion, link = design.motion, design.linkage
    functions, breaks = design.cycle_functions()
    stages = []
    carrier = motion.phi1_start
    line = np.array([math.cos(carrier), math.sin(carrier)])
    centre = np.asarray(link.centre, dtype=float)
    failures = []
    for index, (drive, driven) in enumerate((("sun", "intermediate 1"),
                                             ("intermediate 2", "planet"))):
        pair = PitchPair((drive, driven), link.a, motion.period, functions[drive],
                         functions[driven], breaks=breaks)
        system = _system(cutting, design.modules[index])
        try:
            stages.append(_stage(f"stage {index + 1}", pair, design.teeth[index], system, cutting,
                                 (carrier, centre + index * link.a * line), cache=cache,
                                 shifts=_shifts(shifts, pair)))
        except DesignError as error:  # reported with the gear and the reason; others go on
            failures += [(f"stage {index + 1}", problem) for problem in error.problems]
        cut(f"stage {index + 1}")
    train = GearTrain(tuple(stages), tuple(failures), cache=cache)
    return advise_train(train, pricking_hints(design, cutting))


def _placements(train: GearTrain):
    """Every gear at the start position: (profile, angle, centre) for the assembled sheet."""
    out, seen = [], set()
    for stage in train.stages:
        frame, origin = stage.placement
        pair = stage.generated.pair
        rotations = pair.rotations(np.array([0.0]))
        turn = np.array([math.cos(frame), math.sin(frame)])
        for k, profile in enumerate(stage.generated.profiles):
            if profile.name in seen:
                continue
            seen.add(profile.name)
            centre = np.asarray(origin) + (pair.centre_distance * turn if k == 1 else 0.0)
            out.append((profile, float(rotations[k][0] + frame), tuple(centre)))
    return out


def train_report(train: GearTrain) -> dict:
    gears = []
    for profile, check, stage, _ in train.gears:
        gears.append({
            "gear": profile.name, "stage": stage.name, "teeth": profile.teeth,
            "module_mm": profile.module, "profile_shift": check.profile_shift,
            "cutter": check.cutter,
            "shaper_teeth": check.shaper_teeth, "convex": check.convex,
            "concave_teeth": check.concave_teeth, "curvature_min_per_mm": check.curvature_min,
            "undercut_teeth": check.undercut_teeth, "root_thickness_min_mm": check.root_thickness_min,
            "pointed_teeth": check.pointed_teeth, "tip_thickness_min_mm": check.tip_thickness_min,
            "pressure_angle_deviation_max_deg": check.pressure_angle_deviation_max_deg,
            "undercut_root_thickness_min_mm": check.undercut_root_thickness_min,
            "root_thickness_limit_mm": check.root_thickness_limit,
            "problems": [{"code": c, "message": m,
                          "severity": "failure" if c in FAILING_PROBLEMS else "warning"}
                         for c, m in check.problems],
            "outline_points": int(len(profile.outline)),
        })
        if train.strength is not None and profile.name in train.strength.gears:
            gears[-1].update(train.strength.gears[profile.name].as_dict())
    meshes = [{
        "stage": s.name, "gears": list(s.generated.pair.names),
        "centre_distance_mm": s.generated.pair.centre_distance,
        "poses": s.meshing.poses, "cycle_fraction": s.meshing.cycle_fraction,
        "poses_per_tooth": s.meshing.poses / (s.meshing.cycle_fraction * s.generated.teeth[0]),
        "interference_poses": s.meshing.interference_poses,
        "overlap_area_max_mm2": s.meshing.overlap_area_max,
        "backlash_deg": [s.meshing.backlash_min_deg, s.meshing.backlash_max_deg],
        "backlash_arc_max_mm": s.meshing.backlash_arc_max,
        "transmission_error_pp_deg": s.meshing.transmission_error_pp_deg,
        "free_play_max_deg": s.meshing.free_play_max_deg,
        "tip_relief": s.relief,
    } for s in train.stages]
    failures = [{"stage": stage, "path": p.path, "code": p.code, "message": p.message}
                for stage, p in train.failures]
    out = {"gears": gears, "meshes": meshes, "failures": failures,
           "root_thickness_policy": ROOT_THICKNESS_POLICY}
    if train.sets:
        out["sets"] = [set_report(train, record) for record in train.sets]
    if train.drive is not None:
        out["drive"] = train.drive.as_report()
    if train.strength is not None:
        from cadgen.gears.strength_summary import strength_report

        out["strength"] = strength_report(train.strength)
    return out


def working_centre_distance(z1: int, z2: int, module: float, shift_sum: float,
                            pressure_angle: float) -> float:
    """The centre distance (mm) two standard-rack gears with profile shifts summing to
    ``shift_sum`` mesh at without backlash: ``inv alpha_w = inv alpha + 2 tan alpha (x1 + x2) /
    (z1 + z2)`` solved for ``alpha_w`` by Newton's method, ``a_w = m (z1 + z2) / 2 cos alpha /
    cos alpha_w`` (ISO 21771); ``m (z1 + z2) / 2`` for standard gears."""
    a = module * (z1 + z2) / 2
    if shift_sum == 0.0:
        return a
    target = math.tan(pressure_angle) - pressure_angle + 2 * math.tan(pressure_angle) * \
        shift_sum / (z1 + z2)
    alpha = pressure_angle
    for _ in range(50):   # inv'(alpha) = tan^2 alpha
        step = (math.tan(alpha) - alpha - target) / math.tan(alpha) ** 2
        alpha -= step
        if abs(step) < 1e-15:
            break
    return a * math.cos(pressure_angle) / math.cos(alpha)


def set_report(train: GearTrain, record: dict) -> dict:
    """One of train 1's sets: its converted ratio (from the cut teeth: three external meshes,
    ``-z_sun / z_planet``) against the one asked for, and each mesh's working centre distance
    (:func:`working_centre_distance` of the cut gears' teeth, module and profile shifts, not
    the radii they were cut for) against the axis distance on the carrier."""
    by_name = {s.name: s for s in train.stages}
    meshes = []
    for name, axis_distance in zip(record["stages"], record["axis_distances"]):
        stage = by_name[name]
        drive, driven = stage.generated.profiles
        x1, x2 = (float(check.profile_shift) for check in stage.generated.checks)
        working = working_centre_distance(drive.teeth, driven.teeth, float(drive.module),
                                          x1 + x2, stage.generated.system.pressure_angle)
        meshes.append({"driver": drive.name, "driven": driven.name,
                       "driver_teeth": int(drive.teeth), "driven_teeth": int(driven.teeth),
                       "module_mm": float(drive.module),
                       "profile_shifts": [x1, x2],
                       "centre_distance_mm": float(working),
                       "axis_distance_mm": float(axis_distance),
                       "centre_distance_error_mm": float(working - axis_distance)})
    achieved = -meshes[0]["driver_teeth"] / meshes[-1]["driven_teeth"]
    return {"name": record["name"], "key": record["key"],
            "converted_ratio": float(record["converted_ratio"]),
            "converted_ratio_teeth": float(achieved),
            "ratio_exact": abs(achieved - record["converted_ratio"]) <= 1e-12,
            "rule": record.get("rule", ""), "axes": list(record["axes"]), "meshes": meshes}


#: The undercut policy in words, for the report (the threshold is ``MIN_ROOT_THICKNESS``).
ROOT_THICKNESS_POLICY = (
    f"an undercut tooth is a warning while its remaining root thickness is at least "
    f"{MIN_ROOT_THICKNESS:g} modules (80 % of the full tooth's pi m / 2, 63 % of its bending "
    "section by Lewis), a failure below it; the kinematic undercut finding (radius of "
    "curvature below m (ha* - x) / sin^2 alpha, x the gear's profile shift) is a prediction "
    "for rack cutting, and the cut teeth's measured root thickness decides")
