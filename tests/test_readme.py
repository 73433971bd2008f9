"""The README's two set-up commands are the ones CI and a new user run."""

import re

from tests.helpers import REFERENCE

ROOT = REFERENCE.parents[1]


def commands():
    text = (ROOT / "README.md").read_text()
    return [line.strip() for line in text.splitlines() if line.startswith("    python3 -m venv")]


def test_two_setup_commands():
    main, tests = commands()
    assert main.endswith("cadgen build params/xin2024-planter.toml")
    assert re.search(r"pytest", tests)


def test_ci_runs_exactly_the_readme_test_command():
    _, tests = commands()
    script = (ROOT / ".ci" / "run").read_text().splitlines()
    assert tests in [line.strip() for line in script]


def test_the_library_api_example_runs_as_written(tmp_path, monkeypatch, capsys):
    # the ten lines under "The library API", run from the repository with the output
    # folder moved to tmp_path
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("### The library API", 1)[1]
    block = re.search(r"\n\n((?:    .*\n)(?:    .*\n|\n)*)", section).group(1)
    code = "\n".join(line[4:] for line in block.splitlines())
    assert "cadgen.build(" in code and "cadgen.evaluate(" in code
    monkeypatch.chdir(ROOT)
    exec(compile(code.replace('"outputs"', repr(str(tmp_path))), "README", "exec"), {})
    printed = capsys.readouterr().out
    assert "trajectory height" in printed and "PASSED" in printed
    assert (tmp_path / "xin2024-planter" / "report.json").exists()
