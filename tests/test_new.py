"""``cadgen new planting|pricking NAME`` (cadgen.params.templates): commented starting files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import cadgen
from cadgen.cli import EXIT_OK, EXIT_PROBLEMS, main
from cadgen.params.templates import TEMPLATES, template_text

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "cadgen" / "params" / "examples"
CASES = [("planting", "xin2024-planter"), ("pricking", "kernel-b")]


@pytest.mark.parametrize("file", sorted(TEMPLATES.values()))
def test_bundled_examples_are_the_params_files(file):
    """The package's copies are byte for byte the files in params/ (update both)."""
    assert (EXAMPLES / file).read_bytes() == (ROOT / "params" / file).read_bytes()


@pytest.mark.parametrize("kind, example", CASES, ids=[k for k, _ in CASES])
def test_new_writes_a_file_that_validates_and_builds(kind, example, tmp_path, monkeypatch,
                                                     capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["new", kind, "my-design"]) == EXIT_OK
    path = tmp_path / "my-design.toml"
    assert capsys.readouterr().out.startswith("wrote my-design.toml")
    text = path.read_text(encoding="utf-8")
    # the bundled example, commented, with its name (and the paths naming it) replaced
    assert f"from\n# the bundled example '{example}'" in text
    assert ('\nname = "my-design"' + " " * 10
            + "# design name; outputs are written to outputs/my-design/\n") in text
    assert f'name = "{example}"' not in text and f"outputs/{example}/" not in text
    assert f"params/{example}.toml" not in text
    assert "# Check it with:   cadgen validate my-design.toml" in text
    assert text.count("\n#") > 20   # the example's comments kept
    params = cadgen.load_params(path)
    assert (params.mechanism, params.name) == (kind, "my-design")
    # the same design as the example, only renamed
    reference = cadgen.load_params(ROOT / "params" / f"{example}.toml")
    assert params.model_dump(exclude={"name"}) == reference.model_dump(exclude={"name"})

    capsys.readouterr()
    assert main(["validate", str(path)]) == EXIT_OK
    assert capsys.readouterr().out.strip() == f"{path}: ok"
    out = tmp_path / "out"
    assert main(["build", str(path), "--effects", "metrics", "--output-dir", str(out)]) == EXIT_OK
    report = json.loads((out / "my-design" / "report.json").read_text())
    assert (report["design"], report["passed"]) == ("my-design", True)


def test_new_output_option_and_refusal_to_overwrite(tmp_path, capsys):
    target = tmp_path / "sub" / "start.toml"
    target.parent.mkdir()
    assert main(["new", "pricking", "p-1", "--output", str(target)]) == EXIT_OK
    written = target.read_text(encoding="utf-8")
    assert 'name = "p-1"' in written and f"cadgen build {target}" in written
    capsys.readouterr()

    assert main(["new", "planting", "other", "-o", str(target)]) == EXIT_PROBLEMS
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err == (f"cadgen new: {target} exists; not overwritten (choose another NAME or "
                   "--output FILE)\n")
    assert target.read_text(encoding="utf-8") == written   # untouched


def test_new_refuses_a_bad_name_and_writes_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["new", "planting", "../escape"]) == EXIT_PROBLEMS
    err = capsys.readouterr().err
    assert err.startswith("cadgen new: name: design name '../escape' must be") and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(SystemExit) as exit_info:   # argparse: an unknown kind
        main(["new", "seeding", "x"])
    assert exit_info.value.code == 2


def test_template_text_is_the_public_api():
    assert cadgen.template_text is template_text
    assert cadgen.TEMPLATES == {"planting": "xin2024-planter.toml", "pricking": "kernel-b.toml"}
    text = cadgen.template_text("planting", "a.b_c-1", path="designs/a.toml")
    assert text.startswith("# Starting file for the planting design 'a.b_c-1', written by "
                           "`cadgen new planting a.b_c-1` from\n")
    assert "#   cadgen build designs/a.toml\n" in text
    with pytest.raises(cadgen.ParameterError, match=r"choose planting or pricking"):
        cadgen.template_text("seeding", "x")
