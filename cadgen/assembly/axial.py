"""Which parts are held along their axes, both ways: a check over the whole machine's contacts.

A planar joint graph cannot see a gear sliding off its shaft: a key or a bearing is a joint in
the plane whatever holds it along the axis. This check reads the axial contacts the assembly
model records (:class:`AxialGraph`) and finds, for each way along the axes, the parts that no
chain of contacts ties to the frame:

* ``rests(upper, lower)``: ``upper`` bears on ``lower`` from above. It cannot move down unless
  ``lower`` does, and ``lower`` cannot move up unless ``upper`` does. A bearing in a floor seat
  rests on its housing; a housing rests on a bearing in its roof seat (the shoulder is above
  the bearing); two parts of a shaft's stack in contact (within the designed play) rest on
  each other;
* ``fixed(a, b)``: held both ways (a retaining ring in its groove, a set screw, a bolted flange,
  a housing's base and cover).

A part is held downwards when a chain of ``rests`` (and ``fixed``) leads from it down to the
frame, upwards likewise; a part missing either is free to slide that way, and is named. The
chains run through shafts and housings alike: a hollow shaft whose flange carries gearbox 2 is
held down by gearbox 2 resting on the bearing of the inner shaft in its roof.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["AxialGraph", "axial_check"]


@dataclass
class AxialGraph:
    """The axial contacts of an assembly: ``rests`` ``(upper, lower)`` and ``fixed`` pairs,
    and the parts they are about (``parts``, each with a reader's description)."""

    rests: list = field(default_factory=list)
    fixed: list = field(default_factory=list)
    parts: dict = field(default_factory=dict)   # name -> what it is, for the report

    def part(self, name: str, what: str = "") -> str:
        self.parts.setdefault(name, what or name)
        return name

    def rest(self, upper: str, lower: str) -> None:
        self.rests.append((upper, lower))

    def fix(self, a: str, b: str) -> None:
        self.fixed.append((a, b))

    def held(self, frame: str, way: str) -> set:
        """The parts a chain of contacts holds ``way`` (``"down"`` or ``"up"``) to ``frame``."""
        # down: an upper part is held when what it rests on is; up: a lower part is held when
        # what rests on it is
        step = {}
        for upper, lower in self.rests:
            source, target = (lower, upper) if way == "down" else (upper, lower)
            step.setdefault(source, []).append(target)
        for a, b in self.fixed:
            step.setdefault(a, []).append(b)
            step.setdefault(b, []).append(a)
        held, todo = {frame}, [frame]
        while todo:
            for nxt in step.get(todo.pop(), ()):
                if nxt not in held:
                    held.add(nxt)
                    todo.append(nxt)
        return held


def axial_check(graph: AxialGraph, frame: str) -> dict:
    """report.json's ``assembly.axial``: the parts checked and those free to slide.

    ``{"parts": n, "contacts": n, "free": [{"part", "what", "ways"}], "passed"}``; ``ways``
    lists ``"down"`` and/or ``"up"`` (along the axes, towards the arms is up).
    """
    names = set(graph.parts)
    for pair in graph.rests + graph.fixed:
        names.update(pair)
    names.discard(frame)
    down, up = graph.held(frame, "down"), graph.held(frame, "up")
    free = [{"part": name, "what": graph.parts.get(name, name),
             "ways": [way for way, held in (("down", down), ("up", up)) if name not in held]}
            for name in sorted(names) if name not in down or name not in up]
    return {"parts": len(names), "contacts": len(graph.rests), "fixed": len(graph.fixed),
            "free": free, "passed": not free}


def free_message(entry: dict) -> str:
    """One free part in words."""
    return (f"{entry['what']} is free to slide {' and '.join(entry['ways'])} along its axis: "
            "nothing holds it that way")
