"""Where the gear cache lives, and opening, clearing and describing it for the build and CLI.

The cache itself (entries, keys, atomic writes) is :mod:`cadgen.gears.cache`; this module
adds the one platform-dependent choice, the user's cache directory (platformdirs), so the
gear code stays free of it.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["CACHE_DIR_VARIABLE", "cache_directory", "open_cache", "cache_record", "clear_cache",
           "cache_info", "remember_cutting_outlines"]

#: Environment variable naming the gear cache's directory (tests, a shared scratch disk).
CACHE_DIR_VARIABLE = "CADGEN_CACHE_DIR"


def cache_directory() -> Path:
    """The gear cache's directory: ``$CADGEN_CACHE_DIR`` when set, else
    ``platformdirs.user_cache_dir("cadgen")/gears`` (``~/.cache/cadgen/gears`` on Linux)."""
    chosen = os.environ.get(CACHE_DIR_VARIABLE)
    if chosen:
        return Path(chosen).expanduser()
    import platformdirs

    return Path(platformdirs.user_cache_dir("cadgen")) / "gears"


def open_cache(cache):
    """The :class:`~cadgen.gears.cache.GearCache` a build's ``cache`` argument asks for, or None.

    Parameters
    ----------
    cache : bool, path-like or None
        True: :func:`cache_directory`; a path: that directory; False or None: no cache.
        A directory that cannot be made or written gives None: a build never fails for
        want of a cache, it only runs slower (the report's ``gear_cache`` says so).
    """
    if cache is None or cache is False:
        return None
    from cadgen.gears.cache import GearCache

    directory = cache_directory() if cache is True else Path(cache)
    try:
        return GearCache(directory)
    except OSError:
        return None


def cache_record(cache, asked=None) -> dict:
    """The report's ``gear_cache``: ``{"used", "directory", "hits", "misses"}``.

    ``asked`` is the build's ``cache`` argument, so a cache that could not be opened still
    names the directory that was tried.
    """
    if cache is None:
        tried = None
        if asked is True:
            tried = str(cache_directory())
        elif asked not in (None, False):
            tried = str(asked)
        return {"used": False, "directory": tried, "hits": 0, "misses": 0}
    return {"used": True, "directory": str(cache.directory), "hits": cache.hits,
            "misses": cache.misses}


def clear_cache(directory=None) -> dict:
    """Remove every cached gear: ``{"directory", "entries", "bytes"}`` removed.

    ``directory`` defaults to :func:`cache_directory`; a missing one has nothing to remove
    (it is not created).
    """
    from cadgen.gears.cache import GearCache

    directory = Path(directory) if directory is not None else cache_directory()
    if not directory.is_dir():
        return {"directory": str(directory), "entries": 0, "bytes": 0}
    entries, freed = GearCache(directory, create=False).clear()
    return {"directory": str(directory), "entries": entries, "bytes": freed}


def cache_info(directory=None) -> dict:
    """The gear cache's ``{"directory", "exists", "entries", "bytes"}`` (nothing created)."""
    from cadgen.gears.cache import GearCache

    directory = Path(directory) if directory is not None else cache_directory()
    if not directory.is_dir():
        return {"directory": str(directory), "exists": False, "entries": 0, "bytes": 0}
    entries, size = GearCache(directory, create=False).stats()
    return {"directory": str(directory), "exists": True, "entries": entries, "bytes": size}


def remember_cutting_outlines(train, chord_tolerance: float) -> int:
    """Give each bored gear of ``train`` its cutting outline (thinned to ``chord_tolerance``:
    :func:`cadgen.machine.hubs.cutting_outline`, which the gear's solid, its DXF file and the
    train sheet all draw) from the train's gear cache, or thinned here and stored there.

    Kept as a gear file is (:class:`cadgen.export.train_sheet.CachedFiles`: keyed on the
    bored profile, the tolerance and the writers' and the thinning's sources), so a warm
    build thins no outline again. Returns how many were found; none without a cache or a
    usable tolerance, and a gear whose outline cannot be thinned is left alone (the stages
    that need the outline thin it, and say what is wrong: the DXF writer checks the gear
    first).
    """
    import math

    cache = getattr(train, "cache", None)
    tolerance = float(chord_tolerance)
    if cache is None or not (math.isfinite(tolerance) and tolerance > 0):
        return 0
    from cadgen.export.train_sheet import CachedFiles
    from cadgen.machine.hubs import CuttingOutline, cutting_outline

    files, found = CachedFiles(cache, tolerance), 0
    for profile, *_ in train.gears:
        hits = cache.hits
        try:
            cut = files.get(("cutting outline", profile),
                            lambda profile=profile: cutting_outline(profile, tolerance),
                            kind=CuttingOutline)
        except Exception:   # noqa: BLE001 - a gear its DXF writer refuses: said there
            continue
        if cache.hits > hits:   # read back: read-only as computed, the profile's from now on
            for array in (cut.outline, cut.pitch):
                array.setflags(write=False)
            profile.derived(("cutting outline", tolerance), lambda cut=cut: cut)
            found += 1
    return found


def view_glb(glb: bytes, cache) -> bytes | None:
    """The report's lighter copy of ``solids/assembly.glb`` (:func:`cadgen.report.view_glb.
    lighter_glb`), from the cache a build's ``cache`` argument asks for, or made and stored
    there: thinning the paper design's assembly takes about a second, and a design built
    again (unchanged) has the same GLB. Keyed on the file's bytes and the thinning's source.
    None when the copy cannot be made (the page then embeds the file, saying why).
    """
    import hashlib
    import importlib.resources

    from cadgen.report.view_glb import lighter_glb

    store, key = open_cache(cache), None
    if store is not None:
        digest = hashlib.sha256(b"cadgen report view glb\0")
        folder = importlib.resources.files("cadgen.report")
        for source in ("view_glb.py", "decimate.py"):
            digest.update(folder.joinpath(source).read_bytes())
        digest.update(glb)
        key = digest.hexdigest()
        stored = store.get(key)
        if isinstance(stored, bytes):
            return stored
    try:
        light = lighter_glb(glb)
    except (ValueError, KeyError, IndexError, TypeError):
        return None
    if store is not None:
        store.put(key, light)
    return light
