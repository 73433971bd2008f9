"""Saving from the studio (cadgen.studio.save): comments and layout kept, same parameters back.

The truth is independent of the code under test: the parameters a saved file loads to
(:func:`cadgen.load_params`) against those the page sent (:func:`cadgen.validate_data`),
the comments of the original file (collected by a small TOML comment scanner here), and
the folder's listing before and after a refused save.
"""

import copy
import json
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cadgen
from cadgen.params.scene import PRESETS, apply_preset
from cadgen.studio.save import SaveError, save_design

REPO = Path(__file__).resolve().parents[1]
PARAM_FILES = sorted((REPO / "params").glob("*.toml"))


# --------------------------------------------------------------------------- helpers
def comments(text: str) -> list[str]:
    """Every comment of a TOML text, in order: from a ``#`` outside strings to the line's end."""
    found = []
    for line in text.splitlines():
        quote = None
        index = 0
        while index < len(line):
            char = line[index]
            if quote is None and char == "#":
                found.append(line[index:].rstrip())
                break
            if quote is None and char in "\"'":
                quote = char
            elif quote == '"' and char == "\\":
                index += 1              # an escaped character inside a basic string
            elif char == quote:
                quote = None
            index += 1
    return found


def is_subsequence(needles: list, haystack: list) -> bool:
    remaining = iter(haystack)
    return all(any(needle == item for item in remaining) for needle in needles)


def dumped(params) -> dict:
    return params.model_dump()


def listing(folder: Path) -> dict:
    """Every entry under ``folder`` with its bytes (None for a folder)."""
    return {str(path.relative_to(folder)): (None if path.is_dir() or path.is_symlink()
                                            else path.read_bytes())
            for path in sorted(folder.rglob("*"))}


def change_a_few(data: dict) -> tuple[dict, int]:
    """Two or three values changed the way a designer would; (changed data, values changed)."""
    changed = copy.deepcopy(data)
    if changed["mechanism"] == "planting":
        changed["planter"]["L2"] = changed["planter"]["L2"] + 4.5
        changed["field"]["depth"] = 36          # an integer from JSON for a float field
        return changed, 2
    changed["linkage"]["rocker"] = changed["linkage"]["rocker"] + 2.0
    changed["field"]["depth"] = changed["field"]["depth"] + 2.5
    point = changed["trajectory"]["points"][4]
    changed["trajectory"]["points"][4] = [point[0] - 0.5, point[1]]   # a dragged point
    return changed, 3


@pytest.fixture
def copied(tmp_path):
    def copy_file(source: Path) -> Path:
        target = tmp_path / source.name
        target.write_bytes(source.read_bytes())
        return target
    return copy_file


# --------------------------------------------------------------------------- round trips
@pytest.mark.parametrize("source", PARAM_FILES, ids=[p.stem for p in PARAM_FILES])
def test_changed_values_round_trip_with_every_comment_kept(source, copied):
    path = copied(source)
    original = path.read_text(encoding="utf-8")
    changed, count = change_a_few(tomllib.loads(original))

    written = save_design(changed, original=path, folder=path.parent, name=None)

    assert written == path.resolve()
    saved = path.read_text(encoding="utf-8")
    assert dumped(cadgen.load_params(path)) == dumped(cadgen.validate_data(changed))
    assert comments(original), "the scanner found no comment: the check would be empty"
    assert is_subsequence(comments(original), comments(saved))
    # nothing but the changed values' lines differs
    before, after = original.splitlines(), saved.splitlines()
    assert len(before) == len(after)
    assert sum(a != b for a, b in zip(before, after)) == count


@pytest.mark.parametrize("source", PARAM_FILES, ids=[p.stem for p in PARAM_FILES])
def test_unchanged_design_saves_byte_identical(source, copied):
    path = copied(source)
    original = path.read_bytes()
    save_design(tomllib.loads(original.decode()), original=path, folder=path.parent, name=None)
    assert path.read_bytes() == original


def test_keys_added_only_when_they_mean_something_and_removed_when_left_out(copied):
    path = copied(REPO / "params" / "xin2024-planter.toml")
    original = path.read_text(encoding="utf-8")
    data = tomllib.loads(original)
    planter_defaults = type(cadgen.validate_data(data).planter).model_fields
    thicker = planter_defaults["arm_thickness"].default + 2
    data["planter"]["arm_width"] = planter_defaults["arm_width"].default   # not written
    data["planter"]["arm_thickness"] = thicker                              # written
    data["housing"]["clearance"] = 3                # the file has it commented out
    # a preset knob at the standard preset's value: its presence matters under "draft"
    data["cam"]["profile_points"] = PRESETS["standard"]["cam.profile_points"]
    del data["resolution"]["closure_rtol"]          # the page reset it to the default
    data["scene"] = {"preset": "draft"}             # a table the file lacks

    save_design(data, original=path, folder=path.parent, name=None)

    saved = path.read_text(encoding="utf-8")
    loaded = cadgen.load_params(path)
    expected = cadgen.validate_data(data)
    assert dumped(loaded) == dumped(expected)
    assert "arm_width" not in saved and f"arm_thickness = {float(thicker)!r}" in saved
    assert "closure_rtol = " not in saved.replace("# closure_rtol", "")
    assert "profile_points" in loaded.cam.model_fields_set     # the draft preset leaves it be
    assert apply_preset(loaded, "draft")[0] == apply_preset(expected, "draft")[0]
    assert saved.rstrip().endswith('[scene]\npreset = "draft"')
    # the new key sits under its commented-out line, not below the next table's comments
    lines = saved.splitlines()
    assert lines[lines.index("clearance = 3.0") - 1].startswith("# clearance = 2.0")
    # every comment stays but the removed key's own line comment
    removed_line = next(line for line in original.splitlines()
                        if line.startswith("closure_rtol"))
    kept = [c for c in comments(original) if c not in comments(removed_line)]
    assert len(kept) == len(comments(original)) - 1
    assert is_subsequence(kept, comments(saved))


def test_points_added_and_removed_keep_the_other_points_comments(copied):
    path = copied(REPO / "params" / "kernel-b.toml")
    original = path.read_text(encoding="utf-8")
    data = tomllib.loads(original)
    points = data["trajectory"]["points"]
    midpoint = [(a + b) / 2 for a, b in zip(points[5], points[6])]
    points.insert(6, midpoint)                       # a point added on the loop
    save_design(data, original=path, folder=path.parent, name=None)

    saved = path.read_text(encoding="utf-8")
    assert dumped(cadgen.load_params(path)) == dumped(cadgen.validate_data(data))
    assert is_subsequence(comments(original), comments(saved))
    point_lines = [line for line in saved.splitlines() if line.startswith("    [")]
    assert len(point_lines) == len(points)           # one point per line, as the file has them
    assert "#" not in point_lines[6]                 # the new one: no comment of another's


def test_bundled_design_saved_as_keeps_the_template_comments(tmp_path):
    kind = "planting"
    example = REPO / "cadgen" / "params" / "examples" / cadgen.TEMPLATES[kind]
    data = tomllib.loads(example.read_text(encoding="utf-8"))
    data["planter"]["L1"] = 132.0

    written = save_design(data, original=None, folder=tmp_path, name="mine.toml")

    assert written == (tmp_path / "mine.toml").resolve()
    assert dumped(cadgen.load_params(written)) == dumped(cadgen.validate_data(data))
    kept = [c for c in comments(example.read_text(encoding="utf-8"))
            if "cadgen validate" not in c]          # the template names the new file there
    assert is_subsequence(kept, comments(written.read_text(encoding="utf-8")))


def test_missing_tables_go_at_the_end_of_a_windows_file(copied, tmp_path):
    """A file with the required tables only and CRLF line ends: tables the page adds are
    appended at the end (after the file's last comment), in the file's line ends."""
    full = (REPO / "params" / "xin2024-planter.toml").read_text(encoding="utf-8")
    required = ("pitch_curve", "train", "planter", "field")
    lines, keep = [], True
    for line in full.splitlines():
        if line.startswith("["):
            keep = line.strip("[]").split(".")[0] in required
        if keep and line.strip():
            lines.append(line)
    path = tmp_path / "minimal.toml"
    path.write_bytes(("# minimal\r\n" + "\r\n".join(lines) + "\r\n# the end\r\n").encode())
    original = path.read_bytes().decode("utf-8")
    data = tomllib.loads(original)
    data["cam"] = {"timing": {"opening_offset_deg": -4.0},          # the default: -5
                   "duckbill": {"blade_length": 85.0}}               # the default
    data["housing"] = {"gearbox1": {"O": 50.0}, "axial_gap": 3}

    save_design(data, original=path, folder=tmp_path, name=None)

    saved = path.read_bytes().decode()
    assert dumped(cadgen.load_params(path)) == dumped(cadgen.validate_data(data))
    assert "\n" not in saved.replace("\r\n", "")       # every line ends in CRLF
    assert saved.startswith(original)                 # the file as it was, then the additions
    added = saved[len(original):].split("\r\n")
    assert added == ["", "[cam.timing]", "opening_offset_deg = -4.0", "", "[housing]",
                     "gearbox1 = { O = 50.0 }", "axial_gap = 3.0", ""]


def test_a_table_written_in_parts_is_edited_in_place(tmp_path):
    """[cam.duckbill] moved below [manufacturing] (valid TOML: tomlkit reads [cam] through a
    proxy): values change where they are, keys are added, nothing is lost."""
    text = (REPO / "params" / "xin2024-planter.toml").read_text(encoding="utf-8")
    start, end = text.index("[cam.duckbill]"), text.index("[cam.lever]")
    path = tmp_path / "parts.toml"
    path.write_text(text[:start] + text[end:] + "\n" + text[start:end], encoding="utf-8")
    original = path.read_text(encoding="utf-8")
    data = tomllib.loads(original)
    data["cam"]["opening_angle_deg"] = 14.0         # added to [cam], which tomlkit splits
    data["cam"]["lever"]["rod_arm"] = 90.0
    data["cam"]["duckbill"]["blade_crank"] += 2

    save_design(data, original=path, folder=tmp_path, name=None)

    saved = path.read_text(encoding="utf-8")
    assert dumped(cadgen.load_params(path)) == dumped(cadgen.validate_data(data))
    assert is_subsequence(comments(original), comments(saved))
    assert saved.index("[cam.duckbill]") > saved.index("[manufacturing]")


# --------------------------------------------------------------------------- values
PLANTING = tomllib.loads((REPO / "params" / "xin2024-planter.toml").read_text(encoding="utf-8"))
positive = st.one_of(st.floats(min_value=1e-6, max_value=1e5, allow_nan=False),
                     st.integers(min_value=1, max_value=100_000))


@settings(max_examples=30, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(hole_width=positive,
       offset=st.one_of(st.floats(min_value=-90, max_value=90, allow_nan=False),
                        st.integers(min_value=-90, max_value=90)),
       steps=st.integers(min_value=36, max_value=20_000),   # (validation samples this many)
       tip_load=st.floats(min_value=1e-3, max_value=1e5, allow_nan=False),
       spacings=st.lists(st.floats(min_value=1.0, max_value=5000.0, allow_nan=False),
                         min_size=1, max_size=6, unique=True))
def test_any_value_round_trips(tmp_path, hole_width, offset, steps, tip_load, spacings):
    path = tmp_path / "design.toml"
    path.write_bytes((REPO / "params" / "xin2024-planter.toml").read_bytes())
    data = copy.deepcopy(PLANTING)
    data["targets"]["hole_width_max"] = hole_width
    data["cam"]["timing"]["opening_offset_deg"] = offset
    data["resolution"]["steps_per_revolution"] = steps
    data["machine"]["tip_load_n"] = tip_load
    data["field"]["plant_spacings"] = spacings

    save_design(data, original=path, folder=tmp_path, name=None)

    assert dumped(cadgen.load_params(path)) == dumped(cadgen.validate_data(data))


# --------------------------------------------------------------------------- refusals
BAD_NAMES = ["../escape.toml", "..", "../../etc/passwd.toml", "/tmp/escape.toml",
             "sub/escape.toml", "sub\\escape.toml", "..\\escape.toml", "escape\x00.toml",
             ".hidden.toml", "escape.txt", "escape", ".toml", "C:escape.toml",
             "line\nbreak.toml"]


@pytest.mark.parametrize("name", BAD_NAMES, ids=repr)
def test_names_outside_the_folder_are_refused_and_nothing_written(tmp_path, name):
    folder = tmp_path / "designs" / "inner"
    folder.mkdir(parents=True)
    (folder / "sub").mkdir()
    data = copy.deepcopy(PLANTING)
    before = listing(tmp_path)

    with pytest.raises(SaveError) as refused:
        save_design(data, original=None, folder=folder, name=name, overwrite=True)

    assert (refused.value.field, refused.value.status) == ("as", 400)
    assert listing(tmp_path) == before


def test_a_symlink_out_of_the_folder_is_refused(tmp_path):
    folder, outside = tmp_path / "designs", tmp_path / "elsewhere"
    folder.mkdir()
    outside.mkdir()
    (outside / "target.toml").write_text("precious = true\n")
    (folder / "link.toml").symlink_to(outside / "target.toml")
    (folder / "dangling.toml").symlink_to(outside / "new.toml")
    before = listing(tmp_path)

    for name in ("link.toml", "dangling.toml"):
        with pytest.raises(SaveError) as refused:
            save_design(copy.deepcopy(PLANTING), original=None, folder=folder, name=name,
                        overwrite=True)
        assert refused.value.status == 400

    assert listing(tmp_path) == before


def test_an_existing_file_needs_overwrite(tmp_path):
    (tmp_path / "taken.toml").write_text("# mine\n")
    with pytest.raises(SaveError) as refused:
        save_design(copy.deepcopy(PLANTING), original=None, folder=tmp_path, name="taken.toml")
    assert (refused.value.field, refused.value.status) == ("as", 409)
    assert (tmp_path / "taken.toml").read_text() == "# mine\n"

    written = save_design(copy.deepcopy(PLANTING), original=None, folder=tmp_path,
                          name="taken.toml", overwrite=True)
    assert dumped(cadgen.load_params(written)) == dumped(cadgen.validate_data(PLANTING))


def test_a_bundled_design_needs_a_name(tmp_path):
    with pytest.raises(SaveError) as refused:
        save_design(copy.deepcopy(PLANTING), original=None, folder=tmp_path, name=None)
    assert refused.value.status == 400
    assert listing(tmp_path) == {}


@pytest.mark.parametrize("name", [None, "other.toml"])
def test_invalid_parameters_write_nothing(copied, name):
    path = copied(REPO / "params" / "xin2024-planter.toml")
    before = listing(path.parent)
    data = copy.deepcopy(PLANTING)
    data["planter"]["L2"] = -1.0
    data["planter"]["typo"] = 3

    with pytest.raises(cadgen.ParameterError) as refused:
        save_design(data, original=path, folder=path.parent, name=name)

    assert {p.path for p in refused.value.problems} >= {"planter.L2", "planter.typo"}
    assert listing(path.parent) == before


# --------------------------------------------------------------------------- the route
TOKEN = "test-token-" + "y" * 20


@pytest.fixture
def client(monkeypatch, copied, tmp_path):
    from fastapi.testclient import TestClient

    from cadgen.studio.server import create_app

    # a server error's crash file goes to the test's folder, not the user's temporary one
    monkeypatch.setenv("CADGEN_CRASH_DIR", str(tmp_path / "crashes"))

    path = copied(REPO / "params" / "kernel-b.toml")
    app = create_app(path, token=TOKEN, output_root=path.parent / "outputs")
    with TestClient(app, base_url="http://127.0.0.1",
                    headers={"X-Cadgen-Token": TOKEN}) as test_client:
        test_client.design = path
        yield test_client


def test_save_route_round_trip_keeps_the_comments(client):
    path = client.design
    original = path.read_text(encoding="utf-8")
    design = client.get("/api/design").json()
    assert design["params"] == tomllib.loads(original)
    changed, count = change_a_few(design["params"])

    answer = client.post("/api/save", json={"params": changed, "as": None})

    assert answer.status_code == 200
    assert Path(answer.json()["path"]) == path.resolve()
    saved = path.read_text(encoding="utf-8")
    assert dumped(cadgen.load_params(path)) == dumped(cadgen.validate_data(changed))
    assert is_subsequence(comments(original), comments(saved))
    assert sum(a != b for a, b in zip(original.splitlines(), saved.splitlines())) == count


def test_save_route_refusals_write_nothing(client):
    folder = client.design.parent
    params = tomllib.loads(client.design.read_text(encoding="utf-8"))
    before = listing(folder.parent)

    outside = client.post("/api/save", json={"params": params, "as": "../escape.toml"})
    assert outside.status_code == 400 and outside.json()["field"] == "as"
    taken = client.post("/api/save", json={"params": params, "as": client.design.name})
    assert taken.status_code == 409
    bad = copy.deepcopy(params)
    bad["linkage"]["rocker"] = float("-inf")
    invalid = client.post("/api/save", content=json.dumps({"params": bad, "as": "new.toml"}),
                          headers={"content-type": "application/json"})
    assert invalid.status_code in (400, 422)
    no_token = client.post("/api/save", json={"params": params, "as": "new.toml"},
                           headers={"X-Cadgen-Token": ""})
    assert no_token.status_code == 403

    assert listing(folder.parent) == before

    saved_as = client.post("/api/save", json={"params": params, "as": "copy.toml"})
    assert saved_as.status_code == 200
    assert (folder / "copy.toml").read_bytes() == client.design.read_bytes()
