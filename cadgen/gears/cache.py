"""A content-addressed, on-disk cache of cut gear pairs (one :class:`~cadgen.gears.trains.GearStage`)
and of the files written for them.

Cutting the teeth is the slowest stage of a build, and a designer iterating or a grid
over the planter's lengths cuts the same gears again and again. A stage is stored under
the SHA-256 of everything that determines it (:func:`stage_key`), so an entry is either
exactly what the computation would give or is never looked up: there is no invalidation
to get wrong, only keys. The bytes of a gear's DXF file, of the train sheet and of the
cam's file (when the build cut its teeth with this cache) are stored likewise, under the
SHA-256 of what they draw and of the writer (:func:`file_key`), so a warm build writes its
cutting files without making them.

Entries are files ``<directory>/<key[:2]>/<key>.gear``: a fixed header (magic, format
version, the SHA-256 of the payload, the payload's length) and the payload, a pickle
(protocol 5). Each is written to a temporary file in its own folder, flushed, fsynced
and moved over the entry with :func:`os.replace`, which is atomic: concurrent writers of
one key (batch workers) each replace the whole file, and a reader sees a whole old or a
whole new entry, never a mixture. :meth:`GearCache.get` checks the header, the length
and the digest before unpickling, so a truncated or corrupted file (a full disk, a crash
without fsync, a bit flip) is a miss, never a wrong gear.

The digest guards integrity, not authenticity: the payload is a pickle, so the cache
directory must be the user's own (the default, ``platformdirs.user_cache_dir``, is).
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import pickle
import platform
import struct
import sys
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["GearCache", "stage_key", "file_key", "code_fingerprint", "CACHE_FORMAT",
           "FINGERPRINT_SAMPLES"]

#: Bump when the entry layout or the meaning of a key's fields changes.
CACHE_FORMAT = 1
#: Points of each contact function sampled over the pair's period for the key.
FINGERPRINT_SAMPLES = 2048
#: The entry header: magic, format version, pickle protocol, SHA-256 of the payload, its length.
_HEADER = struct.Struct(">8sHH32sQ")
_MAGIC = b"CGGEAR\r\n"   # a text-mode copy mangles \r\n, which the check then catches
_PROTOCOL = 5
_SUFFIX = ".gear"


class GearCache:
    """Gear stages on disk under ``directory``, keyed by :func:`stage_key`.

    Parameters
    ----------
    directory : path-like
        Created (with its parents) when missing.
    create : bool, default True
        False only looks (``stats``, ``clear``): nothing is created or checked.

    Raises
    ------
    OSError
        With ``create``, when ``directory`` cannot be created or is not a writable
        folder; the caller then builds without a cache.

    Attributes
    ----------
    hits, misses : int
        Lookups answered and not answered by this object (a bad entry is a miss).
    """

    def __init__(self, directory, *, create: bool = True):
        self.directory = Path(directory)
        if create:
            self.directory.mkdir(parents=True, exist_ok=True)
            if not os.access(self.directory, os.W_OK | os.X_OK):
                raise PermissionError(f"the gear cache directory {self.directory} is not "
                                      "writable")
        self.hits = 0
        self.misses = 0

    def path(self, key: str) -> Path:
        """The entry file of ``key`` (a lowercase hexadecimal digest)."""
        if not (isinstance(key, str) and len(key) >= 8
                and all(c in "0123456789abcdef" for c in key)):
            # keys become file names: anything but hex could leave the directory
            raise ValueError(f"a gear cache key is a lowercase hexadecimal digest, not {key!r}")
        return self.directory / key[:2] / (key + _SUFFIX)

    # ------------------------------------------------------------------ reading
    def get(self, key: str):
        """The value stored under ``key``, or None when missing, truncated, corrupt or unreadable.

        Never raises for a bad entry: it is a miss (and a corrupt one is deleted, best
        effort, so the next build stores a good one).
        """
        path = self.path(key)
        try:
            with open(path, "rb") as stream:
                identity = _identity(os.fstat(stream.fileno()))
                data = stream.read()
        except OSError:           # missing (the usual miss) or unreadable
            self.misses += 1
            return None
        value = _decode(data)
        if value is _BAD:
            _discard(path, identity)
            self.misses += 1
            return None
        self.hits += 1
        return value

    # ------------------------------------------------------------------ writing
    def put(self, key: str, value) -> bool:
        """Store ``value`` under ``key`` atomically; False when it could not be written.

        A cache that cannot be written (a full disk, a value that does not pickle) must
        never fail the build that would have used it: the error is swallowed.
        """
        path = self.path(key)
        try:
            payload = pickle.dumps(value, protocol=_PROTOCOL)
        except Exception:          # an unpicklable value: not cached, the build goes on
            return False
        header = _HEADER.pack(_MAGIC, CACHE_FORMAT, _PROTOCOL, hashlib.sha256(payload).digest(),
                              len(payload))
        temporary = None
        try:
            path.parent.mkdir(exist_ok=True)
            # in the entry's own folder: os.replace is atomic only within one filesystem
            handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{key[:16]}.",
                                                 suffix=".tmp")
            with os.fdopen(handle, "wb") as stream:
                stream.write(header)
                stream.write(payload)
                stream.flush()
                os.fsync(stream.fileno())   # whole on disk before it takes the entry's name
            os.replace(temporary, path)
            return True
        except OSError:
            if temporary is not None:
                try:
                    os.unlink(temporary)
                except OSError:
                    pass
            return False

    # ------------------------------------------------------------------ housekeeping
    def _files(self, pattern: str):
        return [p for p in self.directory.glob(f"??/{pattern}") if p.is_file()]

    def stats(self) -> tuple:
        """``(entries, bytes)`` of the entries stored now."""
        sizes = [_size(p) for p in self._files("*" + _SUFFIX)]
        return len(sizes), int(sum(sizes))

    def clear(self) -> tuple:
        """Remove every entry (and temporary files writers left behind): ``(entries, bytes)``."""
        count = freed = 0
        for path in self._files("*" + _SUFFIX) + self._files(".*.tmp"):
            size = _size(path)
            try:
                path.unlink()
            except OSError:
                continue
            if path.suffix == _SUFFIX:
                count += 1
            freed += size
        for folder in self.directory.glob("??"):
            try:
                folder.rmdir()          # only when empty
            except OSError:
                pass
        return count, freed


_BAD = object()


def _decode(data: bytes):
    """The value of an entry's bytes, or ``_BAD`` when any check fails."""
    if len(data) < _HEADER.size:
        return _BAD
    magic, version, protocol, digest, length = _HEADER.unpack_from(data)
    payload = memoryview(data)[_HEADER.size:]
    if (magic != _MAGIC or version != CACHE_FORMAT or protocol != _PROTOCOL
            or length != len(payload) or hashlib.sha256(payload).digest() != digest):
        return _BAD
    try:
        return pickle.loads(payload)
    except Exception:   # a class that moved since: a verified but stale entry is a miss too
        return _BAD


def _identity(status) -> tuple:
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns


def _discard(path: Path, identity: tuple) -> None:
    """Delete a bad entry unless a writer has replaced it since it was read."""
    try:
        if _identity(os.stat(path)) == identity:
            path.unlink()
    except OSError:
        pass


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:
        return 0


# ---------------------------------------------------------------------------------- keys
_FINGERPRINT: list = []


def code_fingerprint() -> str:
    """SHA-256 of the source of ``cadgen/gears/*.py`` and ``kinematics/*.py`` (read once).

    A cached gear is the output of this code: a changed cutter envelope, check or
    meshing rule must not be answered with gears the old code cut, and a version number
    is not bumped on every edit of a source checkout. Hashing the sources that compute a
    stage (everything a stage calls lives in these two packages, besides numpy, scipy
    and shapely, whose versions go into the key too) makes any edit a new key: the
    price is a cold cache after an edit, never a stale gear.
    """
    if not _FINGERPRINT:
        import kinematics

        digest = hashlib.sha256()
        for package in (Path(__file__).parent, Path(kinematics.__file__).parent):
            for source in sorted(package.glob("*.py")):
                digest.update(f"{package.name}/{source.name}\0".encode())
                digest.update(source.read_bytes())
                digest.update(b"\0")
        _FINGERPRINT.append(digest.hexdigest())
    return _FINGERPRINT[0]


def _libraries() -> str:
    """Versions of the numerical libraries a stage's numbers depend on.

    Imported here, not looked up among the modules already loaded: a key made before the
    cutting first imported scipy read ``scipy=None`` (and shapely's, GEOS's), so the same
    gear had two keys depending on what the process had loaded (a second process cutting
    the same train missed the first's entries), and the key did not hold those versions.
    """
    import importlib

    names = []
    for name in ("numpy", "scipy", "shapely"):
        module = importlib.import_module(name)
        names.append(f"{name}={getattr(module, '__version__', None)}")
    shapely = sys.modules["shapely"]
    names.append(f"geos={getattr(shapely, 'geos_version_string', None)}")
    names.append(f"python={sys.version_info[:2]} machine={platform.machine()}")
    return " ".join(names)


def _feed(digest, value) -> None:
    """Feed ``value`` to ``digest`` unambiguously: each item tagged with its type and size."""
    if value is None or isinstance(value, str):
        digest.update(f"{type(value).__name__}:{value!r};".encode())
    elif isinstance(value, (bool, np.bool_)):
        digest.update(f"bool:{bool(value)};".encode())
    elif isinstance(value, (int, np.integer)):
        digest.update(f"int:{int(value)};".encode())
    elif isinstance(value, (float, np.floating)):
        digest.update(b"float:" + np.float64(value).tobytes())   # exact, not a rounded repr
    elif isinstance(value, np.ndarray):
        array = np.ascontiguousarray(value)
        digest.update(f"array:{array.dtype.str}:{array.shape};".encode())
        digest.update(array.tobytes())
    elif isinstance(value, dict):
        digest.update(f"dict:{len(value)};".encode())
        for name in sorted(value, key=str):
            _feed(digest, str(name))
            _feed(digest, value[name])
    elif isinstance(value, (tuple, list)):
        digest.update(f"seq:{len(value)};".encode())
        for item in value:
            _feed(digest, item)
    elif dataclasses.is_dataclass(value):
        digest.update(f"{type(value).__qualname__}:".encode())
        # fields left out of comparison (remembered derived values) say nothing of the value
        _feed(digest, {f.name: getattr(value, f.name) for f in dataclasses.fields(value)
                       if f.compare})
    else:
        raise TypeError(f"cannot key a gear stage on a {type(value).__name__}: {value!r}")


def _pair_fingerprint(pair, samples: int = FINGERPRINT_SAMPLES) -> dict:
    """The pair's contact functions sampled over its period: the pitch curves, as numbers.

    The functions are closures (no source to hash); two pairs whose drive and driven
    ``rho, drho, psi, dpsi`` agree to the last bit at every sample cut the same gears.
    """
    tau = np.arange(samples) * (float(pair.period) / samples)
    samples_of = {}
    for which, functions in (("drive", pair.drive), ("driven", pair.driven)):
        samples_of[which] = [np.asarray(v, dtype=np.float64) * np.ones_like(tau)
                             for v in functions(tau)]
    return {"names": tuple(pair.names), "centre_distance": float(pair.centre_distance),
            "period": float(pair.period), "breaks": np.asarray(pair.breaks, dtype=np.float64),
            "curve_periods": np.asarray(pair.curve_periods, dtype=np.float64),
            "samples": samples, **samples_of}


def stage_key(name: str, pair, teeth, system, *, flank_points: int, bore_radius: float,
              force_shaper: bool, poses: int, span: float | None, circular: bool,
              drive=None, shifts=(0.0, 0.0)) -> str:
    """The hex SHA-256 of everything that determines one stage of a gear train.

    Parameters
    ----------
    name : str
        The stage's name (it names the gears' problems in the checks).
    pair : PitchPair
        Fingerprinted by :func:`_pair_fingerprint` (names, centre distance, period,
        breaks and each gear's contact functions sampled).
    teeth : int or (int, int)
    system : ToothSystem
        Every field (module, pressure angle, addendum, dedendum, tip radius, backlash,
        profile shift: the pair's basic rack; each gear's own shift is in ``shifts``).
    flank_points : int
    bore_radius : float
    force_shaper : bool
    poses : int
        Meshing poses, as resolved for this stage.
    span : float or None
        The part of the cycle the meshing check runs through (None: all of it).
    circular : bool
    drive : (float, (GearProfile, GearCheck, spaces)), optional
        A drive gear carried from another mesh: its phase and the whole cut gear.
    shifts : (float, float)
        The (drive, driven) profile-shift coefficients the gears are cut with.

    Returns
    -------
    str
        64 lowercase hexadecimal digits. Also keyed: :data:`CACHE_FORMAT`, the
        :func:`code_fingerprint` and the numerical libraries' versions.
    """
    digest = hashlib.sha256()
    teeth = (teeth, teeth) if np.isscalar(teeth) else tuple(teeth)
    _feed(digest, {
        "format": CACHE_FORMAT, "code": code_fingerprint(), "libraries": _libraries(),
        "stage": str(name), "pair": _pair_fingerprint(pair),
        "teeth": tuple(int(z) for z in teeth),
        "system": system, "flank_points": int(flank_points), "bore_radius": float(bore_radius),
        "force_shaper": bool(force_shaper), "poses": int(poses),
        "span": None if span is None else float(span), "circular": bool(circular),
        "drive": None if drive is None else (float(drive[0]), drive[1]),
        "shifts": tuple(float(x) for x in shifts),
    })
    return digest.hexdigest()


def file_key(inputs, *, chord_tolerance: float, writer: str) -> str:
    """The hex SHA-256 of everything that decides a written gear file's bytes.

    Parameters
    ----------
    inputs : tuple
        What the file draws, fed whole: ``("gear dxf", profile)`` (the bored
        :class:`~cadgen.gears.teeth.GearProfile`: outline, pitch curve, module, bore, hole,
        keyway angle, name) or ``("train sheet", placements, planes)``.
    chord_tolerance : float
        mm, the outline's thinning.
    writer : str
        The writer's fingerprint (its sources and ezdxf's version:
        :func:`cadgen.export.dxf.writer_fingerprint`), from the caller: the gear package
        does not import the writers.

    Returns
    -------
    str
        64 lowercase hexadecimal digits; also keyed: :data:`CACHE_FORMAT`, the
        :func:`code_fingerprint` and the versions of numpy and shapely (GEOS), which thin
        the outline.
    """
    import shapely

    digest = hashlib.sha256()
    _feed(digest, {
        "format": CACHE_FORMAT, "code": code_fingerprint(), "writer": str(writer),
        "libraries": f"numpy={np.__version__} shapely={shapely.__version__} "
                     f"geos={shapely.geos_version_string} python={sys.version_info[:2]} "
                     f"machine={platform.machine()}",
        "chord_tolerance": float(chord_tolerance), "inputs": inputs,
    })
    return digest.hexdigest()
