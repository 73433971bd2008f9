"""Accuracy presets: ``draft``, ``standard`` and ``fine`` settings of every resolution knob.

Chosen from the accuracy study (``python -m benchmarks.accuracy``, docs/accuracy.md):

* ``draft``: each knob at the coarsest setting that still holds the design's tolerances
  (metrics certified to 1e-9 mm need no more than 720 steps; 32 flank points keep the tooth
  profile within about 1e-3 mm; 48 segments keep a round part's volume within 0.3 %; the
  sweep certified to 1e-3 mm): for iterating on a design.
* ``standard`` (the default): the parameter files' defaults; metrics and sweeps to round-off or
  1e-6 mm, tooth profiles within about 1e-4 mm, DXF within 0.005 mm, volumes within 0.07 %.
* ``fine``: for the release drawings: profiles within 1e-5 mm, DXF within 0.001 mm, volumes
  within 0.01 %, sweeps to 1e-9 mm.

A preset sets a knob only where the file leaves it out: a value written in the file wins.
"""

from __future__ import annotations

__all__ = ["PRESETS", "apply_preset"]

PRESETS = {
    "draft": {"resolution.steps_per_revolution": 720, "resolution.closure_rtol": 1e-10,
              "resolution.inverse_grid": 360, "resolution.sweep_atol": 1e-3,
              "gears.flank_points": 32, "gears.chord_tolerance": 0.02,
              "solids.segments_per_circle": 48, "cam.profile_points": 1440},
    "standard": {"resolution.steps_per_revolution": 3600, "resolution.closure_rtol": 1e-13,
                 "resolution.inverse_grid": 720, "resolution.sweep_atol": 1e-6,
                 "gears.flank_points": 96, "gears.chord_tolerance": 0.005,
                 "solids.segments_per_circle": 96, "cam.profile_points": 3600},
    "fine": {"resolution.steps_per_revolution": 36000, "resolution.closure_rtol": 1e-15,
             "resolution.inverse_grid": 2880, "resolution.sweep_atol": 1e-9,
             "gears.flank_points": 384, "gears.chord_tolerance": 0.001,
             "solids.segments_per_circle": 256, "cam.profile_points": 14400},
}


def apply_preset(params, name: str):
    """``(params with the preset's knobs, {knob: (value, "preset" | "file")})``.

    Knobs the mechanism kind does not have (``steps_per_revolution`` on the
    pricking mechanism) are skipped; knobs set in the file keep the file's value.
    """
    knobs = PRESETS[name]
    updates: dict = {}
    used = {}
    for path, value in knobs.items():
        table_name, field = path.split(".")
        table = getattr(params, table_name, None)
        if table is None or field not in type(table).model_fields:
            continue
        if field in table.model_fields_set:
            used[path] = (getattr(table, field), "file")
            continue
        updates.setdefault(table_name, {})[field] = value
        used[path] = (value, "preset")
    tables = {name_: getattr(params, name_).model_copy(update=fields)
              for name_, fields in updates.items()}
    return params.model_copy(update=tables), used
