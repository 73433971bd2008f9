"""The joint graph of an assembly: which parts move as one, how free the machine is, what hangs loose.

A machine is parts and the joints between them. The CAD pipeline has to answer, before any
solid is cut, three questions a drawing review asks: which parts form one rigid body (a gear
keyed to its shaft turns with it), does the machine have exactly the freedom its drive
gives it (planar Kutzbach–Grübler with higher pairs), and is every part held by something
(a part no chain of joints ties to the frame falls out of the assembly).

Counting rule (the reason for each choice is in :meth:`AssemblyModel.mobility`):

* ``fixed`` joints merge parts into one rigid body and are not counted;
* joints of one kind between the same two bodies are one kinematic pair: a shaft on two
  coaxial bearings turns about one axis, the planar model has one revolute pair there;
* a moving joint between two parts of one rigid body is a contradiction (the body cannot
  turn inside itself): it is counted, so the count shows the lock, and it is listed by
  :meth:`AssemblyModel.redundant_joints`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterable, Union

#: Two parts joined this way move as one (key, bolts, press fit, weld).
FIXED = "fixed"
#: Lower pairs: each leaves one planar freedom between its parts, so removes two.
LOWER_PAIRS = ("revolute", "prismatic")
#: Higher pairs (point or line contact): each removes one planar freedom. A pin in a slot
#: (``slot``) turns and slides: two freedoms left, one removed, as a cam contact.
HIGHER_PAIRS = ("gear", "cam", "slot")
JOINT_KINDS = (FIXED,) + LOWER_PAIRS + HIGHER_PAIRS
MOBILITY_FORMULA = "M = 3 (N - 1) - 2 J1 - J2"


@dataclass(frozen=True)
class Item:
    """A bought item a joint is made with, ``count`` of them per joint: a bearing, a key, a screw.

    ``kind`` is what the bill calls it (``"bearing"``, ``"key"``, ``"socket head cap screw"``,
    ...), ``description`` the full line a buyer orders from, ``designation`` the standard's
    short name.
    """

    kind: str
    description: str
    designation: str
    count: int = 1

    def __post_init__(self):
        if not isinstance(self.count, int) or isinstance(self.count, bool) or self.count < 1:
            raise ValueError(f"{self.description}: a joint needs a whole positive number of "
                             f"each item, not {self.count!r}")

    def as_dict(self) -> dict:
        return {"kind": self.kind, "description": self.description,
                "designation": self.designation, "count": self.count}


@dataclass(frozen=True)
class Placement:
    """One placed copy of a made part: ``instance`` (a part of the graph) is the file ``part``
    riding on the kinematic ``body`` at carrier angle plus ``phase`` (rad); ``kind`` is the
    part's (``"gear"``, ``"shaft"``, ``"housing"``, ... as the solids say; empty if unknown)."""

    instance: str
    part: str
    body: str
    phase: float = 0.0
    kind: str = ""

    def as_tuple(self) -> tuple:
        """``(instance, body, phase)``, as a solid part lists its instances."""
        return (self.instance, self.body, self.phase)


@dataclass(frozen=True)
class Joint:
    """One joint between parts ``a`` and ``b``; ``detail`` says what makes it (for the reader),
    ``items`` what is bought to make it (not part of its identity: equal joints differ only in
    what they are, not in the screws counted for them)."""

    kind: str
    a: str
    b: str
    detail: str = ""
    items: tuple = field(default=(), compare=False)

    def __post_init__(self):
        if self.kind not in JOINT_KINDS:
            raise ValueError(f"joint kind {self.kind!r} is not one of {', '.join(JOINT_KINDS)}")
        for name in (self.a, self.b):
            if not isinstance(name, str) or not name:
                raise ValueError(f"{self}: a part name is a non-empty string, not {name!r}")
        if self.a == self.b:
            raise ValueError(f"{self}: a joint ties two different parts, not a part to itself")
        object.__setattr__(self, "items", tuple(self.items))
        for item in self.items:
            if not isinstance(item, Item):
                raise TypeError(f"{self}: an item is an Item, not {item!r}")

    def __str__(self):
        detail = f" ({self.detail})" if self.detail else ""
        return f"{self.kind} joint {self.a}–{self.b}{detail}"

    def as_dict(self) -> dict:
        out = {"kind": self.kind, "a": self.a, "b": self.b, "detail": self.detail}
        if self.items:
            out["items"] = [item.as_dict() for item in self.items]
        return out


def connected_groups(parts: Iterable[str], links: Iterable[tuple[str, str]]) -> list[list[str]]:
    """The parts grouped by the links between them (union-find), in the order the parts come.

    Each group lists its parts in input order and the groups come in the order of their
    first part, so the answer does not depend on the order of the links.
    """
    ordered = list(parts)
    leader = {part: part for part in ordered}

    def root(part: str) -> str:
        while leader[part] != part:
            leader[part] = leader[leader[part]]   # path halving: short trees, no recursion
            part = leader[part]
        return part

    for a, b in links:
        ra, rb = root(a), root(b)
        if ra != rb:
            leader[rb] = ra
    groups: dict[str, list[str]] = {}
    for part in ordered:
        groups.setdefault(root(part), []).append(part)
    return list(groups.values())


JointSelector = Union[Joint, Callable[[Joint], bool]]


@dataclass(frozen=True)
class AssemblyModel:
    """Parts, the joints between them, which part is the frame (the ground), and where each
    made part's copies are placed (``placements``: the solids, the assembly file, the bill's
    quantities and the sweeps read them from here). ``made``: the parts the machine's files
    make or its bill buys as solids (a part outside it, such as the user's own coupling, is
    in the graph for what holds it)."""

    parts: tuple[str, ...]
    joints: tuple[Joint, ...] = ()
    frame: str = "frame"
    placements: tuple[Placement, ...] = ()
    made: tuple[str, ...] = ()
    axial: object = field(default=None, compare=False, repr=False)   # assembly.axial.AxialGraph
    _body_index: dict = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self):
        object.__setattr__(self, "parts", tuple(self.parts))
        object.__setattr__(self, "joints", tuple(self.joints))
        object.__setattr__(self, "placements", tuple(self.placements))
        object.__setattr__(self, "made", tuple(self.made))
        self._check_parts()
        self._check_joints()
        self._check_placements()
        object.__setattr__(self, "_body_index", self._index_bodies())

    def _check_parts(self):
        seen = set()
        for part in self.parts:
            if not isinstance(part, str) or not part:
                raise ValueError(f"a part name is a non-empty string, not {part!r}")
            if part in seen:
                raise ValueError(f"part {part!r} is listed twice")
            seen.add(part)
        if self.frame not in seen:
            raise ValueError(f"the frame {self.frame!r} is not one of the parts")

    def _check_joints(self):
        known = set(self.parts)
        for joint in self.joints:
            if not isinstance(joint, Joint):
                raise TypeError(f"a joint is a Joint, not {joint!r}")
            for name in (joint.a, joint.b):
                if name not in known:
                    raise ValueError(f"{joint} names the unknown part {name!r}")

    def _check_placements(self):
        known, seen = set(self.parts), set()
        for placement in self.placements:
            if not isinstance(placement, Placement):
                raise TypeError(f"a placement is a Placement, not {placement!r}")
            if placement.instance not in known:
                raise ValueError(f"{placement} places {placement.instance!r}, which is not a part")
            if placement.instance in seen:
                raise ValueError(f"{placement.instance!r} is placed twice")
            seen.add(placement.instance)
        unknown = [part for part in self.made if part not in known]
        if unknown:
            raise ValueError(f"the made parts {unknown} are not parts")

    def _index_bodies(self) -> dict[str, frozenset[str]]:
        fixed = [(j.a, j.b) for j in self.joints if j.kind == FIXED]
        index = {}
        for group in connected_groups(self.parts, fixed):
            body = frozenset(group)
            index.update((part, body) for part in group)
        return index

    # --- rigid bodies -------------------------------------------------------------------

    def bodies(self) -> tuple[frozenset[str], ...]:
        """The rigid bodies (parts merged along fixed joints), ordered by their first part."""
        return tuple(dict.fromkeys(self._body_index[part] for part in self.parts))

    def body_of(self, part: str) -> frozenset[str]:
        """The rigid body ``part`` belongs to: everything that moves with it."""
        if part not in self._body_index:
            raise ValueError(f"{part!r} is not one of the parts")
        return self._body_index[part]

    def joints_of(self, part: str) -> tuple[Joint, ...]:
        """The joints that touch ``part``, in model order."""
        if part not in self._body_index:
            raise ValueError(f"{part!r} is not one of the parts")
        return tuple(j for j in self.joints if part in (j.a, j.b))

    def redundant_joints(self) -> tuple[Joint, ...]:
        """Moving joints (not ``fixed``) whose two parts are already one rigid body.

        A bearing between a shaft and the gear keyed to it cannot turn: the model says two
        contradictory things about those parts, which a reviewer has to resolve.
        """
        return tuple(j for j in self.joints
                     if j.kind != FIXED and self.body_of(j.a) == self.body_of(j.b))

    # --- mobility -----------------------------------------------------------------------

    def _kinematic_pairs(self, kinds: tuple[str, ...]) -> set:
        """The distinct (kind, body, body) pairs among the joints of ``kinds``.

        Joints of one kind between the same two bodies collapse into one pair: the two
        bearings of a shaft are one planar revolute, two guide rails one prismatic.
        """
        return {(j.kind, frozenset((self.body_of(j.a), self.body_of(j.b))))
                for j in self.joints if j.kind in kinds}

    def mobility_report(self) -> dict:
        """The planar Kutzbach–Grübler count with higher pairs, term by term."""
        bodies = len(self.bodies())
        lower = len(self._kinematic_pairs(LOWER_PAIRS))
        higher = len(self._kinematic_pairs(HIGHER_PAIRS))
        return {"formula": MOBILITY_FORMULA, "bodies": bodies, "lower_pairs": lower,
                "higher_pairs": higher, "mobility": 3 * (bodies - 1) - 2 * lower - higher}

    def mobility(self) -> int:
        """The planar degrees of freedom, ``M = 3 (N - 1) - 2 J1 - J2``.

        N counts rigid bodies (the frame's included), J1 the revolute and prismatic pairs,
        J2 the gear and cam contacts. A joint inside one body still counts: it adds a
        constraint nothing can satisfy, and the lower count is the honest sign of that.
        Grübler counts constraints, so special geometry (parallel links) can fool it.
        """
        return self.mobility_report()["mobility"]

    # --- connection to the frame --------------------------------------------------------

    def unconnected(self) -> list[str]:
        """The parts no chain of holding joints ties to the frame, in ``parts`` order.

        Holding joints are the fixed ones and the lower pairs (a bearing, a slide): they keep
        a part in place. A gear mesh or a cam contact only pushes: a gear whose key is missing
        still meshes, but nothing holds it on its axis, so it counts as loose."""
        links = [(j.a, j.b) for j in self.joints if j.kind == FIXED or j.kind in LOWER_PAIRS]
        held = next(set(group) for group in connected_groups(self.parts, links)
                    if self.frame in group)
        return [part for part in self.parts if part not in held]

    # --- placements and bought items ---------------------------------------------------

    def instances_of(self, part: str) -> tuple[tuple, ...]:
        """``(instance, body, phase)`` of every placed copy of the made ``part`` (a file stem)."""
        return tuple(p.as_tuple() for p in self.placements if p.part == part)

    def placed_parts(self) -> tuple[str, ...]:
        """The made parts (file stems) the model places, in placement order."""
        return tuple(dict.fromkeys(p.part for p in self.placements))

    def bought(self, present: Iterable[str] | None = None) -> list[tuple[Item, int]]:
        """Every bought item the joints need, summed: ``[(item, total)]`` in first-seen order.

        ``present``: the instances that were made (a build that cut no gears has no keys to
        buy for them). A joint counts when each of its parts is present or is not one of the
        machine's own parts (``made``: the user's coupling is not); None counts every joint.
        """
        own = set(self.made)
        made = None if present is None else set(present)
        totals: dict[tuple, list] = {}
        for joint in self.joints:
            if made is not None and any(p in own and p not in made for p in (joint.a, joint.b)):
                continue
            for item in joint.items:
                key = (item.kind, item.description, item.designation)
                totals.setdefault(key, [item, 0])[1] += item.count
        return [(item, total) for item, total in totals.values()]

    # --- editing ------------------------------------------------------------------------

    def without(self, joint_or_predicate: JointSelector) -> AssemblyModel:
        """A copy without the given joint (every equal copy of it) or the joints a test picks.

        A Joint the model does not have is a ValueError: a removal that removes nothing
        is usually a misspelt part name, and a silent no-op would hide it.
        """
        if isinstance(joint_or_predicate, Joint):
            if joint_or_predicate not in self.joints:
                raise ValueError(f"the model has no {joint_or_predicate}")
            drop = joint_or_predicate.__eq__
        elif callable(joint_or_predicate):
            drop = joint_or_predicate
        else:
            raise TypeError(f"without() takes a Joint or a Joint -> bool, not {joint_or_predicate!r}")
        kept = tuple(j for j in self.joints if not drop(j))
        return AssemblyModel(self.parts, kept, self.frame, self.placements, self.made)

    def with_joints(self, *joints: Joint) -> AssemblyModel:
        """A copy with ``joints`` added at the end (their parts must already be parts)."""
        return AssemblyModel(self.parts, self.joints + joints, self.frame, self.placements,
                             self.made)

    # --- reports ------------------------------------------------------------------------

    def as_report(self) -> dict:
        """Everything above as plain lists, dicts, strings and ints (ready for json.dumps)."""
        rule = self.mobility_report()
        return {
            "parts": list(self.parts),
            "joints": [j.as_dict() for j in self.joints],
            "frame": self.frame,
            "mobility": rule["mobility"],
            "mobility_rule": rule,
            "unconnected": self.unconnected(),
            "bodies": [[p for p in self.parts if p in body] for body in self.bodies()],
            "placements": [{"instance": p.instance, "part": p.part, "body": p.body,
                            "phase_deg": round(math.degrees(p.phase), 9), "kind": p.kind}
                           for p in self.placements],
        }

    def degrees_of_freedom_check(self, expected: int = 1) -> list[str]:
        """The problems, in words; empty when the mobility is ``expected`` and every part is held."""
        problems = []
        loose = self.unconnected()
        if loose:
            problems.append(_loose_parts_message(loose))
        mobility = self.mobility()
        if mobility != expected:
            problems.append(f"mobility {mobility}, expected {expected}: "
                            + self._mobility_hint(mobility, expected, bool(loose)))
        return problems

    def _mobility_hint(self, mobility: int, expected: int, loose: bool) -> str:
        """Why the count may be off, pointing at the likeliest causes first."""
        redundant = self.redundant_joints()
        if redundant:
            listed = "; ".join(str(j) for j in redundant)
            return f"joints inside one rigid body lock it ({listed})"
        if mobility > expected:
            extra = mobility - expected
            cause = "the loose parts count as free bodies" if loose else (
                "a part can move while the drive stands still")
            return f"{extra} freedom{'s' if extra > 1 else ''} too many: {cause}"
        short = expected - mobility
        return (f"{short} freedom{'s' if short > 1 else ''} short: the joints over-constrain "
                "the parts (a structure, or a drive that jams)")


def _loose_parts_message(loose: list[str]) -> str:
    if len(loose) == 1:
        return f"the part {loose[0]} is tied to the frame by no chain of joints"
    return f"the parts {', '.join(loose)} are tied to the frame by no chain of joints"
