"""Tests of the command line (cadgen.cli, python -m cadgen)."""

from __future__ import annotations

import subprocess
import sys
import types
from pathlib import Path

import pytest

import cadgen
import cadgen.feasibility
from cadgen.cli import EXIT_OK, EXIT_PROBLEMS, main
from kinematics.errors import ConvergenceError

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "params" / "xin2024-planter.toml"
INVALID = Path(__file__).resolve().parent / "invalid"


def run_cadgen(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "cadgen", *args],
        cwd=cwd, capture_output=True, text=True, timeout=120,
    )


# --------------------------------------------------------------------------- subprocess


def test_validate_ok_exits_0_and_writes_nothing(tmp_path):
    result = run_cadgen("validate", str(REFERENCE), cwd=tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.strip() == f"{REFERENCE}: ok"
    assert list(tmp_path.iterdir()) == []


def test_validate_problems_exit_2_one_line_each(tmp_path):
    bad = INVALID / "out_of_range.toml"
    result = run_cadgen("validate", str(bad), cwd=tmp_path)
    assert result.returncode == 2
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 3
    assert all(line.startswith(f"{bad}: ") and line.endswith("[out_of_range]") for line in lines)
    assert any(f"{bad}: train.R: " in line for line in lines)
    assert list(tmp_path.iterdir()) == []


def test_validate_several_files_reports_each(tmp_path):
    missing = tmp_path / "missing.toml"
    result = run_cadgen(
        "validate", str(REFERENCE), str(INVALID / "bad_e2.toml"), str(missing), cwd=tmp_path
    )
    assert result.returncode == 2
    lines = result.stdout.strip().splitlines()
    assert lines[0] == f"{REFERENCE}: ok"
    assert lines[1].startswith(f"{INVALID / 'bad_e2.toml'}: pitch_curve.e2: ")
    assert lines[2].startswith(f"{missing}: <file>: ") and lines[2].endswith("[file_not_found]")


@pytest.mark.parametrize(
    "command", [[], ["validate"], ["analyze"]], ids=["top", "validate", "analyze"]
)
def test_help(command, tmp_path):
    result = run_cadgen(*command, "--help", cwd=tmp_path)
    assert result.returncode == 0
    assert result.stdout.startswith(f"usage: cadgen{''.join(' ' + c for c in command)}")
    if not command:
        assert "validate" in result.stdout and "analyze" in result.stdout


def test_version(tmp_path):
    result = run_cadgen("--version", cwd=tmp_path)
    assert result.returncode == 0
    assert result.stdout.strip() == f"cadgen {cadgen.__version__}"


def test_no_command_is_a_usage_error(tmp_path):
    result = run_cadgen(cwd=tmp_path)
    assert result.returncode == 2
    assert "usage:" in result.stderr


def test_help_imports_no_heavy_module(tmp_path):
    code = (
        "import sys\n"
        "from cadgen.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "heavy = {'numpy', 'scipy', 'matplotlib', 'pydantic', 'trimesh'}\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in heavy))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == "[]"


# --------------------------------------------------------------------------- analyze, in process


class _FakeResult:
    exit_code = EXIT_OK

    def summary_text(self) -> str:
        return "fake summary"


@pytest.fixture
def fake_analysis(monkeypatch):
    """Stand-in for cadgen.build.build, recording its calls; feasibility isolated too."""
    import cadgen.build

    calls = []
    module = types.SimpleNamespace(fail=None, calls=calls)

    def build(params, *, output_root, effects=None, case=None, steps=None, preset=None):
        calls.append({"params": params, "output_root": output_root, "steps": steps,
                      "effects": effects, "case": case, "preset": preset})
        if module.fail:
            raise module.fail
        return _FakeResult()

    monkeypatch.setattr(cadgen.build, "build", build)
    monkeypatch.setattr(cadgen.feasibility, "design_problems", lambda params: [])
    return module


def test_analyze_passes_the_arguments(fake_analysis, tmp_path, capsys):
    argv = ["analyze", str(REFERENCE), "--output-dir", str(tmp_path / "out"), "--steps", "720"]
    assert main(argv) == EXIT_OK
    (call,) = fake_analysis.calls
    assert call["output_root"] == tmp_path / "out" and isinstance(call["output_root"], Path)
    assert call["steps"] == 720
    assert call["params"].name == "xin2024-planter"
    assert capsys.readouterr().out.strip() == "fake summary"


def test_analyze_defaults(fake_analysis, capsys):
    assert main(["analyze", str(REFERENCE)]) == EXIT_OK
    (call,) = fake_analysis.calls
    assert call["output_root"] == Path("outputs") and call["steps"] is None
    assert call["effects"] is None and call["case"] is None   # the file's scene decides


def test_build_passes_effects_and_case(fake_analysis):
    assert main(["build", str(REFERENCE), "--effects", "metrics,plots,metrics",
                 "--case", "bench"]) == EXIT_OK
    (call,) = fake_analysis.calls
    assert call["effects"] == ["metrics", "plots"] and call["case"] == "bench"
    assert call["preset"] is None   # the file's scene decides


def test_build_passes_the_preset(fake_analysis):
    assert main(["build", str(REFERENCE), "--preset", "draft"]) == EXIT_OK
    assert fake_analysis.calls[0]["preset"] == "draft"


def test_build_rejects_an_unknown_effect(fake_analysis, capsys):
    with pytest.raises(SystemExit) as caught:
        main(["build", str(REFERENCE), "--effects", "metrics,meshes"])
    assert caught.value.code == 2
    assert "meshes" in capsys.readouterr().err and fake_analysis.calls == []


def test_analyze_bad_file_exits_2_without_running(fake_analysis, capsys):
    assert main(["analyze", str(INVALID / "several_tables.toml")]) == EXIT_PROBLEMS
    assert fake_analysis.calls == []
    err = capsys.readouterr().err
    assert "planter.L2" in err and "[not_finite]" in err


def test_analyze_mechanism_error_exits_2(fake_analysis, capsys):
    fake_analysis.fail = ConvergenceError("closure did not converge")
    assert main(["analyze", str(REFERENCE)]) == EXIT_PROBLEMS
    captured = capsys.readouterr()
    assert "closure did not converge" in captured.err and captured.out == ""


@pytest.mark.parametrize("steps", ["10", "abc", "2000000"])
def test_analyze_rejects_bad_steps(fake_analysis, steps, capsys):
    with pytest.raises(SystemExit) as caught:
        main(["analyze", str(REFERENCE), "--steps", steps])
    assert caught.value.code == 2
    assert "--steps" in capsys.readouterr().err
    assert fake_analysis.calls == []
