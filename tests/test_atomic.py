"""Tests of cadgen.export.atomic: atomic files and staged output directories."""

from __future__ import annotations

import os
import stat

import pytest

import cadgen.export.atomic
from cadgen.export.atomic import staged_directory, write_bytes_atomic, write_text_atomic


def _names(directory):
    return sorted(p.name for p in directory.iterdir())


@pytest.fixture
def umask_022():
    old = os.umask(0o022)
    yield
    os.umask(old)


def test_write_bytes_creates_and_replaces(tmp_path):
    target = tmp_path / "gear.dxf"
    assert write_bytes_atomic(target, b"first") == target
    assert target.read_bytes() == b"first"
    write_bytes_atomic(target, b"second, longer")
    assert target.read_bytes() == b"second, longer"
    assert _names(tmp_path) == ["gear.dxf"]  # no temporary left behind


def test_write_text_keeps_newlines_and_encodes_utf8(tmp_path):
    target = tmp_path / "report.md"
    write_text_atomic(str(target), "a\nb\u00b0\n")
    assert target.read_bytes() == "a\nb\u00b0\n".encode("utf-8")


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_written_file_has_ordinary_permissions(tmp_path, umask_022):
    target = tmp_path / "part.stl"
    write_bytes_atomic(target, b"solid")
    assert stat.S_IMODE(target.stat().st_mode) == 0o644


def test_failed_write_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "report.json"
    target.write_text("old")

    def broken_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(cadgen.export.atomic.os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        write_text_atomic(target, "new")
    assert target.read_text() == "old"
    assert _names(tmp_path) == ["report.json"]


def test_write_into_missing_directory_fails(tmp_path):
    with pytest.raises(FileNotFoundError):
        write_bytes_atomic(tmp_path / "nope" / "x.bin", b"")
    assert _names(tmp_path) == []


def test_staged_directory_creates_final(tmp_path):
    final = tmp_path / "outputs" / "design"
    with staged_directory(final) as staging:
        assert staging.is_dir() and staging.parent == final.parent and staging != final
        assert not final.exists()  # nothing visible until the block succeeds
        write_text_atomic(staging / "report.json", "{}")
    assert _names(final) == ["report.json"]
    assert _names(final.parent) == ["design"]


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_staged_directory_has_ordinary_permissions(tmp_path, umask_022):
    final = tmp_path / "design"
    with staged_directory(final):
        pass
    assert stat.S_IMODE(final.stat().st_mode) == 0o755


def test_staged_directory_replaces_old_outputs(tmp_path):
    final = tmp_path / "design"
    final.mkdir()
    (final / "stale.stl").write_text("old")
    with staged_directory(final) as staging:
        (staging / "fresh.stl").write_text("new")
        assert (final / "stale.stl").exists()
    assert _names(final) == ["fresh.stl"]
    assert _names(tmp_path) == ["design"]


def test_staged_directory_failure_keeps_old_outputs(tmp_path):
    final = tmp_path / "design"
    final.mkdir()
    (final / "good.stl").write_text("old")
    with pytest.raises(RuntimeError, match="boom"):
        with staged_directory(final) as staging:
            (staging / "half.stl").write_text("partial")
            raise RuntimeError("boom")
    assert _names(final) == ["good.stl"] and (final / "good.stl").read_text() == "old"
    assert _names(tmp_path) == ["design"]


def test_staged_directory_failure_without_old_outputs_leaves_nothing(tmp_path):
    final = tmp_path / "design"
    with pytest.raises(KeyboardInterrupt):
        with staged_directory(final) as staging:
            (staging / "half.stl").write_text("partial")
            raise KeyboardInterrupt
    assert _names(tmp_path) == []


def test_staged_directory_failed_swap_restores_old_outputs(tmp_path, monkeypatch):
    final = tmp_path / "design"
    final.mkdir()
    (final / "good.stl").write_text("old")
    real_replace = os.replace

    def replace(src, dst):
        if os.fspath(dst) == os.fspath(final) and "staging" in os.fspath(src):
            raise OSError("rename refused")
        return real_replace(src, dst)

    monkeypatch.setattr(cadgen.export.atomic.os, "replace", replace)
    with pytest.raises(OSError, match="rename refused"):
        with staged_directory(final) as staging:
            (staging / "new.stl").write_text("new")
    assert _names(final) == ["good.stl"]
    assert _names(tmp_path) == ["design"]


def test_staged_directory_refuses_a_file(tmp_path):
    final = tmp_path / "design"
    final.write_text("not a directory")
    with pytest.raises(NotADirectoryError):
        with staged_directory(final):
            pass  # pragma: no cover
    assert final.read_text() == "not a directory"


@pytest.mark.skipif(not hasattr(os, "kill"), reason="signals")
@pytest.mark.parametrize("moment", ["made", "swapped"])
def test_ctrl_c_as_the_staging_folder_is_made_or_swapped_leaves_no_stray_folder(
        moment, tmp_path, monkeypatch):
    # the signal arrives the instant the folder exists (inside mkdtemp) or the instant the
    # swap is done: raised there, it would leave a folder nobody knows of, or roll back a
    # swap half way; held back, it comes once the folder is named or the swap is whole
    import signal
    import tempfile

    from cadgen.processes import Interrupts

    final = tmp_path / "design"
    final.mkdir()
    (final / "old.txt").write_text("old")
    real_mkdtemp, real_replace = tempfile.mkdtemp, os.replace

    def mkdtemp(*args, **kwargs):
        made = real_mkdtemp(*args, **kwargs)
        if moment == "made" and ".staging-" in made:
            os.kill(os.getpid(), signal.SIGINT)
        return made

    def replace(source, target):
        real_replace(source, target)
        if moment == "swapped" and str(target) == str(final):
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(tempfile, "mkdtemp", mkdtemp)
    monkeypatch.setattr(os, "replace", replace)
    wrote = []
    # handled as in a terminal's foreground job (a suite run in the background ignores it)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with Interrupts(signals=(signal.SIGINT,)) as interrupts:
            with pytest.raises(KeyboardInterrupt):
                with staged_directory(final) as staging:
                    (staging / "new.txt").write_text("new")
                    wrote.append(True)
                for _ in range(10 ** 7):   # (not reached when the interrupt came in the block)
                    pass
            interrupts.stopping = True
    finally:
        signal.signal(signal.SIGINT, previous)
    assert interrupts.seen
    if moment == "made":   # interrupted before the block ran: the old outputs, untouched
        assert not wrote and _names(tmp_path) == ["design"]
        assert _names(final) == ["old.txt"]
    else:                  # the swap is whole: the new outputs, nothing stray beside them
        assert wrote and _names(tmp_path) == ["design"]
        assert _names(final) == ["new.txt"]
