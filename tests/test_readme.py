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
