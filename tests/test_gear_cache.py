"""The gear cache (cadgen.gears.cache, cadgen.pipeline.gear_cache): cached builds write the same
bytes, bad entries are recomputed, concurrent writers cannot corrupt an entry."""

import dataclasses
import multiprocessing
import os
import time
from pathlib import Path

import numpy as np
import pytest

import cadgen
from cadgen.cli import main
from cadgen.gears.cache import _HEADER, GearCache, stage_key

REPO = Path(__file__).resolve().parents[1]
PAPER = REPO / "params" / "xin2024-planter.toml"
#: What the byte-for-byte comparison covers: every cut gear's DXF and the pitch curves.
EFFECTS = ["teeth", "dxf", "curves"]

#: The paper's gear pairs, each one cached stage: gearbox 2's two, train 1's two sets of three,
#: the frame's drive's two.
PAIRS = 2 + 2 * 3 + 2


@pytest.fixture(scope="module")
def paper():
    return cadgen.load_params(PAPER)


def _files(folder: Path) -> dict:
    """Every file under gears/, drawings/ and curves/ of a build's folder: {relative path:
    bytes}."""
    return {str(p.relative_to(folder)): p.read_bytes()
            for sub in ("gears", "drawings", "curves") for p in sorted((folder / sub).rglob("*"))
            if p.is_file()}


def _build(params, out: Path, cache):
    result = cadgen.build(params, out, effects=EFFECTS, cache=cache)
    assert result.report["stages"][-1]["status"] == "ok", result.report["stages"]
    return result.report["gear_cache"], _files(out / params.name)


@pytest.fixture(scope="module")
def uncached(paper, tmp_path_factory):
    """The paper design's gear files cut with no cache: the reference bytes."""
    record, files = _build(paper, tmp_path_factory.mktemp("uncached"), cache=False)
    assert record == {"used": False, "directory": None, "hits": 0, "misses": 0}
    assert any(name.startswith("gears/") for name in files)
    assert any(name.startswith("curves/") for name in files)
    return files


def test_cached_builds_write_the_bytes_an_uncached_build_writes(paper, uncached, tmp_path):
    cache = tmp_path / "cache"
    cold, cold_files = _build(paper, tmp_path / "cold", cache)
    assert cold == {"used": True, "directory": str(cache), "hits": 0, "misses": PAIRS}
    warm, warm_files = _build(paper, tmp_path / "warm", cache)
    assert (warm["hits"], warm["misses"]) == (PAIRS, 0)
    assert cold_files.keys() == warm_files.keys() == uncached.keys()
    for name, data in uncached.items():
        assert cold_files[name] == data, name
        assert warm_files[name] == data, name
    # every pair's stage, the bytes of every gear's cutting file and of the train sheet (a
    # drawing), and each gear's cutting outline
    dxf = [name for name in uncached if name.startswith("gears/")]
    assert "drawings/train.dxf" in uncached
    # and the cam's cutting file and drawing (the drivetrain the gears are bored for is sized
    # with the cam's spring, so these scenes design the cam too)
    assert "drawings/cam.dxf" in uncached   # and cam.dxf beside the folders
    assert len(_stage_entries(cache)) == PAIRS
    assert GearCache(cache).stats()[0] == PAIRS + (len(dxf) + 1) + len(dxf) + 2


def _stage_entries(cache: Path) -> list:
    """The cache's entries holding a cut stage (the others hold a written file's bytes or a
    gear's cutting outline)."""
    from cadgen.machine.hubs import CuttingOutline

    store = GearCache(cache)
    return [entry for entry in sorted(cache.glob("??/*.gear"))
            if not isinstance(store.get(entry.stem), (bytes, CuttingOutline))]


def test_a_warm_build_writes_the_gear_files_without_making_them(paper, uncached, tmp_path,
                                                                 monkeypatch):
    import cadgen.export.train_sheet as train_sheet

    cache = tmp_path / "cache"
    _build(paper, tmp_path / "cold", cache)

    def made(*args, **kwargs):
        raise AssertionError("a warm build made a gear file")

    monkeypatch.setattr(train_sheet, "gear_dxf_bytes", made)
    monkeypatch.setattr(train_sheet, "_sheet_bytes", made)
    _, files = _build(paper, tmp_path / "warm", cache)
    assert files == uncached


_WARM_CAM_BUILD = f"""
import sys
import cadgen
params = cadgen.load_params(sys.argv[1])
result = cadgen.build(params, sys.argv[2], effects=["teeth", "cam", "dxf"], cache=sys.argv[3])
assert (result.report["gear_cache"]["hits"], result.report["gear_cache"]["misses"]) == ({PAIRS}, 0)
print("ezdxf" in sys.modules)
"""


def test_a_warm_build_writes_the_cam_file_without_loading_ezdxf(paper, tmp_path):
    """The cam's DXF bytes are kept beside the gear files: a warm build (a fresh interpreter)
    writes every cutting file and never imports ezdxf, and the cam file it writes is the
    uncached build's byte for byte."""
    import subprocess
    import sys

    effects, cache = ["teeth", "cam", "dxf"], tmp_path / "cache"
    alone = cadgen.build(paper, tmp_path / "uncached", effects=effects, cache=False)
    cold = cadgen.build(paper, tmp_path / "cold", effects=effects, cache=cache)
    loaded = subprocess.run([sys.executable, "-c", _WARM_CAM_BUILD, str(PAPER),
                             str(tmp_path / "warm"), str(cache)], capture_output=True,
                            text=True, check=True, cwd=REPO).stdout.strip()
    assert loaded == "False"
    cam = [(folder / paper.name / "cam.dxf").read_bytes()
           for folder in (tmp_path / "uncached", tmp_path / "cold", tmp_path / "warm")]
    assert cam[0] == cam[1] == cam[2] and cam[0].startswith(b"  0\nSECTION")
    assert alone.report["gear_cache"]["used"] is False and cold.report["gear_cache"]["misses"] == PAIRS


def test_a_warm_build_thins_no_gear_outline_again(paper, tmp_path, monkeypatch):
    """Each bored gear's cutting outline (its solid's, its DXF's and the train sheet's) is
    kept beside the gear: a warm build of the solids and the cutting files thins none, and
    its files are the cold build's byte for byte."""
    import sys

    import cadgen.geometry.contour as contour

    effects, cache = ["teeth", "solids", "dxf", "stl"], tmp_path / "cache"
    cold = cadgen.build(paper, tmp_path / "cold", effects=effects, cache=cache)

    def never_a_gear(thin):
        def thinned(*args, **kwargs):   # the cam's contour is thinned for its solid: not a gear
            caller = sys._getframe(1).f_globals.get("__name__")
            assert caller != "cadgen.machine.hubs", "a warm build thinned a gear's outline"
            return thin(*args, **kwargs)

        return thinned

    monkeypatch.setattr(contour, "thin_outline", never_a_gear(contour.thin_outline))
    monkeypatch.setattr(contour, "thin_ring", never_a_gear(contour.thin_ring))
    warm = cadgen.build(paper, tmp_path / "warm", effects=effects, cache=cache)
    assert (warm.report["gear_cache"]["hits"], warm.report["gear_cache"]["misses"]) == (PAIRS, 0)
    cold_files = {f.relative_to(cold.output_dir): f.read_bytes()
                  for f in sorted(cold.output_dir.rglob("*")) if f.is_file()}
    warm_files = {f.relative_to(warm.output_dir): f.read_bytes()
                  for f in sorted(warm.output_dir.rglob("*")) if f.is_file()}
    assert {str(name) for name in cold_files} >= {"drawings/train.dxf", "solids/sun.stl"}
    for name, data in cold_files.items():
        if name.name != "report.json":       # stage times, cache hits
            assert warm_files[name] == data, name
    # a damaged outline entry is a miss: thinned again (here, by the real thinning) and stored
    monkeypatch.undo()
    from cadgen.machine.hubs import CuttingOutline

    store = GearCache(cache)
    outlines = [entry for entry in sorted(cache.glob("??/*.gear"))
                if isinstance(store.get(entry.stem), CuttingOutline)]
    assert len(outlines) == sum(name.parent.name == "gears" for name in cold_files)
    for victim in outlines:
        victim.write_bytes(victim.read_bytes()[:-7])
    again = cadgen.build(paper, tmp_path / "again", effects=effects, cache=cache)
    for name, data in cold_files.items():
        if name.name != "report.json":
            assert (again.output_dir / name).read_bytes() == data, name
    assert all(isinstance(GearCache(cache).get(v.stem), CuttingOutline) for v in outlines)


def test_a_damaged_file_entry_is_made_again(paper, uncached, tmp_path):
    cache = tmp_path / "cache"
    _build(paper, tmp_path / "cold", cache)
    store = GearCache(cache)
    files = [entry for entry in sorted(cache.glob("??/*.gear"))
             if isinstance(store.get(entry.stem), bytes)]
    # the gears' files, the sheet and the cam's two (its file and drawing)
    assert len(files) == sum(name.startswith("gears/") for name in uncached) + 1 + 2
    for victim in files[:3]:
        data = victim.read_bytes()
        victim.write_bytes(data[:-1] + bytes([data[-1] ^ 0x01]))   # a payload byte flipped
    _, again = _build(paper, tmp_path / "again", cache)
    assert again == uncached
    assert all(isinstance(GearCache(cache).get(v.stem), bytes) for v in files[:3])


def _equal(a, b, path="stage"):
    """Recursive equality, arrays element by element (exactly, NaN equal to NaN)."""
    if isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype, path
        np.testing.assert_array_equal(a, b, err_msg=path)
    elif type(a).__name__ == "ArcLengthCurve":   # splines inside: compared by their values
        s = np.linspace(0.0, a.length, 997)
        assert type(b) is type(a) and (a.length, a.reversed) == (b.length, b.reversed), path
        np.testing.assert_array_equal(a.frame(s), b.frame(s), err_msg=path)
        np.testing.assert_array_equal(a.curvature(s), b.curvature(s), err_msg=path)
        np.testing.assert_array_equal(a.arc_of_source(s), b.arc_of_source(s), err_msg=path)
    elif dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), path
        for f in dataclasses.fields(a):
            _equal(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b) and len(a) == len(b), path
        for k, (x, y) in enumerate(zip(a, b)):
            _equal(x, y, f"{path}[{k}]")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _equal(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, float) and np.isnan(a):
        assert np.isnan(b), path
    else:
        assert a == b, path


def test_a_loaded_stage_equals_the_computed_one_in_every_array(paper, tmp_path):
    from cadgen.design import build_mechanism
    from cadgen.gears.trains import planting_train

    mechanism = build_mechanism(paper)
    cache = GearCache(tmp_path)
    computed = planting_train(paper, mechanism, cache=cache)
    loaded = planting_train(paper, mechanism, cache=cache)
    assert (cache.hits, cache.misses) == (PAIRS, PAIRS)
    for a, b in zip(computed.stages, loaded.stages, strict=True):
        # the pair's contact functions are closures (each train makes its own): the loaded
        # stage has the caller's pair, and every other field equal
        assert b.generated.pair.names == a.generated.pair.names
        _equal(*(dataclasses.replace(s, generated=dataclasses.replace(s.generated, pair=None),
                                     meshing=dataclasses.replace(s.meshing, seconds=0.0))
                 for s in (a, b)), a.name)


def test_a_grid_over_the_planter_length_recuts_no_gear(paper, tmp_path):
    text = PAPER.read_text(encoding="utf-8")
    assert "L2 = 190.0" in text
    shorter = cadgen.validate_text(text.replace("L2 = 190.0", "L2 = 180.0", 1))
    assert shorter.planter.L2 == 180.0
    cache = tmp_path / "cache"
    first, _ = _build(paper, tmp_path / "190", cache)
    second, _ = _build(shorter, tmp_path / "180", cache)
    assert (first["hits"], first["misses"]) == (0, PAIRS)
    assert (second["hits"], second["misses"]) == (PAIRS, 0)


def test_a_key_changes_with_what_determines_the_stage():
    from cadgen.gears.pairs import circle_pair
    from cadgen.gears.teeth import ToothSystem

    options = dict(flank_points=48, bore_radius=5.0, force_shaper=False, poses=32, span=None,
                   circular=True)
    pair = circle_pair(("a", "b"), 20.0, 30.0)
    key = stage_key("s", pair, (20, 30), ToothSystem(2.0), **options)
    assert key == stage_key("s", circle_pair(("a", "b"), 20.0, 30.0), (20, 30), ToothSystem(2.0),
                            **options)
    others = [stage_key("t", pair, (20, 30), ToothSystem(2.0), **options),
              stage_key("s", circle_pair(("a", "b"), 20.0, 30.000001), (20, 30),
                        ToothSystem(2.0), **options),
              stage_key("s", pair, (20, 31), ToothSystem(2.0), **options),
              stage_key("s", pair, (20, 30), ToothSystem(2.0, backlash=0.01), **options),
              stage_key("s", pair, (20, 30), ToothSystem(2.0), **{**options, "poses": 33}),
              stage_key("s", pair, (20, 30), ToothSystem(2.0), **{**options, "bore_radius": 6})]
    assert len({key, *others}) == len(others) + 1


_KEY_IN_A_FRESH_PROCESS = """
import sys
from cadgen.gears.cache import stage_key
from cadgen.gears.pairs import circle_pair
from cadgen.gears.teeth import ToothSystem
assert "scipy" not in sys.modules   # what the key once read as scipy=None
print(stage_key("s", circle_pair(("a", "b"), 20.0, 30.0), (20, 30), ToothSystem(2.0),
                flank_points=48, bore_radius=5.0, force_shaper=False, poses=32, span=None,
                circular=True))
"""


def test_a_key_does_not_depend_on_what_the_process_has_imported():
    """The libraries' versions are part of a key: read whether or not the process has
    imported them yet (a key made before the cutting first loaded scipy once differed from
    the same gear's key in a process that had: a second process missed the first's
    entries)."""
    import subprocess
    import sys

    import scipy

    from cadgen.gears.pairs import circle_pair
    from cadgen.gears.teeth import ToothSystem

    fresh = subprocess.run([sys.executable, "-c", _KEY_IN_A_FRESH_PROCESS], capture_output=True,
                           text=True, check=True, cwd=REPO).stdout.strip()
    here = stage_key("s", circle_pair(("a", "b"), 20.0, 30.0), (20, 30), ToothSystem(2.0),
                     flank_points=48, bore_radius=5.0, force_shaper=False, poses=32, span=None,
                     circular=True)
    assert fresh == here
    from cadgen.gears.cache import _libraries

    assert f"scipy={scipy.__version__}" in _libraries()     # the versions are in the key


@pytest.mark.parametrize("damage", ["truncated", "flipped"])
def test_a_bad_entry_is_a_miss_and_the_build_recomputes_it(paper, uncached, tmp_path, damage):
    cache = tmp_path / "cache"
    _build(paper, tmp_path / "cold", cache)
    entries = _stage_entries(cache)
    assert len(entries) == PAIRS
    victim = entries[0]
    data = victim.read_bytes()
    if damage == "truncated":
        victim.write_bytes(data[: len(data) // 2])
    else:
        position = _HEADER.size + (len(data) - _HEADER.size) // 2   # a payload byte
        victim.write_bytes(data[:position] + bytes([data[position] ^ 0x01])
                           + data[position + 1:])
    store = GearCache(cache)
    assert store.get(victim.stem) is None and (store.hits, store.misses) == (0, 1)
    assert not victim.exists()      # deleted, so the next build stores a good one
    victim.write_bytes(b"CGGEAR")   # shorter than a header: unreadable, still no exception
    record, files = _build(paper, tmp_path / "again", cache)
    assert (record["hits"], record["misses"]) == (PAIRS - 1, 1)
    assert files == uncached
    assert GearCache(cache).get(victim.stem) is not None   # recomputed and stored again


def test_get_never_raises_for_a_missing_or_garbage_entry(tmp_path):
    store = GearCache(tmp_path)
    key = "ab" * 32
    assert store.get(key) is None
    store.path(key).parent.mkdir()
    for garbage in (b"", b"\x00" * 200, os.urandom(5000)):
        store.path(key).write_bytes(garbage)
        assert store.get(key) is None
    assert store.put(key, {"x": np.arange(3)}) and store.get(key)["x"].tolist() == [0, 1, 2]
    with pytest.raises(ValueError, match="hexadecimal"):
        store.get("../../etc/passwd")
    assert store.put("cd" * 32, lambda: None) is False   # does not pickle: not stored


# ------------------------------------------------------------------------ concurrent writers
KEY = "5a" * 32
SIZE = 400_000


def _writer(directory, mark, times):
    store = GearCache(directory)
    for _ in range(times):
        assert store.put(KEY, {"mark": mark, "values": np.full(SIZE, float(mark))})


def _context():
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


def test_concurrent_writers_of_one_key_never_show_a_reader_a_partial_entry(tmp_path):
    context = _context()
    writers = [context.Process(target=_writer, args=(str(tmp_path), mark, 50))
               for mark in (1, 2)]
    for writer in writers:
        writer.start()
    store, whole, deadline = GearCache(tmp_path), 0, time.monotonic() + 120
    while any(w.is_alive() for w in writers) and time.monotonic() < deadline:
        value = store.get(KEY)
        if value is None:
            continue
        # a whole entry of one writer: never a mixture of the two, never short
        assert value["mark"] in (1, 2) and value["values"].shape == (SIZE,)
        assert (value["values"] == value["mark"]).all()
        whole += 1
    for writer in writers:
        writer.join(60)
        assert writer.exitcode == 0
    assert store.get(KEY)["values"].shape == (SIZE,)
    assert whole > 0
    assert not list(tmp_path.glob("??/*.tmp"))   # no temporary file left behind
    assert store.stats()[0] == 1


# ------------------------------------------------------------------------ command line
def test_cache_clear_and_info_on_the_command_line(paper, tmp_path, monkeypatch, capsys):
    cache = tmp_path / "cache"
    monkeypatch.setenv("CADGEN_CACHE_DIR", str(cache))
    assert cadgen.cache_directory() == cache
    result = cadgen.build(paper, None, effects=["teeth"])   # the default: the cache
    assert result.report["gear_cache"]["directory"] == str(cache)
    assert main(["cache", "info"]) == 0
    out = capsys.readouterr().out
    assert str(cache) in out and f"entries:   {PAIRS}" in out
    assert main(["cache", "clear"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"removed {PAIRS} gear cache entries (") and str(cache) in out
    assert cache.is_dir() and not list(cache.iterdir())
    assert cadgen.cache_info()["entries"] == 0
    assert main(["cache", "clear"]) == 0 and "removed 0 " in capsys.readouterr().out


def test_no_cache_builds_use_no_cache(paper, tmp_path, monkeypatch, capsys):
    cache = tmp_path / "cache"
    monkeypatch.setenv("CADGEN_CACHE_DIR", str(cache))
    assert main(["build", str(PAPER), "--effects", "teeth", "--no-cache",
                 "--output-dir", str(tmp_path / "out")]) in (0, 1)
    import json

    report = json.loads((tmp_path / "out" / paper.name / "report.json").read_text())
    assert report["gear_cache"] == {"used": False, "directory": None, "hits": 0, "misses": 0}
    assert not cache.exists()
    capsys.readouterr()


def test_an_unusable_cache_directory_builds_without_it(paper, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    record = cadgen.build(paper, None, effects=["teeth"], cache=blocker / "gears").report[
        "gear_cache"]
    assert record == {"used": False, "directory": str(blocker / "gears"), "hits": 0,
                      "misses": 0}


def test_a_scene_without_teeth_never_touches_the_cache(paper, tmp_path):
    report = cadgen.build(paper, None, effects=["metrics"], cache=tmp_path / "c").report
    assert report["gear_cache"]["used"] is False and not (tmp_path / "c").exists()


def test_batch_no_cache_reaches_each_designs_build(monkeypatch, tmp_path, capsys):
    import argparse

    import cadgen.batch as batch

    parser = batch.add_batch_arguments(argparse.ArgumentParser())
    assert parser.parse_args([]).no_cache is False
    seen = []

    def run_batch(jobs, output_root, **options):   # records what the workers would get
        seen.append(options.get("build_kwargs"))
        return []

    monkeypatch.setattr(batch, "run_batch", run_batch)
    monkeypatch.setattr(batch, "write_summary", lambda summaries, root: ("a.csv", "a.html"))
    for argv in ([str(PAPER), "--no-cache"], [str(PAPER)]):
        batch.main_batch(parser.parse_args([*argv, "--output-dir", str(tmp_path)]))
    assert seen == [{"cache": False}, None]   # the default leaves a custom build's options be
    capsys.readouterr()


@pytest.mark.filterwarnings("ignore:invalid value encountered in linearrings:RuntimeWarning")
def test_remember_cutting_outlines_stores_loads_and_leaves_a_bad_gear_to_its_writer(tmp_path):
    """The outline is thinned once and stored, found by the next build's profiles (equal
    arrays, read-only as computed); a gear whose outline cannot be thinned (a NaN vertex:
    GEOS refuses it) is skipped, not raised: the DXF writer checks a gear first and names
    the problem."""
    from types import SimpleNamespace

    from cadgen.gears.teeth import GearProfile
    from cadgen.machine.hubs import cutting_outline
    from cadgen.pipeline.gear_cache import remember_cutting_outlines

    angles = np.linspace(0.0, 2.0 * np.pi, 400, endpoint=False)
    ring = np.column_stack([10.0 * np.cos(angles), 10.0 * np.sin(angles)])
    broken = ring.copy()
    broken[7] = np.nan

    def train():
        profiles = [GearProfile(name=name, outline=outline, pitch_curve=ring, teeth=20,
                                module=1.0, bore_radius=2.0)
                    for name, outline in (("good", ring), ("broken", broken))]
        return SimpleNamespace(cache=GearCache(tmp_path), gears=[(p, None, None, None)
                                                                  for p in profiles])

    first = train()
    assert remember_cutting_outlines(first, 0.005) == 0
    assert GearCache(tmp_path).stats()[0] == 1          # the good gear's outline only
    second = train()
    assert remember_cutting_outlines(second, 0.005) == 1
    good = second.gears[0][0]
    loaded = cutting_outline(good, 0.005)                 # from the profile: not thinned again
    assert not loaded.outline.flags.writeable
    expected = cutting_outline(first.gears[0][0], 0.005)
    np.testing.assert_array_equal(loaded.outline, expected.outline)
    np.testing.assert_array_equal(loaded.pitch, expected.pitch)
    assert loaded.tolerance_used == expected.tolerance_used
    assert remember_cutting_outlines(SimpleNamespace(cache=None, gears=[]), 0.005) == 0
    assert remember_cutting_outlines(train(), float("nan")) == 0
