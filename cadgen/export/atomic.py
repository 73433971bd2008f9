"""Atomic output: files and whole output directories appear complete or not at all.

A file is written to a temporary sibling, flushed to disk, then renamed over the
target (``os.replace`` is atomic on POSIX and Windows for paths on one filesystem).
A build writes its outputs into a staged sibling directory, which replaces the
final directory only once everything in it was written. :func:`check_output_root`
says, before any work, whether a directory can take outputs at all.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from kinematics.errors import MechanismError

__all__ = ["OutputDirError", "check_output_root", "write_bytes_atomic", "write_text_atomic",
           "staged_directory"]


class OutputDirError(MechanismError):
    """An output directory that cannot take the outputs, with the reason.

    Attributes
    ----------
    directory : Path
        The directory as given.
    reason : str
        Why it cannot be used, for a person.
    """

    def __init__(self, directory: str | os.PathLike, reason: str):
        self.directory = Path(directory)
        self.reason = reason
        super().__init__(f"output directory {self.directory}: {reason}")

_DEFAULT_FILE_MODE = 0o666  # what open() would ask for, before the umask


def _current_umask() -> int:
    # Reading it from /proc avoids os.umask's set-and-restore, which races with
    # other threads creating files.
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_directory(directory: Path) -> None:
    """Make a rename in ``directory`` durable (a no-op where directories cannot be opened)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def check_output_root(directory: str | os.PathLike, *, name: str | None = None) -> Path:
    """Check, before any work, that ``directory`` can take outputs; write nothing.

    The directory need not exist: its nearest existing ancestor must be a directory
    in which a folder can be made (the staged build makes the rest). Whether a
    folder can be made is tried, not read off the permission bits, which say
    nothing about read-only or virtual filesystems (``/proc``) or a process that
    ignores them (root); the probe folder is removed at once.

    Parameters
    ----------
    directory : str or path-like
        The output root (``--output-dir``).
    name : str, optional
        A design's folder under it: an existing ``directory/name`` must be a directory.

    Returns
    -------
    Path
        ``directory`` as a Path.

    Raises
    ------
    OutputDirError
        Naming the directory and the reason.
    """
    root = Path(directory)
    existing = root
    while not os.path.lexists(existing) and existing.parent != existing:
        existing = existing.parent
    if existing != root and not existing.is_dir():
        raise OutputDirError(root, f"{existing} is a file, not a directory, so no folder can be "
                                   "made under it")
    if existing == root and not root.is_dir():
        what = "a broken link" if root.is_symlink() and not root.exists() else "a file"
        raise OutputDirError(root, f"it exists and is {what}, not a directory")
    try:
        probe = tempfile.mkdtemp(dir=existing, prefix=".cadgen-probe-")
    except OSError as error:
        why = error.strerror or str(error)
        raise OutputDirError(root, f"not writable: no folder can be created in it ({why})"
                             if existing == root else
                             f"cannot be made: no folder can be created in {existing} ({why})"
                             ) from None
    os.rmdir(probe)
    if name is not None and existing == root:
        final = root / name
        if os.path.lexists(final) and not final.is_dir():
            raise OutputDirError(root, f"{final} exists and is not a directory, so the design's "
                                       "outputs cannot go there")
    return root


def write_bytes_atomic(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` so that readers see the old file or the new one, never a part.

    Parameters
    ----------
    path : str or path-like
        Target file; its directory must exist. An existing file is replaced.
    data : bytes
        The whole content.

    Returns
    -------
    Path
        The target path.

    Notes
    -----
    The new file gets the permissions a plain ``open(path, "wb")`` would give it
    (``0o666`` less the umask), not the ``0o600`` of a temporary file.
    """
    path = Path(path)
    data = bytes(data)
    directory = path.parent
    if not directory.is_dir():
        raise FileNotFoundError(f"cannot write {path}: directory {directory} does not exist")
    fd, temporary = tempfile.mkstemp(dir=directory, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(temporary, _DEFAULT_FILE_MODE & ~_current_umask())
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise
    _fsync_directory(directory)
    return path


def write_text_atomic(path: str | os.PathLike, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` atomically (see :func:`write_bytes_atomic`).

    Parameters
    ----------
    path : str or path-like
        Target file; its directory must exist.
    text : str
        The whole content, written as is: ``"\\n"`` stays ``"\\n"`` on every platform.
    encoding : str, default "utf-8"

    Returns
    -------
    Path
        The target path.
    """
    return write_bytes_atomic(path, text.encode(encoding))


@contextlib.contextmanager
def staged_directory(final_dir: str | os.PathLike) -> Iterator[Path]:
    """Fill a temporary sibling directory, then swap it in for ``final_dir``.

    Parameters
    ----------
    final_dir : str or path-like
        The directory the outputs belong in. Its parent is created if needed; an
        existing ``final_dir`` is replaced (and removed) only when the block succeeds.

    Yields
    ------
    Path
        An empty directory next to ``final_dir`` (same filesystem, so the swap is a rename).

    Raises
    ------
    NotADirectoryError
        If ``final_dir`` exists and is not a directory.

    Notes
    -----
    If the block raises, the staged directory is removed and ``final_dir`` is left as
    it was. On success the old directory is first renamed aside, the staged one
    renamed into place, then the old one deleted; if the second rename fails the old
    directory is put back. Between the two renames (microseconds) ``final_dir`` does
    not exist: the standard library has no atomic exchange of two directories.

    Examples
    --------
    >>> with staged_directory(out / "xin2024-planter") as staging:  # doctest: +SKIP
    ...     write_text_atomic(staging / "report.json", text)
    """
    final_dir = Path(final_dir)
    if final_dir.exists() and not final_dir.is_dir():
        raise NotADirectoryError(f"{final_dir} exists and is not a directory")
    from cadgen.processes import sigint_deferred

    final_dir.parent.mkdir(parents=True, exist_ok=True)
    staging = None
    try:
        # made and named at once: a Ctrl-C between the two would leave a folder nobody removes
        with sigint_deferred():
            staging = Path(tempfile.mkdtemp(dir=final_dir.parent,
                                            prefix=f".{final_dir.name}.staging-"))
        yield staging
        # mkdtemp makes the directory 0o700; give it the mode mkdir() would.
        os.chmod(staging, 0o777 & ~_current_umask())
    except BaseException:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
        raise
    retired, swapped = None, False
    try:
        # the swap is the commit: done whole, a Ctrl-C meanwhile comes after it (the outputs
        # are then complete, in place, and the command still says it was interrupted)
        with sigint_deferred():
            if final_dir.exists():
                retired = Path(tempfile.mkdtemp(dir=final_dir.parent,
                                                prefix=f".{final_dir.name}.old-"))
                os.replace(final_dir, retired / final_dir.name)
            os.replace(staging, final_dir)
            swapped = True
    except BaseException:
        if not swapped:
            if retired is not None and (retired / final_dir.name).exists():
                os.replace(retired / final_dir.name, final_dir)
            shutil.rmtree(staging, ignore_errors=True)
        if retired is not None:
            shutil.rmtree(retired, ignore_errors=True)
        raise
    _fsync_directory(final_dir.parent)
    if retired is not None:
        # The new outputs are in place; a leftover old copy must not fail the build.
        shutil.rmtree(retired, ignore_errors=True)
