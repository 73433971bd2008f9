"""Bought parts as solids: bearings, keys, screws, nuts, washers, dowels, placed where they sit.

The bill buys them (the assembly model's joints carry their :class:`~cadgen.assembly.graph.Item`
rows); this module makes them solids so the assembly file shows them, the overlap check fits
them into their seats and holes and the sweeps see a screw head reach the other arm or the soil.

Three pieces, each open to a new kind of item:

- **A maker per kind** (:func:`register_maker`): ``maker(size, segments) -> manifold3d.Manifold``,
  the item from its catalogue dimensions (``size``, a dict in mm) in its own frame, its axis
  along +z (see :mod:`cadgen.solids.bought_makers` for each kind's frame). The catalogue kinds
  are registered there; a new kind (a retaining ring's own shape, a spring's coil) registers its
  maker once, at import of the module that places it, and the solid is made once per
  ``(kind, size, segments)`` and shared by every copy (one geometry in the GLB, one FCL shape).
- **A placement per item** (:class:`BoughtItem`): a made part lists the items fixed in it, in
  its own frame, in :attr:`Part.bought <cadgen.solids.parts.Part.bought>`. The function that
  cuts a feature places what goes into it (the housing's seats and bolt holes, a shaft's
  keyseats, the cam's counterbores; :mod:`cadgen.solids.bought_places`), from the same record,
  so a bearing is where its seat is bored and a screw where its hole is drilled. To add items,
  append :class:`BoughtItem` records to the part that holds them (a retaining ring to its
  shaft, a hinge pin to the planter); nothing else changes.
- **The placed solids** (:func:`bought_parts`): one :class:`BoughtPart` per item, riding on its
  host part's body with the host's copies (a screw of gearbox 2's flange once per arm), its
  pose the host's times the item's placement (a key turns with its shaft). An item is placed
  when every made part it is fitted to was built, as the bill counts a joint only when its
  parts are there (:meth:`~cadgen.assembly.graph.AssemblyModel.bought`). Instances are named
  ``bought/<label>-<n>`` (``bought/bearing-6202-2Z-1``), ``n`` counting each label's copies.

The bought solids stay out of ``Assembly.parts`` (the made parts: their STL files, masses,
printing poses and bill rows); ``Assembly.bought`` holds them, and the assembly file, the
overlap check and the sweeps take them from there.

Adding items, for example a DIN 471 ring in a groove of a shaft, where the shaft's part is
made (``shaft_part``: its frame has the shaft's axis along z, heights in the body's frame)::

    from cadgen.solids.bought import BoughtItem, item_frame

    ring = BoughtItem("retaining ring", "DIN 471 - 15 x 1", {"inner": 14.3, "outer": 21.0,
                      "thickness": 1.0}, item_frame((0.0, 0.0, z_groove)), "ring-471-15")
    part.bought += (ring,)

``designation`` must be the bill's item's, letter for letter (the test counts the solids of
each bill row by it). A kind without a catalogue maker registers one first
(``register_maker("spring", maker)``, see :mod:`cadgen.solids.bought_makers` for the shapes
and the frames the registered kinds use); a record that places many items (a hinge pin in each
blade) returns them from the function that cuts their holes, as
:mod:`cadgen.solids.bought_places` does for the housings.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass
from typing import Callable

import numpy as np

from cadgen.solids.parts import Part

__all__ = ["BoughtItem", "BoughtPart", "register_maker", "registered_kinds", "bought_solid",
           "bought_mesh", "bought_parts", "placed_designations", "item_frame", "fits_part",
           "BOUGHT_PREFIX"]

#: Instance names of bought solids start with this (the GLB's node names, the sweeps' pairs).
BOUGHT_PREFIX = "bought/"

#: kind -> maker(size: dict, segments: int) -> manifold3d.Manifold
_MAKERS: dict[str, Callable] = {}
#: (kind, size items, segments) -> (manifold, trimesh): one solid per distinct item
_SOLIDS: dict = {}


def register_maker(kind: str, maker: Callable, *, replace: bool = False) -> None:
    """Make bought items of ``kind`` (the bill's word: ``"bearing"``, ``"retaining ring"``)
    with ``maker(size, segments)``.

    Parameters
    ----------
    kind : str
        The :class:`~cadgen.assembly.graph.Item` kind the items are bought as.
    maker : callable
        ``maker(size: dict, segments: int) -> manifold3d.Manifold``: the item in its own frame
        (axis along +z), from its catalogue dimensions (mm), round features with ``segments``
        sides. Called once per distinct size.
    replace : bool
        Registering a kind twice is an error (two modules disagreeing on a shape), unless asked.
    """
    if not isinstance(kind, str) or not kind:
        raise ValueError(f"a bought item's kind is a non-empty string, not {kind!r}")
    if not callable(maker):
        raise TypeError(f"the maker of {kind!r} must be callable, not {maker!r}")
    if kind in _MAKERS and not replace and _MAKERS[kind] is not maker:
        raise ValueError(f"bought items of kind {kind!r} have a maker already "
                         "(register_maker(..., replace=True) to change it)")
    _MAKERS[kind] = maker
    for key in [key for key in _SOLIDS if key[0] == kind]:
        del _SOLIDS[key]


def registered_kinds() -> tuple[str, ...]:
    """The kinds a maker is registered for (the catalogue's and any added), sorted."""
    _defaults()
    return tuple(sorted(_MAKERS))


def _defaults() -> None:
    # the catalogue's makers register themselves on import (that module imports this one)
    import cadgen.solids.bought_makers  # noqa: F401


def _size_key(size: dict) -> tuple:
    """A size as a hashable key: its numbers as floats, its words (a set screw's point) as
    they are."""
    return tuple(sorted((str(name), value if isinstance(value, str) else float(value))
                        for name, value in size.items()))


def bought_solid(kind: str, size: dict, segments: int):
    """The manifold3d solid of one bought item (made once per kind, size and segments)."""
    return _made(kind, size, segments)[0]


def bought_mesh(kind: str, size: dict, segments: int):
    """Its trimesh (watertight, checked by :func:`~cadgen.solids.extrude.to_trimesh`), shared."""
    return _made(kind, size, segments)[1]


def _made(kind: str, size: dict, segments: int) -> tuple:
    _defaults()
    key = (kind, _size_key(size), int(segments))
    if key not in _SOLIDS:
        if kind not in _MAKERS:
            raise ValueError(f"no maker for bought items of kind {kind!r} (registered: "
                             f"{', '.join(sorted(_MAKERS))}); see register_maker")
        from cadgen.solids.extrude import to_trimesh

        solid = _MAKERS[kind](dict(size), int(segments))
        _SOLIDS[key] = (solid, to_trimesh(solid, f"{kind} {dict(key[1])}"))
    return _SOLIDS[key]


def item_frame(origin=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), turn: float = 0.0) -> np.ndarray:
    """The 4x4 placement of an item in its host's frame: its own +z along ``axis``, turned by
    ``turn`` (rad) about it, its origin at ``origin`` (mm).

    An axis along -z is a half turn about x (a screw put in from below); any other axis the
    shortest rotation onto it (a splice's bolts lie in the plane).
    """
    axis = np.asarray(axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if axis.shape != (3,) or not np.isfinite(norm) or norm == 0.0:
        raise ValueError(f"an item's axis is a non-zero 3-vector, not {axis!r}")
    z = axis / norm
    if z[2] > 1.0 - 1e-12:
        rotation = np.eye(3)
    elif z[2] < -1.0 + 1e-12:
        rotation = np.diag([1.0, -1.0, -1.0])
    else:   # Rodrigues' rotation of +z onto the axis
        cross = np.cross([0.0, 0.0, 1.0], z)
        sine, cosine = float(np.linalg.norm(cross)), float(z[2])
        k = cross / sine
        skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        rotation = np.eye(3) + sine * skew + (1.0 - cosine) * skew @ skew
    c, s = np.cos(turn), np.sin(turn)
    frame = np.eye(4)
    frame[:3, :3] = rotation @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    frame[:3, 3] = np.asarray(origin, dtype=float)
    return frame


@dataclass(frozen=True, eq=False)
class BoughtItem:
    """One bought item where it sits in the made part that holds it (its host).

    Attributes
    ----------
    kind : str
        What the bill calls it (the maker's key): ``"bearing"``, ``"key"``,
        ``"socket head cap screw"``, ``"hexagon nut"``, ``"plain washer"``, ``"dowel pin"``,
        ``"set screw"``, ...
    designation : str
        The bill's designation of it (:class:`~cadgen.assembly.graph.Item`), letter for letter:
        the placed solids are counted against the bill by it.
    size : dict
        Its catalogue dimensions (mm), what its maker reads.
    at : (4, 4) float
        Its own frame in the host part's frame (:func:`item_frame`).
    label : str
        Its instance names' stem (``"bearing-6202-2Z"``, ``"screw-M3x16"``).
    fitted : tuple of str
        The made parts (file stems; a housing half's segments match its stem) it is fitted to
        besides its host: a seat's bearing to its shaft, a key to its gear. It is placed only
        when they were all built, and the overlap check allows it their fit.
    allowance : float
        The designed overlap with those parts (mm, radial): a screw's thread in a tapped hole
        is as deep as half the difference of its nominal and tap-drill diameters.
    stack : str
        Items placed together by one rule on each other's faces (a screw, its washers and its
        nut; a free gear's two bearings) share a stack name: the overlap check takes their
        contact as designed and does not intersect them with each other.
    """

    kind: str
    designation: str
    size: dict
    at: np.ndarray
    label: str
    fitted: tuple = ()
    allowance: float = 0.0
    stack: str = ""

    def __post_init__(self):
        at = np.asarray(self.at, dtype=float)
        if at.shape != (4, 4) or not np.isfinite(at).all():
            raise ValueError(f"{self.label}: a placement is a finite 4x4 transform, not {at!r}")
        object.__setattr__(self, "at", at)
        object.__setattr__(self, "fitted", tuple(self.fitted))


@dataclass
class BoughtPart(Part):
    """A placed bought solid: a :class:`~cadgen.solids.parts.Part` riding on its host's body
    (its copies the host's), with the bill's designation, its host, the parts it is fitted to
    (the host's stem among them), its designed overlap with them and its stack (see
    :class:`BoughtItem`)."""

    designation: str = ""
    host: str = ""
    fitted: frozenset = frozenset()
    allowance: float = 0.0
    stack: str = ""


_SEGMENT = re.compile(r"-\d+$")
#: A part's own copy for a second arm (``shaft-C2-arm2``: its keyseats phased for arm 2)
_OWN_COPY = re.compile(r"-arm2$")


def fits_part(stem: str, fitted) -> bool:
    """Whether the made part ``stem`` is one of ``fitted`` (a segment of a cut housing half,
    ``gearbox1-base-2``, is its half's; a part's own copy for arm 2, ``shaft-C2-arm2``, is the
    part's)."""
    if stem in fitted or _OWN_COPY.sub("", stem) in fitted:
        return True
    match = _SEGMENT.search(stem)
    return match is not None and stem[:match.start()] in fitted


def bought_parts(parts, segments: int) -> list:
    """Every bought item of ``parts`` placed as a :class:`BoughtPart`, in the parts' order.

    Each rides on its host's body, once per host copy (its instances), at the host's local
    placement times the item's; an item fitted to a made part that is not among ``parts`` is
    left out (a gear not cut needs no key). ``segments``: sides of the items' round features
    (the solids' own, so a bearing's ring matches its seat's polygon).
    """
    made = {part.name for part in parts}
    numbers: Counter = Counter()
    placed = []
    for host in parts:
        copies = host.instances or ((host.name, host.body, 0.0),)
        for index, item in enumerate(getattr(host, "bought", ()) or ()):
            if not all(fits_part(stem, made) or any(fits_part(m, {stem}) for m in made)
                       for stem in item.fitted):
                continue
            solid, mesh = _made(item.kind, item.size, segments)
            instances = []
            for _, body, phase in copies:
                numbers[item.label] += 1
                instances.append((f"{BOUGHT_PREFIX}{item.label}-{numbers[item.label]}", body,
                                  phase))

            def local(phi, host_local=host.local, at=item.at):
                return np.asarray(host_local(phi), dtype=float) @ at

            placed.append(BoughtPart(
                f"{host.name}/{BOUGHT_PREFIX}{index + 1}-{item.label}", item.kind, host.body,
                solid, local, instances=tuple(instances), _mesh=mesh,
                designation=item.designation, host=host.name,
                fitted=frozenset(item.fitted) | {host.name}, allowance=float(item.allowance),
                stack=f"{host.name}/{item.stack}" if item.stack else ""))
    return placed


def placed_designations(assembly) -> Counter:
    """``{designation: placed copies}`` of every bought solid of ``assembly``: its bought items
    and the made-looking parts bought whole (the pricking case's sprocket)."""
    counts: Counter = Counter()
    for part in list(assembly.parts) + list(getattr(assembly, "bought", ())):
        if isinstance(part, BoughtPart) and part.designation:
            counts[part.designation] += len(part.instances) or 1
    return counts
