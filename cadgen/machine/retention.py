"""Axial location of every gear, bearing and hub along its shaft: spacers, retaining rings, set screws.

A key stops a gear turning on its shaft, not sliding along it; a bearing bored into a seat
is stopped by the seat's shoulder one way only. What holds each part along its shaft is
designed here, shaft by shaft, from the drivetrain's records (heights ``z`` from the shaft's
housing's cavity floor, as :class:`~cadgen.machine.model.Shaft` gives them):

* **Stops.** A bearing in a floor seat rests on the seat's shoulder (it cannot move down); in
  a roof seat the shoulder is above it (it cannot move up). A bearing carries axial load both
  ways through its balls, so its rings count as one part.
* **Spacers.** Between two parts on the shaft inside one cavity, a turned sleeve fills the gap
  (bore: the shaft plus :data:`SPACER_BORE_CLEARANCE`; outside: :func:`spacer_outside`, on
  the bearing's inner ring, clear of its outer ring), so the parts between two shoulders form
  one stack. A gap through a housing wall or between two housings breaks the stack.
* **Retaining rings (DIN 471).** The end of a stack that no shoulder stops gets a ring in a
  groove next to its last part; a stack stopped at both ends by its shoulders (the usual
  cross-located pair of bearings) gets one ring inside it, in its longest spacer, which ties
  the shaft to the stack both ways. That stack is given :data:`AXIAL_PLAY` between its
  shoulders (the spacer above the ring is that much shorter) so the bearings are not
  preloaded by the tolerances of the parts between them.
* **Set screws.** A keyed part at a shaft's very end has no shaft beyond it for a groove: a set
  screw (ISO 4029, cup point) through its hub onto the key holds it.
* **Hubs outside a housing** (the planter on E, the rocker on the planet shaft): a ring on
  each side; the shaft reaches :func:`ring_room` beyond the hub for the upper one
  (:func:`cadgen.machine.fixings.arm_fixings`).

Whether this holds everything both ways is not assumed: :mod:`cadgen.assembly.axial` checks
the whole machine's contacts (shafts, housings, flanges) and names any part free to slide.
"""

from __future__ import annotations

import re

import math
from dataclasses import dataclass, field

from cadgen.machine.catalogue import CatalogueError, shaft_ring
from kinematics.errors import Problem

__all__ = ["AXIAL_PLAY", "MIN_SPACER", "RING_CLEARANCE", "SPACER_BORE_CLEARANCE", "MAX_PLAY", "StackPart",
           "ShaftRetention", "set_screw_size", "ring_room", "drivetrain_retention", "spacer_outside", "set_screw", "shaft_retention",
           "retention_report"]

#: Axial play (mm) left in a stack held between two shoulders: the bearings are not preloaded
#: by the sum of its parts' length tolerances (a few tenths is usual for deep-groove pairs).
AXIAL_PLAY = 0.2
#: Shortest spacer (mm) a workshop turns; a shorter gap is left as play.
MIN_SPACER = 0.5
#: Running clearance (mm) between a ring turning with its shaft and a part that does not.
RING_CLEARANCE = 0.2
#: Diametral clearance (mm) of a spacer's bore on its shaft: it slides on by hand.
SPACER_BORE_CLEARANCE = 0.2
#: A spacer's wall reaches this fraction of the way from the bearing's bore to its outside:
#: onto the inner ring's face, short of the outer ring and the shield (DIN 5418 abutment).
SPACER_REACH = 0.25
#: Contact tolerance (mm): parts this close are touching.
TOUCH = 1e-6
#: The most play (mm) a stack is designed with: its play and a gap too short for a spacer.
#: Parts this far apart along a shaft bear on each other once the play is taken up.
MAX_PLAY = AXIAL_PLAY + MIN_SPACER


def ring_room(d: float) -> float:
    """Shaft length (mm) a DIN 471 ring needs beyond the part it holds: its groove and the
    shaft beyond the groove (``m + n``), rounded up to half a millimetre."""
    ring = shaft_ring(d)
    return math.ceil((ring["m"] + ring["n"]) * 2.0 - 1e-9) / 2.0


def spacer_outside(d: float, bearing) -> float:
    """Outside diameter (mm) of a spacer on a shaft of ``d`` next to ``bearing``'s inner ring."""
    return float(d) + SPACER_REACH * (bearing.outside - float(d))


def set_screw(key) -> str:
    """The ISO 4029 cup-point set screw through a hub onto its key (a size for the key's width:
    M4 up to 5 mm keys, M5 to 8 mm, M6 beyond)."""
    thread = "M4" if key is None or key.width <= 5 else "M5" if key.width <= 8 else "M6"
    length = {"M4": 6, "M5": 8, "M6": 10}[thread]
    return f"set screw ISO 4029 {thread} x {length} - 45H"


def set_screw_size(designation: str) -> tuple[str, float]:
    """``(thread, length mm)`` of a :func:`set_screw` designation (``... M5 x 8 - 45H``)."""
    found = re.search(r"ISO 4029 (M\d+) x (\d+(?:\.\d+)?)", designation)
    if found is None:
        raise ValueError(f"not an ISO 4029 set screw: {designation!r}")
    return found.group(1), float(found.group(2))


@dataclass(frozen=True)
class StackPart:
    """One part of a shaft's axial stack, ``z0 < z1`` from the shaft's housing's cavity floor.

    ``kind``: ``"bearing"`` (``ref``: the seat's index in ``shaft.seats``), ``"gear"`` (``ref``:
    the gear's name), ``"hub"`` (``ref``: the part keyed on: ``"planter"``, ``"rocker"``),
    ``"spacer"`` or ``"ring"`` (``ref``: its number on the shaft, from 1). ``stop``: the way a
    housing shoulder stops it (``"down"``, ``"up"``, ``""``), ``housing`` that housing;
    ``locked``: held to the shaft both ways (a ring; a hub's set screw).
    """

    kind: str
    ref: object
    z0: float
    z1: float
    stop: str = ""
    housing: str = ""
    locked: bool = False
    bore: float = 0.0
    outside: float = 0.0
    designation: str = ""


@dataclass(frozen=True)
class ShaftRetention:
    """A shaft's axial stack (bottom up) and what it adds: spacers, rings, set screws."""

    shaft: str
    side: int
    parts: tuple            # StackPart, sorted by z0
    set_screws: tuple = ()  # (gear or hub name, designation)
    problems: tuple = field(default=(), compare=False)

    @property
    def spacers(self) -> tuple:
        return tuple(p for p in self.parts if p.kind == "spacer")

    @property
    def rings(self) -> tuple:
        return tuple(p for p in self.parts if p.kind == "ring")

    def touching(self) -> list:
        """``(lower, upper)`` pairs of parts in contact (within the designed play)."""
        ordered = sorted(self.parts, key=lambda p: p.z0)
        return [(a, b) for i, a in enumerate(ordered) for b in ordered[i + 1:]
                if -TOUCH <= b.z0 - a.z1 <= MAX_PLAY + TOUCH]


def _frame(shaft, stacks, bases):
    """``{housing: (cavity floor, cavity top)}`` in the shaft's frame, and its ends."""
    own = bases.get(shaft.housing, 0.0)
    cavities = {name: (bases.get(name, 0.0) - own, bases.get(name, 0.0) - own + s.cavity_height)
                for name, s in stacks.items()}
    if shaft.ends is not None:
        return cavities, tuple(shaft.ends)
    stack = stacks[shaft.housing]
    bottom, top = -stack.floor_wall, stack.cavity_height + stack.roof_wall
    for seat in shaft.seats:
        if seat.housing != shaft.housing:
            continue
        if seat.wall == "floor":
            bottom = -stack.floor_wall - shaft.extends_below if seat.through else -seat.depth
        else:
            top = (stack.cavity_height + stack.roof_wall + shaft.extends_above if seat.through
                   else stack.cavity_height + seat.depth)
    return cavities, (bottom, top)


def _own_parts(shaft, cavities, ends, hub):
    parts = []
    for k, seat in enumerate(shaft.seats):
        low, high = cavities[seat.housing]
        z0, z1, stop = ((low - seat.depth, low, "down") if seat.wall == "floor"
                        else (high, high + seat.depth, "up"))
        parts.append(StackPart("bearing", k, z0, z1, stop, seat.housing,
                               designation=seat.bearing.designation))
    for mount in shaft.mounts:
        parts.append(StackPart("gear", mount.gear, mount.z_bottom,
                               mount.z_bottom + mount.face_width))
    if hub:   # outside the housing, at the top: the shaft reaches ring_room beyond it
        top = ends[1] - hub["beyond"]
        parts.append(StackPart("hub", hub["part"], top - hub["length"], top))
    return sorted(parts, key=lambda p: p.z0)


def _inside_one_cavity(low: float, high: float, cavities) -> bool:
    return any(a - TOUCH <= low and high <= b + TOUCH for a, b in cavities.values())


def _groups(parts, cavities):
    """Runs of parts joined by contact or by a gap inside one cavity (a spacer's)."""
    groups = [[parts[0]]]
    for lower, upper in zip(parts, parts[1:]):
        if _inside_one_cavity(lower.z1, upper.z0, cavities):
            groups[-1].append(upper)
        else:
            groups.append([upper])
    return groups


def shaft_retention(shaft, stacks, bases, hub=None, axial_gap: float = 0.0) -> ShaftRetention:
    """The axial stack of one shaft record, with its spacers, rings and set screws.

    ``hub``: the fixing of the part keyed on the shaft outside its housing
    (:func:`cadgen.machine.fixings.keyed_hub` with ``beyond``, the shaft past it), or None;
    ``axial_gap``: the gap below that hub (``housing.axial_gap``), where its lower ring goes.
    """
    cavities, ends = _frame(shaft, stacks, bases)
    parts = _own_parts(shaft, cavities, ends, hub)
    try:
        ring = shaft_ring(shaft.diameter)
    except CatalogueError as error:   # a diameter given off the table: said, nothing added
        return ShaftRetention(shaft.name, shaft.side, tuple(parts), (), (Problem(
            f"machine.shafts.{shaft.name}.diameter", "no_retaining_ring",
            f"shaft {shaft.name}: {error}; its parts are not held along it"),))
    room = ring["m"] + ring["n"]
    bearing = shaft.seats[0].bearing
    bore = shaft.diameter + SPACER_BORE_CLEARANCE
    added, screws, problems, rings = [], [], [], []

    def hold_end(part, below: bool, free: float):
        """A ring beside ``part`` (below or above it), or a set screw when the shaft ends."""
        beyond = part.z0 - ends[0] if below else ends[1] - part.z1
        if beyond >= room - TOUCH and free >= ring["s"] + RING_CLEARANCE - TOUCH:
            rings.append(part.z0 - ring["s"] if below else part.z1)
        elif part.kind in ("gear", "hub") and beyond < room - TOUCH:
            key = next((m.key for m in shaft.mounts if m.gear == part.ref), None)
            if part.kind == "hub":
                key = hub.get("key")
            screws.append((part.ref, set_screw(key)))
        else:
            problems.append(Problem(
                "housing.axial_gap", "no_room_for_retaining_ring",
                f"shaft {shaft.name}: the {part.ref if part.kind != 'bearing' else 'bearing'} "
                f"has {free:.2f} mm beside it, less than its {ring['designation']} needs "
                f"({ring['s'] + RING_CLEARANCE:g} mm)"))

    ordered = parts   # sorted by z0 (_own_parts)
    for group in _groups(ordered, cavities):
        first, last = group[0], group[-1]
        index = ordered.index(first)
        gaps = list(zip(group, group[1:]))
        for lower, upper in gaps:
            if upper.z0 - lower.z1 >= MIN_SPACER - TOUCH:
                added.append([lower.z1, upper.z0])
        after = ordered.index(last) + 1
        below_free = first.z0 - max([ordered[index - 1].z1 if index > 0 else ends[0]]
                                    + [a for a, b in cavities.values()
                                       if a - TOUCH <= first.z0 <= b + TOUCH])
        above_free = min([ordered[after].z0 if after < len(ordered) else ends[1]]
                         + [b for a, b in cavities.values()
                            if a - TOUCH <= last.z1 <= b + TOUCH]) - last.z1
        if first.kind == "hub":   # above the housing: the gap below it to what does not turn
            below_free = axial_gap
        if first.stop != "down":
            hold_end(first, True, below_free)
        if last.stop != "up":
            hold_end(last, False, above_free)
        if first.stop == "down" and last.stop == "up":
            # cross-located: one ring inside, in the longest gap, ties the shaft both ways
            # (of equal ones the middle: between two gears rather than on a bearing's face,
            # so the spacers beside it keep their length)
            middle = (len(gaps) - 1) / 2
            longest = max(gaps, key=lambda g: (round(g[1].z0 - g[0].z1, 6),
                                               -abs(gaps.index(g) - middle)), default=None)
            if longest is None or longest[1].z0 - longest[0].z1 < ring["s"] + AXIAL_PLAY - TOUCH:
                problems.append(Problem(
                    "housing.axial_gap", "no_room_for_retaining_ring",
                    f"shaft {shaft.name}: no gap between its parts takes a "
                    f"{ring['designation']} and {AXIAL_PLAY:g} mm of play"))
                continue
            low, high = longest[0].z1, longest[1].z0
            rings.append(low)
            for gap in added:
                if abs(gap[0] - low) < TOUCH and abs(gap[1] - high) < TOUCH:
                    gap[0], gap[1] = low + ring["s"], high - AXIAL_PLAY
    spacers = [StackPart("spacer", k + 1, z0, z1, bore=bore,
                         outside=spacer_outside(shaft.diameter, bearing))
               for k, (z0, z1) in enumerate(sorted(g for g in added
                                                   if g[1] - g[0] >= MIN_SPACER - TOUCH))]
    ring_parts = [StackPart("ring", k + 1, z0, z0 + ring["s"], locked=True, bore=ring["d2"],
                            outside=ring["d4"], designation=ring["designation"])
                  for k, z0 in enumerate(sorted(rings))]
    screwed = {name for name, _ in screws}
    held = [p if p.ref not in screwed or p.kind not in ("gear", "hub")
            else StackPart(p.kind, p.ref, p.z0, p.z1, p.stop, p.housing, True)
            for p in parts]
    everything = sorted(held + spacers + ring_parts, key=lambda p: (p.z0, p.z1))
    return ShaftRetention(shaft.name, shaft.side, tuple(everything), tuple(screws),
                          tuple(problems))


#: The part keyed on each shaft outside its housing (its fixing's name in the drivetrain).
OUTSIDE_HUBS = {"E": "planter", "planet": "rocker"}


def drivetrain_retention(shafts, stacks, bases, fixings, axial_gap: float) -> tuple:
    """``(retention, problems)``: every shaft's :func:`shaft_retention` (the hubs outside the
    housings from ``fixings``), and the problems of side 1's (side 2 repeats them)."""
    retention = tuple(shaft_retention(s, stacks, bases, fixings.get(OUTSIDE_HUBS.get(s.name)),
                                      axial_gap) for s in shafts)
    return retention, [p for r in retention if r.side == 1 for p in r.problems]


def retention_report(retentions) -> list:
    """report.json's ``machine.retention``: each shaft's stack, bottom up (mm)."""
    out = []
    for r in retentions:
        out.append({
            "shaft": r.shaft, "side": r.side,
            "stack": [{"kind": p.kind, "part": str(p.ref), "z": [round(p.z0, 4), round(p.z1, 4)],
                       **({"stop": p.stop, "housing": p.housing} if p.stop else {}),
                       **({"designation": p.designation} if p.designation else {}),
                       **({"bore": p.bore, "outside": round(p.outside, 3)}
                          if p.kind == "spacer" else {})}
                      for p in r.parts],
            "set_screws": [{"part": name, "designation": d} for name, d in r.set_screws],
            "problems": [{"path": p.path, "code": p.code, "message": p.message}
                         for p in r.problems]})
    return out
