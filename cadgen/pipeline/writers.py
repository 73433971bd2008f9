"""The files a build writes, each from the stages that ran and the effects asked for.

Each writer takes the staging folder and returns the paths it wrote, relative
to it (see :func:`cadgen.pipeline.build.build`, which runs them inside the staged,
atomic output folder).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["writers_for", "prepare", "animation_of"]


def writers_for(run) -> list:
    """The writers of a finished run: curves (CSV), DXF (gears, cam), STL and the assembly,
    the bill of materials (CSV)."""
    ok = {r.stage for r in run.records if r.status == "ok"}
    effects = set(run.effects)
    writers = []
    if "curves" in effects and "kinematics" in ok:
        writers.append(lambda staging: _write_curves(run, staging))
    if "dxf" in effects:
        if "teeth" in ok and run.values["teeth"].stages:
            writers.append(lambda staging: _write_gears(run, staging))
        if "cam" in ok and run.values["cam"].cuttable:
            writers.append(lambda staging: _write_cam(run, staging))
    if "stl" in effects and "parts" in ok:
        from cadgen.export.meshes import write_solids

        writers.append(lambda staging: write_solids(run.values["parts"], staging))
    if "parts" in ok and run.report.get("bom"):
        writers.append(lambda staging: _write_bom(run, staging))
    return writers


def prepare(run) -> int:
    """Make what the writing and the report will need: the solids' report section, each STL,
    the assembly file, the gear files, the cam's file, the report's animation (the building
    process makes them while the worker beside draws). Made once, they are taken as made
    later (same bytes; the files name their folder only in error messages, and a failure is
    left for the writing to raise). Returns the pieces made.
    """
    if run.status("parts") != "ok":
        return 0
    from cadgen.export.meshes import solids_files
    from cadgen.solids.outcome import solids_report

    outcome = run.values["parts"]
    made = 0
    solids_report(outcome)
    made += 1
    if "stl" in run.effects:
        for _ in solids_files(outcome):
            made += 1
    if "dxf" in run.effects and run.status("teeth") == "ok" and run.values["teeth"].stages:
        made += _made_ahead(run, "_gear_files", lambda: _gear_files(run, Path("gears")))
    if "dxf" in run.effects and run.status("cam") == "ok" and run.values["cam"].cuttable:
        made += _made_ahead(run, "_cam_file", lambda: (_cam_file(run, Path("cam.dxf")),
                                                       _cam_file(run, Path(DRAWINGS) / "cam.dxf",
                                                                 drawing=True)))
    if "report" in run.effects:
        animation_of(run)
        made += 1
    return made


def _made_ahead(run, memo: str, make) -> int:
    """1 when ``make()`` made a cutting file ahead of the writing (remembered in the run's
    ``memo``), else 0 and nothing remembered: a failure is said again, with the staging
    folder's path, when the file is written."""
    try:
        make()
    except Exception:   # noqa: BLE001 - raised again by the writing, with its path
        run.__dict__.pop(memo, None)
        return 0
    return 1


def animation_of(run) -> dict:
    """The report's animation data (:func:`cadgen.report.animation.animation_data`), made once
    per run: :func:`prepare` may have made it."""
    if "_animation" not in run.__dict__:
        from cadgen.report.animation import animation_data

        run.__dict__["_animation"] = animation_data(run.params, run.values, soil=run.soil)
    return run.__dict__["_animation"]


def _write_bom(run, staging):
    """bom.csv: every made and bought part with its count (:mod:`cadgen.report.bom`)."""
    from cadgen.report.bom import bom_csv

    (staging / "bom.csv").write_text(bom_csv(run.report["bom"]), encoding="utf-8")
    return ["bom.csv"]


#: Where the drawings go (the train sheet, the cam's drawing): apart from the cutting files, so
#: a CAM program loading a folder of cutting files finds no construction geometry.
DRAWINGS = "drawings"


def _write_gears(run, staging):
    from cadgen.export.atomic import write_bytes_atomic
    from cadgen.export.train_sheet import SHEET_NAME

    written = []
    for name, data in _gear_files(run, staging / "gears"):
        folder = DRAWINGS if name == SHEET_NAME else "gears"   # the sheet is a drawing
        (staging / folder).mkdir(exist_ok=True)
        write_bytes_atomic(staging / folder / name, data)
        written.append(f"{folder}/{name}")
    return written


def _gear_files(run, folder: Path):
    """The gear files' ``[(name, bytes)]`` (:func:`cadgen.export.train_sheet.train_files`),
    made once per run: :func:`prepare` may have made them."""
    made = run.__dict__.setdefault("_gear_files", {})
    if "files" not in made:
        from cadgen.export.train_sheet import train_files

        made["files"] = train_files(run.values["teeth"], run.params.gears.chord_tolerance,
                                    folder=folder)
    return made["files"]


def _write_cam(run, staging):
    from cadgen.export.atomic import write_bytes_atomic

    write_bytes_atomic(staging / "cam.dxf", _cam_file(run, staging / "cam.dxf"))
    (staging / DRAWINGS).mkdir(exist_ok=True)
    drawing = staging / DRAWINGS / "cam.dxf"
    write_bytes_atomic(drawing, _cam_file(run, drawing, drawing=True))
    return ["cam.dxf", f"{DRAWINGS}/cam.dxf"]


def _cam_file(run, path: Path, drawing: bool = False) -> bytes:
    """The cam's DXF bytes (``path`` names it in error messages): the cutting file, or its
    ``drawing`` (with the roller's pitch curve); made once per run: :func:`prepare` may have
    made them. Kept in the gear cache beside the gear files when the build cut its teeth with
    one (keyed on the contour, the pitch curve, the bore, the holes, the chord tolerance and
    the writers' sources): a warm build never loads ezdxf."""
    made = run.__dict__.setdefault("_cam_file", {})
    kind = "drawing" if drawing else "bytes"
    if kind not in made:
        from cadgen.export.cam_dxf import cam_dxf_bytes
        from cadgen.export.train_sheet import CachedFiles

        from cadgen.solids.fixing_features import cam_bore_radius, cam_screw_holes

        params, design = run.params, run.values["cam"]
        points = params.cam.profile_points
        shafts = run.values.get("drivetrain")
        if shafts is None:   # a scene with the cam alone: size the shafts here (milliseconds)
            from cadgen.machine.drivetrain import drivetrain

            shafts = drivetrain(params, run.values["kinematics"], design)
        contour = design.profile.working_profile(points)
        pitch = design.profile.pitch_curve(points)
        bore = cam_bore_radius(params, shafts)
        # the screws' clearance holes, in the cam's frame (as the solid's)
        mechanism = run.values["kinematics"]
        holes = cam_screw_holes(shafts, float(mechanism.attitude(np.array([0.0]))[0])
                                - mechanism.phic)
        tolerance = params.gears.chord_tolerance
        # the teeth's cache (a scene without teeth touches none)
        cache = getattr(run.values.get("teeth"), "cache", None)
        made[kind] = CachedFiles(cache, tolerance).get(
            ("cam dxf", kind, np.asarray(contour, dtype=float), np.asarray(pitch, dtype=float),
             float(bore), tuple((tuple(c), r) for c, r in holes)),
            lambda: cam_dxf_bytes(contour, pitch, bore_radius=bore, chord_tolerance=tolerance,
                                  path=path, holes=holes, drawing=drawing))
    return made[kind]


#: Samples per turn of each tabulated pitch curve.
CURVE_SAMPLES = 3600


def _write_curves(run, staging):
    """The non-circular gears' pitch curves, tabulated in polar form for manufacture (CSV)."""
    folder = staging / "curves"
    folder.mkdir()
    written = []
    for name, (angle, radius) in _pitch_tables(run).items():
        order = np.argsort(np.mod(angle, 2 * np.pi))
        rows = np.column_stack([np.degrees(np.mod(angle, 2 * np.pi))[order], radius[order]])
        # python floats (tolist), not numpy's: the same text at a third of the time
        text = "polar_angle_deg,radius_mm\n" + "".join(f"{a:.9f},{r:.9f}\n"
                                                        for a, r in rows.tolist())
        path = folder / f"{name.replace(' ', '-')}.csv"
        path.write_text(text, encoding="utf-8")
        written.append(f"curves/{path.name}")
    return written


def _pitch_tables(run) -> dict:
    """``{gear: (polar angle rad, radius mm)}`` of every non-circular gear over one turn."""
    if run.params.mechanism == "pricking":
        design = run.values["kinematics"]
        v = np.linspace(0.0, design.motion.period, CURVE_SAMPLES, endpoint=False)
        gears = design.cycle_functions()[0]   # from the outer dead centre, as the train
    else:
        from cadgen.gears.trains import planting_pair

        pair = planting_pair(run.values["kinematics"])
        v = np.linspace(0.0, 2 * np.pi, CURVE_SAMPLES, endpoint=False)
        gears = dict(zip(pair.names, (pair.drive, pair.driven)))
    tables = {}
    for name, functions in gears.items():   # contact functions: (rho, drho, psi, dpsi)
        rho, _, psi, _ = functions(v)
        tables[name] = (psi, rho)
    return tables
