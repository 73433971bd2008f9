"""The bought items' solids from their catalogue dimensions, one maker per kind.

Each maker takes the item's ``size`` (mm; the keys below) and the sides of a round feature and
returns a manifold3d solid in the item's own frame, its axis along +z. The shapes are the
catalogue's envelopes, true to the dimensions the fits and clearances depend on; what only a
drawing shows is left out (a screw's hexagon socket and thread, a key's rounded ends, the
balls and seals of a bearing):

``bearing``
    ``bore``, ``outside``, ``width`` (ISO 15): one ring from bore to outside, ``z`` 0 to
    width (inner and outer ring as one body: the seat and the journal see nothing else).
``key``
    ``width`` b, ``height`` h, ``length`` l (DIN 6885): a box, ``x`` 0 to h (outwards from the
    keyseat's bottom), ``y`` centred, ``z`` 0 to l. The keyseats are cut as plain boxes of the
    key's length (:func:`~cadgen.solids.split_housing.shaft_solid`), so the key fills its seat.
``socket head cap screw``
    ``d``, ``length`` l, ``head_diameter`` dk, ``head_height`` k (ISO 4762): the head ``z`` 0
    to k, the shank ``z`` -l to 0 (the origin is the head's bearing face on the axis).
``clevis pin``
    ``d``, ``length`` l, ``head_diameter`` dk, ``head_height`` k (ISO 2341 B): as a screw, the
    head ``z`` 0 to k, the shank ``z`` -l to 0 (its split-pin hole left out).
``split pin``
    ``d`` (its legs together, max), ``c`` (its eye, max), ``length`` l (ISO 1234): the legs a
    cylinder ``z`` -l to 0, the eye a block c wide along ``x``, c high, d thick along ``y``
    (``y`` along the pin it goes through).
``hexagon nut``
    ``d``, ``s`` (across flats), ``m`` (height) (ISO 4032): a hexagonal prism ``z`` 0 to m, a
    corner on +x, bored to d.
``plain washer``, ``washer``
    ``d1`` (hole), ``d2`` (outside), ``h`` (ISO 7089; ISO 8738 for a clevis pin's): a ring
    ``z`` 0 to h.
``dowel pin``, ``pin``, ``parallel pin``
    ``diameter``, ``length`` (ISO 8734, ISO 2338): a cylinder ``z`` 0 to length.
``set screw``
    ``d``, ``length``, ``point`` (``"cone"``, the default, ISO 4027: a 90 degree cone point;
    ``"cup"`` or ``"flat"``, ISO 4029 / 4026: a plain cylinder, the cup's hollow left out):
    the point's end at z = 0.
``retaining ring``
    ``inner``, ``outer``, ``thickness`` (DIN 471/472): a thin ring ``z`` 0 to thickness.
``spring``, ``compression spring``
    ``outside``, ``wire``, ``length``: the coil's envelope, a tube one wire thick (EN 13906-1's
    outside diameter D + d, its length as installed).
``roller``
    ``outside``, ``width``, ``bore`` (0: solid): a ring or a disc ``z`` 0 to width.

An optional ``sides`` in a size overrides the solids' sides per circle: a dowel takes its
reamed hole's polygon, so the two coincide.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.solids.bought import register_maker
from cadgen.solids.outline import circle

__all__ = ["ring", "bearing", "parallel_key", "socket_head_cap_screw", "clevis_pin",
           "split_pin", "hexagon_nut", "plain_washer", "pin", "set_screw", "retaining_ring",
           "spring", "roller"]


def _sides(size: dict, segments: int) -> int:
    return int(size.get("sides", segments))


def _positive(size: dict, *names) -> list:
    values = []
    for name in names:
        value = float(size[name])
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"a bought item's {name} must be a finite length > 0 mm, "
                             f"not {size[name]!r} (size {size})")
        values.append(value)
    return values


def ring(inner: float, outer: float, height: float, sides: int, path: str = "bought item"):
    """A ring (``inner`` 0: a disc) of diameters ``inner`` to ``outer``, ``z`` 0 to ``height``."""
    from cadgen.solids.extrude import extrude

    if not outer > inner >= 0:
        raise ValueError(f"{path}: a ring needs outer > inner >= 0 mm, not {inner!r} / {outer!r}")
    holes = [circle(inner / 2, sides)] if inner > 0 else []
    return extrude(circle(outer / 2, sides), height, holes=holes, path=path)


def bearing(size: dict, segments: int):
    """A deep-groove ball bearing's rings as one body."""
    bore, outside, width = _positive(size, "bore", "outside", "width")
    return ring(bore, outside, width, _sides(size, segments), "bearing")


def parallel_key(size: dict, segments: int):
    """A parallel key as a box (its seat's shape)."""
    from cadgen.solids.extrude import manifold3d_engine

    width, height, length = _positive(size, "width", "height", "length")
    return manifold3d_engine().Manifold.cube((height, width, length)).translate(
        (0.0, -width / 2, 0.0))


def _headed(size: dict, segments: int, path: str):
    """A round head ``z`` 0 to k above the origin on a shank ``z`` -l to 0 (a screw, a clevis
    pin: both measure their length from under the head)."""
    from cadgen.solids.extrude import extrude, manifold3d_engine

    d, length, head, k = _positive(size, "d", "length", "head_diameter", "head_height")
    sides = _sides(size, segments)
    m3d = manifold3d_engine()
    parts = [extrude(circle(head / 2, sides), k, path=f"{path} head"),
             extrude(circle(d / 2, sides), length, z0=-length, path=f"{path} shank")]
    return m3d.Manifold.batch_boolean(parts, m3d.OpType.Add)


def socket_head_cap_screw(size: dict, segments: int):
    """A socket head cap screw: head above the origin, shank below."""
    return _headed(size, segments, "screw")


def clevis_pin(size: dict, segments: int):
    """An ISO 2341 B clevis pin: head above the origin, shank below (its split-pin hole and
    chamfers left out: the split pin's solid crosses the shank where the hole is)."""
    return _headed(size, segments, "clevis pin")


def split_pin(size: dict, segments: int):
    """An ISO 1234 split pin as its envelope, straight as it goes in (legs not yet bent): the
    two half-round legs together a cylinder ``d`` across, ``z`` -l to 0 below the eye's
    bearing face; the eye a block ``c`` wide along ``x``, ``c`` high, ``d`` thick along ``y``
    (the loop of a wire ``d`` wide lies in the legs' plane, ``x``-``z``)."""
    from cadgen.solids.extrude import extrude, manifold3d_engine

    d, eye, length = _positive(size, "d", "c", "length")
    m3d = manifold3d_engine()
    block = m3d.Manifold.cube((eye, d, eye)).translate((-eye / 2, -d / 2, 0.0))
    legs = extrude(circle(d / 2, _sides(size, segments)), length, z0=-length, path="split pin")
    return m3d.Manifold.batch_boolean([block, legs], m3d.OpType.Add)


def hexagon_nut(size: dict, segments: int):
    """A hexagon nut, bored to the thread's nominal diameter."""
    from cadgen.solids.extrude import extrude

    d, flats, height = _positive(size, "d", "s", "m")
    corners = flats / math.sqrt(3.0)   # the hexagon's circumradius
    angles = np.arange(6) * math.pi / 3
    hexagon = corners * np.column_stack([np.cos(angles), np.sin(angles)])
    return extrude(hexagon, height, holes=[circle(d / 2, _sides(size, segments))], path="nut")


def plain_washer(size: dict, segments: int):
    """A plain washer."""
    hole, outside, thickness = _positive(size, "d1", "d2", "h")
    return ring(hole, outside, thickness, _sides(size, segments), "washer")


def pin(size: dict, segments: int):
    """A cylindrical pin (a dowel, a hinge pin)."""
    diameter, length = _positive(size, "diameter", "length")
    return ring(0.0, diameter, length, _sides(size, segments), "pin")


def set_screw(size: dict, segments: int):
    """A set screw, its point's end at z = 0: a 90 degree cone (ISO 4027) or flat."""
    from cadgen.solids.extrude import manifold3d_engine

    d, length = _positive(size, "d", "length")
    point = size.get("point", "cone")
    if point in ("cup", "flat"):
        return ring(0.0, d, length, _sides(size, segments), "set screw")
    if point != "cone":
        raise ValueError(f"a set screw's point is 'cone', 'cup' or 'flat', not {point!r}")
    if length <= d / 2:
        raise ValueError(f"a set screw's length must exceed its point's height {d / 2:g} mm, "
                         f"not {length!r}")
    m3d = manifold3d_engine()
    sides = _sides(size, segments)
    point = m3d.Manifold.cylinder(d / 2, 0.0, d / 2, sides)
    body = m3d.Manifold.cylinder(length - d / 2, d / 2, d / 2, sides).translate((0.0, 0.0, d / 2))
    return m3d.Manifold.batch_boolean([point, body], m3d.OpType.Add)


def retaining_ring(size: dict, segments: int):
    """A retaining ring as a thin ring (its lugs and gap left out)."""
    inner, outer, thickness = _positive(size, "inner", "outer", "thickness")
    return ring(inner, outer, thickness, _sides(size, segments), "retaining ring")


def spring(size: dict, segments: int):
    """A helical spring as its coil's envelope: a tube one wire thick."""
    outside, wire, length = _positive(size, "outside", "wire", "length")
    return ring(outside - 2 * wire, outside, length, _sides(size, segments), "spring")


def roller(size: dict, segments: int):
    """A roller (a cam follower's): a ring on its pin, or a disc."""
    outside, width = _positive(size, "outside", "width")
    return ring(float(size.get("bore", 0.0)), outside, width, _sides(size, segments), "roller")


for _kind, _maker in (("bearing", bearing), ("key", parallel_key),
                      ("socket head cap screw", socket_head_cap_screw),
                      ("hexagon nut", hexagon_nut), ("plain washer", plain_washer),
                      ("dowel pin", pin), ("pin", pin), ("set screw", set_screw),
                      ("retaining ring", retaining_ring), ("spring", spring),
                      ("roller", roller), ("clevis pin", clevis_pin), ("split pin", split_pin),
                      ("washer", plain_washer), ("parallel pin", pin),
                      ("compression spring", spring)):
    register_maker(_kind, _maker)
