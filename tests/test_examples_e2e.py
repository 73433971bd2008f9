"""End to end: the real ``cadgen`` console script on every bundled example, as a user runs it.

Files are found by glob (``params/*.toml``, the studies' base designs
``params/studies/bases/*.toml``, ``params/grids/*.toml``, ``params/studies/*.toml``), so a new
example is covered without touching this file. Each run must end without a traceback and with exit
0 or 1; what it prints and writes is checked against the input files themselves (read
here with tomllib) and against report.json, not against the code that made them.
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PARAMS = sorted((ROOT / "params").glob("*.toml"))
#: The studies' base designs: deliberately failing ones (the optimiser's starting points)
STUDY_BASES = sorted((ROOT / "params" / "studies" / "bases").glob("*.toml"))
GRIDS = sorted((ROOT / "params" / "grids").glob("*.toml"))
STUDIES = sorted((ROOT / "params" / "studies").glob("*.toml"))
#: A study's own budget is a real search (up to minutes for the pricking mechanism); here a
#: small one (a part of the first generation), enough to run every stage of the command
#: (screen, certify, write).
STUDY_EVALUATIONS = 40
CADGEN = Path(sys.executable).with_name("cadgen")
TIMEOUT = 300


def cadgen(*args, cwd: Path) -> subprocess.CompletedProcess:
    assert CADGEN.is_file(), f"no console script next to {sys.executable}: pip install -e ."
    return subprocess.run([str(CADGEN), *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=TIMEOUT)


def no_traceback(result: subprocess.CompletedProcess) -> None:
    for stream in (result.stdout, result.stderr):
        assert "Traceback" not in stream, stream[-3000:]
        assert "internal error" not in stream, stream[-3000:]


def toml(path: Path) -> dict:
    return tomllib.loads(path.read_text(encoding="utf-8"))


def test_examples_are_found():
    assert len(PARAMS) >= 3 and len(GRIDS) >= 1 and len(STUDIES) >= 3
    assert {p.name for p in PARAMS} >= {"xin2024-planter.toml", "kernel-a.toml", "kernel-b.toml"}


@pytest.mark.parametrize("file", PARAMS, ids=[p.stem for p in PARAMS])
def test_validate_every_example(file, tmp_path):
    result = cadgen("validate", file, cwd=tmp_path)
    no_traceback(result)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.splitlines()[0] == f"{file}: ok"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("file", PARAMS, ids=[p.stem for p in PARAMS])
def test_build_every_example(file, tmp_path):
    data = toml(file)
    name, mechanism = data["name"], data["mechanism"]
    result = cadgen("build", file, "--output-dir", tmp_path / "out", cwd=tmp_path)
    no_traceback(result)
    assert result.returncode in (0, 1), result.stdout[-2000:] + result.stderr[-2000:]
    folder = tmp_path / "out" / name
    report = json.loads((folder / "report.json").read_text(encoding="utf-8"))
    assert report["design"] == name and report["mechanism"] == mechanism
    # the exit code is the report's verdict: 0 exactly when nothing failed
    assert result.returncode == (0 if report["passed"] else 1)
    assert (result.returncode == 0) == (report["failures"] == [])
    # no staging or set-aside folder left beside the outputs
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [name]
    lines = result.stdout.splitlines()
    assert lines[0].startswith(f"design {name} ({mechanism} mechanism)")
    assert lines[-1] == f"wrote {len(report['files'])} files to {tmp_path / 'out' / name}"
    assert ("PASSED" if report["passed"] else "NOT PASSED") in result.stdout
    # every file the report lists is there
    assert all((folder / f).is_file() for f in report["files"])
    # each clearance line carries the certified minimum of report.json, and says plainly
    # when the mechanism has no kinematic estimate (the pricking gear case)
    for row in report.get("sweep", {}).values():
        line = next(x for x in lines if x.startswith(row["label"] + ":"))
        assert f": {row['minimum_mm']:.3f} mm (certified >= " in line
        if row["kinematic_estimate_mm"] is None:
            assert "no kinematic estimate for this mechanism" in line
        else:
            assert f"kinematic estimate {row['kinematic_estimate_mm']:.3f} mm" in line
    if mechanism == "pricking":
        assert "sweep" in report and "no kinematic estimate" in result.stdout


def _grid_size(grid: dict) -> int:
    """Designs in a grid file: the product of its lists' lengths (``{num}`` for a range)."""
    return math.prod(len(v) if isinstance(v, list) else int(v["num"])
                     for v in grid["grid"].values())


@pytest.mark.parametrize("grid", GRIDS, ids=[g.stem for g in GRIDS])
def test_batch_every_grid(grid, tmp_path):
    data = toml(grid)
    count = _grid_size(data)
    out = tmp_path / "out"
    result = cadgen("batch", "--grid", grid, "--output-dir", out, "--workers", 2, cwd=tmp_path)
    no_traceback(result)
    assert result.returncode in (0, 1), result.stdout[-2000:] + result.stderr[-2000:]
    with open(out / "batch-summary.csv", newline="", encoding="utf-8") as stream:
        table = list(csv.DictReader(stream))
    names = [f"{data['name']}-{k:03d}" for k in range(1, count + 1)]
    assert sorted(row["design"] for row in table) == names
    # every combination of the grid's values, once
    for key, values in data["grid"].items():
        if isinstance(values, list):
            assert sorted({float(row[f"grid:{key}"]) for row in table}) == sorted(values)
    built = sorted(p.name for p in out.iterdir() if p.is_dir())
    assert not [n for n in built if n.startswith(".")]        # no staging folder left
    assert built == sorted(row["design"] for row in table if row["output"])
    for name in built:
        report = json.loads((out / name / "report.json").read_text(encoding="utf-8"))
        assert report["design"] == name
        # each clearance under the name of what measured it, as the report labels it: the
        # solids' sweep and, beside it, the metrics stage's centre-line estimate
        row = next(row for row in table if row["design"] == name)
        arm = next(m for m in report["metrics"] if m["key"] == "arm_distance")
        assert arm["label"] == "arm distance (solids, FCL)"
        assert float(row["arm_distance (solids, FCL)"]) == pytest.approx(arm["value"], rel=1e-6)
        assert float(row["arm_distance (centre lines)"]) == pytest.approx(
            arm["kinematic_estimate"], rel=1e-6)
    failed = sum(not row["output"] for row in table)
    assert result.returncode == (1 if failed else 0)
    assert f"{count} designs in " in result.stdout


@pytest.mark.parametrize("file", GRIDS + STUDIES, ids=[p.stem for p in GRIDS + STUDIES])
def test_build_on_a_grid_or_study_file_names_the_command_that_reads_it(file, tmp_path):
    # a user pointing `cadgen build` at the wrong kind of bundled file is told which command
    # reads it, from the file's own tables, not that `mechanism` is missing
    result = cadgen("build", file, "--output-dir", tmp_path / "out", cwd=tmp_path)
    no_traceback(result)
    assert result.returncode == 2 and not (tmp_path / "out").exists()
    command = "cadgen batch --grid FILE" if "grid" in toml(file) else "cadgen optimize FILE"
    assert result.stderr.strip().splitlines() == [
        f"{file}: <file>: this is a {'grid' if 'grid' in toml(file) else 'study'} file (a base "
        f"design and [{'grid' if 'grid' in toml(file) else 'free'}]), not a parameter file: "
        f"run `{command}` [not_a_parameter_file]"]


@pytest.mark.parametrize("file", STUDY_BASES, ids=[p.stem for p in STUDY_BASES])
def test_study_bases_fail_cleanly_and_validate_says_what_build_does(file, tmp_path):
    # a base a study starts from misses its targets, or is refused by a build stage: either
    # way one line per problem naming its field, never a traceback, a refused build writes
    # nothing, and validate's verdict is the build's (the same lines, exit 2; or exit 0 for
    # a design that builds and misses its targets)
    check = cadgen("validate", file, cwd=tmp_path)
    no_traceback(check)
    result = cadgen("build", file, "--output-dir", tmp_path / "out", cwd=tmp_path)
    no_traceback(result)
    if result.returncode == 2:
        refused = result.stderr.strip().splitlines()
        assert refused and all(line.startswith(f"{file}: ") for line in refused)
        assert check.returncode == 2, check.stdout
        assert check.stdout.strip().splitlines() == refused
        assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []
    else:
        assert result.returncode == 1, result.stdout[-2000:] + result.stderr[-2000:]
        assert check.returncode == 0, check.stdout


@pytest.mark.parametrize("study", STUDIES, ids=[s.stem for s in STUDIES])
def test_optimize_every_study(study, tmp_path):
    name = toml(study)["name"]
    result = cadgen("optimize", study, "--evaluations", STUDY_EVALUATIONS, "--workers", 2,
                    "--output-dir", tmp_path / "out", cwd=tmp_path)
    no_traceback(result)
    assert result.returncode in (0, 1), result.stdout[-2000:] + result.stderr[-2000:]
    folder = tmp_path / "out" / name
    summary = json.loads((folder / "optimize.json").read_text(encoding="utf-8"))
    # exit 0 exactly when a design meeting every target was found: then best.toml, else the
    # least-violating design; either is a parameter file that validates
    assert summary["found"] == (result.returncode == 0) and summary["exit_code"] == result.returncode
    written = folder / ("best.toml" if result.returncode == 0 else "least-violating.toml")
    assert summary["best_file"] == written.name
    assert written.is_file() and (folder / "optimize.html").is_file()
    assert not (folder / ("least-violating.toml" if result.returncode == 0 else "best.toml")).exists()
    assert summary["search"]["evaluations"] == STUDY_EVALUATIONS
    check = cadgen("validate", written, cwd=tmp_path)
    no_traceback(check)
    assert check.returncode == 0, check.stdout + check.stderr


