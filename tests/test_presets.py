"""Accuracy presets: what each sets, that the file wins, and that the report states what it bought."""

import math

import pytest

from cadgen.pipeline.build import build
from cadgen.params import load_params, validate_text
from cadgen.params.scene import PRESETS, apply_preset

from helpers import REFERENCE, reference_text


def test_standard_is_the_files_defaults():
    """The standard preset changes nothing: its values are the schema's defaults."""
    params = load_params(REFERENCE)
    preset, _ = apply_preset(params, "standard")
    assert preset == params


def test_a_preset_sets_only_what_the_file_leaves_out():
    from tests.helpers import with_keys

    text = with_keys(reference_text(), "gears", flank_points=64)
    params = validate_text(text, check_feasibility=False)
    draft, used = apply_preset(params, "draft")
    assert draft.gears.flank_points == 64 and used["gears.flank_points"] == (64, "file")
    assert draft.gears.chord_tolerance == PRESETS["draft"]["gears.chord_tolerance"]
    assert used["gears.chord_tolerance"] == (0.02, "preset")
    # the reference file writes steps_per_revolution itself: the file wins
    assert draft.resolution.steps_per_revolution == 3600
    # the pricking mechanism has no steps_per_revolution: skipped, not an error
    kernel, used = apply_preset(load_params(REFERENCE.parent / "kernel-b.toml"), "fine")
    assert "resolution.steps_per_revolution" not in used
    assert used["resolution.inverse_grid"] == (720, "file")     # kernel-b writes it
    assert kernel.resolution.sweep_atol == 1e-9 and used["gears.flank_points"] == (384, "preset")


def test_the_report_states_the_preset_and_what_it_bought():
    params = load_params(REFERENCE)
    report = build(params, None, effects=["metrics", "solids", "ground_clearance"],
                   preset="draft").report
    assert report["preset"]["name"] == "draft"
    assert report["preset"]["knobs"]["solids.segments_per_circle"] == {"value": 48,
                                                                      "from": "preset"}
    rows = {row["knob"]: row for row in report["accuracy_achieved"]}
    # a round part's volume error is the inscribed 48-gon's, in closed form
    angle = 2 * math.pi / 48
    assert f"{1 - math.sin(angle) / angle:.1e}" in rows["solids.segments_per_circle"]["achieved"]
    sweep = report["sweep"]["ground_clearance"]
    assert sweep["atol_mm"] == PRESETS["draft"]["resolution.sweep_atol"]
    assert sweep["minimum_mm"] - sweep["certified_bound_mm"] <= 1e-3 * (1 + 1e-9)


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_every_preset_names_only_real_knobs(name):
    from cadgen.params import PlantingParameters, PrickingParameters

    for path in PRESETS[name]:
        table, field = path.split(".")
        owners = [model for model in (PlantingParameters, PrickingParameters)
                  if table in model.model_fields
                  and field in model.model_fields[table].annotation.model_fields]
        assert owners, path
