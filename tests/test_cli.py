"""Tests of the command line (cadgen.cli, python -m cadgen)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import types
from pathlib import Path

import pytest

import cadgen
import cadgen.export.atomic
import cadgen.params.feasibility
from cadgen.cli import (
    CRASH_DIR_VARIABLE,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_PROBLEMS,
    main,
)
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
    """Stand-in for cadgen.pipeline.build.build, recording its calls; feasibility isolated too."""
    import cadgen.pipeline.build

    calls = []
    module = types.SimpleNamespace(fail=None, calls=calls)

    def build(params, *, output_root, effects=None, case=None, steps=None, preset=None,
              progress=None):
        calls.append({"params": params, "output_root": output_root, "steps": steps,
                      "effects": effects, "case": case, "preset": preset,
                      "progress": progress})
        if module.fail:
            raise module.fail
        return _FakeResult()

    monkeypatch.setattr(cadgen, "build", build)   # the public API the command line calls
    monkeypatch.setattr(cadgen.params.feasibility, "design_problems", lambda params: [])
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


# --------------------------------------------------------------------------- errors: one line each


def test_internal_error_exits_3_with_one_line_and_a_crash_file(fake_analysis, tmp_path,
                                                               monkeypatch, capsys):
    import platform

    crash_dir = tmp_path / "crashes"
    monkeypatch.setenv(CRASH_DIR_VARIABLE, str(crash_dir))
    fake_analysis.fail = RuntimeError("stage table\nlost its 42nd row")
    argv = ["build", str(REFERENCE), "--output-dir", str(tmp_path / "out")]
    assert main(argv) == EXIT_INTERNAL == 3
    captured = capsys.readouterr()
    assert captured.out == ""
    (line,) = captured.err.splitlines()
    assert line.startswith("cadgen: internal error: RuntimeError: stage table lost its 42nd row "
                           "(please report it; traceback saved to ")
    (crash,) = crash_dir.iterdir()
    assert line.endswith(f"{crash})")
    assert re.fullmatch(rf"cadgen-crash-\d{{8}}-\d{{6}}-{os.getpid()}\.txt", crash.name)
    text = crash.read_text(encoding="utf-8")
    assert "Traceback (most recent call last):" in text
    assert "RuntimeError: stage table\nlost its 42nd row" in text
    assert "in _cmd_build" in text                       # where it happened
    assert f"cadgen {cadgen.__version__} " in text
    assert f"python {platform.python_version()} " in text
    assert repr(argv)[1:-1] in text                      # the command line, whole
    assert not (tmp_path / "out").exists()


def test_internal_error_in_validate_is_3_too(tmp_path, monkeypatch, capsys):
    import cadgen.params

    monkeypatch.setenv(CRASH_DIR_VARIABLE, str(tmp_path))

    def broken(path):
        raise TypeError("unsupported operand type(s) for +: 'NoneType' and 'float'")

    monkeypatch.setattr(cadgen, "load_params", broken)
    assert main(["validate", str(REFERENCE)]) == EXIT_INTERNAL
    (line,) = capsys.readouterr().err.splitlines()
    assert "internal error: TypeError: unsupported operand" in line
    assert len(list(tmp_path.glob("cadgen-crash-*.txt"))) == 1


def test_internal_error_when_the_crash_file_cannot_be_written(fake_analysis, tmp_path,
                                                               monkeypatch, capsys):
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("")
    monkeypatch.setenv(CRASH_DIR_VARIABLE, str(blocker / "crashes"))
    fake_analysis.fail = ValueError("bad")
    assert main(["build", str(REFERENCE), "--output-dir", str(tmp_path / "out")]) == EXIT_INTERNAL
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("cadgen: internal error: ValueError: bad (please report it; "
                           "the traceback could not be saved: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not-a-directory"]


def test_crash_file_goes_to_the_temporary_directory_by_default(fake_analysis, tmp_path,
                                                                monkeypatch, capsys):
    import tempfile

    monkeypatch.delenv(CRASH_DIR_VARIABLE, raising=False)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    fake_analysis.fail = KeyError("x")
    assert main(["build", str(REFERENCE), "--output-dir", str(tmp_path / "out")]) == EXIT_INTERNAL
    (crash,) = tmp_path.glob("cadgen-crash-*.txt")
    assert str(crash) in capsys.readouterr().err


def test_keyboard_interrupt_exits_130_with_one_line(fake_analysis, tmp_path, capsys):
    fake_analysis.fail = KeyboardInterrupt()
    assert main(["build", str(REFERENCE), "--output-dir", str(tmp_path / "out")]) \
        == EXIT_INTERRUPTED == 130
    captured = capsys.readouterr()
    assert captured.err == "cadgen: interrupted\n" and captured.out == ""
    assert list(tmp_path.iterdir()) == []


def test_keyboard_interrupt_during_a_real_build_leaves_no_folder(tmp_path, monkeypatch, capsys):
    import cadgen.pipeline.build

    def interrupted(run):
        raise KeyboardInterrupt

    # the solids stage is interrupted after the metrics and cam ran: nothing may be written
    monkeypatch.setitem(cadgen.pipeline.build.STAGE_FUNCTIONS, "parts", interrupted)
    out = tmp_path / "out"
    (out / "xin2024-planter").mkdir(parents=True)
    (out / "xin2024-planter" / "previous.txt").write_text("kept")
    assert main(["build", str(REFERENCE), "--output-dir", str(out),
                 "--effects", "metrics,solids"]) == EXIT_INTERRUPTED
    # the stages that ran, as plain progress lines (stderr is not a terminal), then one line
    lines = capsys.readouterr().err.splitlines()
    assert lines[-1] == "cadgen: interrupted"
    assert [line.split("] ", 1)[1] for line in lines[:-1] if "started" in line] == [
        "kinematics: started", "metrics: started", "cam: started", "drivetrain: started",
        "parts: started"]
    assert all(line.startswith("[") for line in lines[:-1])
    assert sorted(p.name for p in out.iterdir()) == ["xin2024-planter"]
    assert (out / "xin2024-planter" / "previous.txt").read_text() == "kept"


def test_the_sigint_handler_is_put_back(fake_analysis, tmp_path):
    import signal

    before = signal.getsignal(signal.SIGINT)
    main(["build", str(REFERENCE), "--output-dir", str(tmp_path / "out")])
    assert signal.getsignal(signal.SIGINT) is before


def _unusable_output_dirs(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    return {"proc": (Path("/proc/x"), "/proc"),
            "existing-file": (afile, "is a file, not a directory"),
            "under-a-file": (afile / "out", f"{afile} is a file")}


@pytest.mark.skipif(not Path("/proc/self").exists(), reason="needs /proc (Linux)")
@pytest.mark.parametrize("case", ["proc", "existing-file", "under-a-file"])
@pytest.mark.parametrize("command", ["build", "analyze", "batch"])
def test_unusable_output_dir_exits_2_before_any_work(case, command, tmp_path, monkeypatch,
                                                     capsys):
    import cadgen.batch
    import cadgen.pipeline.build
    import cadgen.params

    def no_work(*args, **kwargs):
        pytest.fail("work started although the output directory cannot be used")

    for module, name in ((cadgen.pipeline.build, "build"), (cadgen.params, "load_params"),
                         (cadgen.batch, "run_batch"), (cadgen.batch, "expand_grid")):
        monkeypatch.setattr(module, name, no_work)
    directory, reason = _unusable_output_dirs(tmp_path)[case]
    before = sorted(tmp_path.rglob("*"))
    args = [command, str(REFERENCE)] if command != "batch" else [command, "--grid",
                                                                 str(ROOT / "params" / "grids"
                                                                     / "l2-sweep.toml")]
    assert main([*args, "--output-dir", str(directory)]) == EXIT_PROBLEMS   # no_work: none
    captured = capsys.readouterr()
    (line,) = captured.err.splitlines()
    assert line.startswith(f"cadgen: output directory {directory}: ") and reason in line
    assert captured.out == ""
    assert sorted(tmp_path.rglob("*")) == before       # nothing written


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="POSIX permissions; root writes into read-only directories")
def test_read_only_output_dir_exits_2(tmp_path, capsys, fake_analysis):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        assert main(["build", str(REFERENCE), "--output-dir", str(locked / "out")]) \
            == EXIT_PROBLEMS
    finally:
        locked.chmod(0o755)
    (line,) = capsys.readouterr().err.splitlines()
    assert line == (f"cadgen: output directory {locked / 'out'}: cannot be made: no folder can "
                    f"be created in {locked} (Permission denied)")
    assert fake_analysis.calls == [] and list(locked.iterdir()) == []


def test_unwritable_output_dir_is_found_by_trying(tmp_path, capsys, fake_analysis, monkeypatch):
    """Permission bits say nothing to root or on a read-only mount: the check tries."""
    import tempfile

    def refused(*args, **kwargs):
        raise OSError(30, "Read-only file system")

    monkeypatch.setattr(tempfile, "mkdtemp", refused)
    assert main(["build", str(REFERENCE), "--output-dir", str(tmp_path)]) == EXIT_PROBLEMS
    (line,) = capsys.readouterr().err.splitlines()
    assert line == (f"cadgen: output directory {tmp_path}: not writable: no folder can be "
                    "created in it (Read-only file system)")
    assert fake_analysis.calls == []


def test_design_folder_that_is_a_file_is_refused_before_any_stage(tmp_path, monkeypatch, capsys):
    import cadgen.pipeline.build

    def no_stage(run):
        pytest.fail("a stage ran")

    for stage in list(cadgen.pipeline.build.STAGE_FUNCTIONS):
        monkeypatch.setitem(cadgen.pipeline.build.STAGE_FUNCTIONS, stage, no_stage)
    (tmp_path / "xin2024-planter").write_text("a file where the outputs would go")
    assert main(["build", str(REFERENCE), "--output-dir", str(tmp_path)]) == EXIT_PROBLEMS
    (line,) = capsys.readouterr().err.splitlines()
    assert line == (f"cadgen: output directory {tmp_path}: {tmp_path / 'xin2024-planter'} exists "
                    "and is not a directory, so the design's outputs cannot go there")
    assert (tmp_path / "xin2024-planter").read_text() == "a file where the outputs would go"


def test_library_build_raises_output_dir_error(tmp_path):
    from cadgen.export.atomic import OutputDirError
    from cadgen.pipeline.build import build
    from cadgen.params import load_params

    with pytest.raises(OutputDirError, match="is a file") as caught:
        (tmp_path / "f").write_text("")
        build(load_params(REFERENCE), tmp_path / "f" / "out", effects=["metrics"])
    assert caught.value.directory == tmp_path / "f" / "out"
    assert isinstance(caught.value, cadgen.export.atomic.MechanismError)


def test_a_reader_that_goes_away_is_a_quiet_141(monkeypatch, capsys):
    # `cadgen build ... | head`: the pipe closes under the summary; no "internal error"
    import argparse
    import os

    import cadgen.cli

    def closed(args: argparse.Namespace) -> int:
        raise BrokenPipeError(32, "Broken pipe")

    redirected = []
    monkeypatch.setattr(cadgen.cli, "_cmd_validate", closed)
    monkeypatch.setattr(os, "dup2", lambda source, target: redirected.append(target))
    assert main(["validate", str(REFERENCE)]) == cadgen.cli.EXIT_BROKEN_PIPE == 141
    assert capsys.readouterr().err == ""
    assert redirected in ([], [1])   # stdout to /dev/null where it is a file (not here)


PARAMS_DIR = REFERENCE.parent
WRONG_KINDS = [  # (command line, the file's kind, the command the line must name)
    (["batch", "--grid", PARAMS_DIR / "xin2024-planter.toml"], "parameter", "cadgen build FILE"),
    (["optimize", PARAMS_DIR / "xin2024-planter.toml"], "parameter", "cadgen build FILE"),
    (["optimize", PARAMS_DIR / "grids" / "l2-sweep.toml"], "grid", "cadgen batch --grid FILE"),
    (["batch", "--grid", PARAMS_DIR / "studies" / "planter-margins.toml"], "study",
     "cadgen optimize FILE"),
    (["batch", PARAMS_DIR / "grids" / "l2-sweep.toml"], "grid", "cadgen batch --grid FILE"),
    (["batch", PARAMS_DIR / "studies" / "planter-margins.toml"], "study",
     "cadgen optimize FILE")]


@pytest.mark.parametrize("argv, kind, command", WRONG_KINDS,
                         ids=["grid<-params", "optimize<-params", "optimize<-grid",
                              "grid<-study", "batch<-grid", "batch<-study"])
def test_a_file_of_another_kind_names_the_command_that_reads_it(argv, kind, command, tmp_path,
                                                                  capsys):
    out = tmp_path / "out"
    status = main([*map(str, argv), "--output-dir", str(out)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and not out.exists()
    # one line, not an "unknown key" per table of the file
    assert len(lines) == 1, lines
    assert f"this is a {kind} file" in lines[0] and f"run `{command}`" in lines[0]


def test_a_batch_of_a_missing_file_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    status = main(["batch", str(tmp_path / "nosuch.toml"), str(REFERENCE), "--output-dir",
                   str(out)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and not out.exists()
    assert lines == [f"{tmp_path / 'nosuch.toml'}: <file>: no such file: "
                     f"{tmp_path / 'nosuch.toml'} [file_not_found]"]
