"""The exploded view: where each placed part goes when the machine is taken apart for a fitter.

The 3D views (the report's and the studio's) have an *explode* slider: 0 is the machine as
assembled, 1 fully exploded, each part moved by ``t`` times its offset from here (stored per
node in ``assembly.glb``, :func:`cadgen.export.meshes.assembly_bytes`). The offsets are read
from the assembly model's order (:func:`cadgen.assembly.sequence.assembly_sequence`), so the
picture is the fitter's: every part comes off along the way it goes on.

* The machine stands on the part the order starts from (the frame, or the first housing's
  base when the frame is mounted last, as the pricking machine's bracket): it does not move.
* The steps are taken in order. A step's part leaves the part it goes onto along the shaft
  axes (z, normal to the mechanism plane): a shaft out of its housing's base towards the
  base's open side (its cover's side); a cover off its base; a housing away from the flange
  it is bolted to; what rides outside (cam, planter, blades, rocker, needle, sprocket) away
  from what carries it, up or down as it lies from it. It goes at least :data:`GAP_FRACTION`
  of the machine's size, and on until it clears, by that gap, every part placed before it
  that it overlaps seen along z, so what goes on later lies further out: a base, its shafts
  above it, its cover above them, the next housing above that.
* A gear keyed to, or running on its bearings on, its shaft stays on it (the shaft and its
  gears are one sub-assembly, put in together), the gears on one shaft spread along it, a gap
  each, away from its middle.
* An arm of the carrier (a housing base named ``...-arm<n>`` hung on a shaft of another
  housing, and everything put onto it) also moves out in the mechanism plane, away from the
  housing that carries it, until clear of it seen along z: the two arms apart radially.
* A housing's printed segments (spliced) stay together.

Each offset is the offset of the part it goes onto plus its own, so a sub-assembly moves as
one. Offsets are mm in the assembly's frame at the carrier angle the GLB is written at. The
views only interpolate; the same offsets serve any pose the views might animate (they add to
the node's placement). A part the order does not reach (the soil) keeps its place.
"""

from __future__ import annotations

import re

import numpy as np

__all__ = ["explode_offsets", "GAP_FRACTION"]

#: The gap between exploded parts, as a fraction of the assembled machine's largest extent
#: (the soil left out): 4 %, about 30 mm on the paper design's 800 mm.
GAP_FRACTION = 0.04
#: An arm's root: a housing's base on an arm of the carrier.
_ARM = re.compile(r"-base(-\d+)?-arm\d+$")
_BASE = re.compile(r"-base(-\d+)?(-(arm|side)\d)?$")
_UP = np.array([0.0, 0.0, 1.0])
#: Gears whose middles are this close along z (mm) are in one layer.
_LEVEL_TOLERANCE = 0.5
_PAD = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])
#: The kinds a shaft carries with it: put in together, spread along it.
RIDING = ({"gear", "shaft"}, {"spacer", "shaft"})


def _boxes(assembly, phi: float) -> tuple[dict, dict]:
    """``({instance: (2, 3) box}, {instance: kind})`` of the placed parts at carrier angle phi."""
    boxes, kinds = {}, {}
    for name, part, pose in assembly.placements(phi):
        vertices = np.asarray(part.mesh.vertices, dtype=float) @ pose[:3, :3].T + pose[:3, 3]
        boxes[name] = np.array([vertices.min(axis=0), vertices.max(axis=0)])
        kinds[name] = part.kind
    return boxes, kinds


def _overlap_in_plan(a, b) -> bool:
    """Whether two boxes overlap seen along z (with some area)."""
    return bool(np.all(np.minimum(a[1, :2], b[1, :2]) - np.maximum(a[0, :2], b[0, :2]) > 1e-9))


def _clearing_lift(moving, placed, sign: float, start: float) -> float:
    """The least lift ``s >= start`` (mm, along ``sign`` z) that takes every box of ``moving``
    beyond, by the boxes' own gap, each box of ``placed`` it overlaps seen along z: what goes on
    later comes off further out, so the order along the axis is the assembly's.

    ``moving``, ``placed``: lists of (2, 3) boxes (the gap already added to ``placed``'s)."""
    lift = float(start)
    for m in moving:
        for p in placed:
            if _overlap_in_plan(m, p):
                need = p[1, 2] - m[0, 2] if sign > 0 else m[1, 2] - p[0, 2]
                lift = max(lift, float(need))
    return lift


def _radial_clearance(moving, carriers, direction, gap: float) -> float:
    """The least move (mm) along the in-plane unit ``direction`` that takes the box ``moving``
    clear of every box of ``carriers`` seen along z, by ``gap``."""
    need = 0.0
    for box in carriers:
        if not _overlap_in_plan(moving, box):
            continue
        ways = []   # clear along x or along y: either will do
        for axis in (0, 1):
            if direction[axis] > 1e-9:
                ways.append((box[1, axis] - moving[0, axis] + gap) / direction[axis])
            elif direction[axis] < -1e-9:
                ways.append((moving[1, axis] - box[0, axis] + gap) / -direction[axis])
        if ways:
            need = max(need, min(ways))
    return need


def _layers(gears, boxes: dict, gap: float) -> dict:
    """Each gear's offset along z: its layer (gears level with each other, as meshing gears
    are) a gap from the next, spread about the layers' middle, so meshing gears stay level."""
    centre = {g: float(boxes[g][:, 2].mean()) for g in gears}
    levels = []
    for gear in sorted(gears, key=centre.get):
        if not levels or centre[gear] - levels[-1][0] > _LEVEL_TOLERANCE:
            levels.append((centre[gear], []))
        levels[-1][1].append(gear)
    middle = (len(levels) - 1) / 2
    return {gear: (index - middle) * gap * _UP for index, (_, level) in enumerate(levels)
            for gear in level}


def _cover_of(base: str, boxes: dict) -> str | None:
    cover = re.sub(r"-base(?=(-\d+)?(-(arm|side)\d)?$)", "-cover", base)
    return cover if cover in boxes else None


def _sign(new: str, anchor: str, boxes: dict, kinds: dict) -> float:
    """Which way along z ``new`` leaves ``anchor``: a shaft out of a base towards the base's
    cover; anything else away from the anchor's middle (up when level)."""
    if kinds.get(new) == "shaft" and _BASE.search(anchor) and _cover_of(anchor, boxes):
        below, above = boxes[anchor][:, 2].mean(), boxes[_cover_of(anchor, boxes)][:, 2].mean()
        return 1.0 if above >= below else -1.0
    return 1.0 if boxes[new][:, 2].mean() >= boxes[anchor][:, 2].mean() - 1e-9 else -1.0


def explode_offsets(assembly, phi: float, *, gap: float | None = None) -> dict:
    """Each placed part's exploded offset (mm, (3,) in the assembly's frame at carrier angle
    ``phi``), by the scheme of the module notes.

    Parameters
    ----------
    assembly : Assembly
        With its assembly model (``assembly.model``); without one every offset is zero.
    phi : float
        The carrier angle (rad) the parts are placed at.
    gap : float, optional
        The gap (mm) between exploded parts; :data:`GAP_FRACTION` of the machine's size.

    Returns
    -------
    dict
        ``{instance name: (3,) float}``, one per placed part.
    """
    from cadgen.assembly.sequence import assembly_sequence

    boxes, kinds = _boxes(assembly, phi)
    offsets = {name: np.zeros(3) for name in boxes}
    model = getattr(assembly, "model", None)
    solid = [box for name, box in boxes.items() if kinds[name] != "ground"]
    if model is None or not solid:
        return offsets
    if gap is None:
        extent = np.ptp(np.vstack(solid), axis=0)
        gap = GAP_FRACTION * float(extent.max())
    steps = [s for s in assembly_sequence(model) if s["part"] in boxes and s["onto"] in boxes]
    # the gears and spacers ride on their shafts (the spacers sit between the gears)
    riding = [s for s in steps if {kinds[s["part"]], kinds[s["onto"]]} in RIDING]
    riders = {}
    for step in riding:
        gear, shaft = ((step["part"], step["onto"]) if kinds[step["part"]] != "shaft"
                       else (step["onto"], step["part"]))
        riders.setdefault(shaft, []).append(gear)
    local = {}
    pending = [s for s in steps if s not in riding]
    spliced = {}   # each printed segment: all the segments of its half, spliced together
    for step in pending:
        if "splice" in step["how"]:
            joined = spliced.get(step["part"], [step["part"]])
            joined += [p for p in spliced.get(step["onto"], [step["onto"]]) if p not in joined]
            for part in joined:
                spliced[part] = joined
    if not pending:
        return offsets
    root = pending[0]["onto"]
    done = {root: np.zeros(3)}
    station = {root: root}          # the housing base each placed part was put into or onto
    placed = [boxes[root] + gap * _PAD]

    def group(name, start):
        """The boxes of ``name`` and its gears at ``start``."""
        return [boxes[m] + start + local.get(m, np.zeros(3)) for m in [name] + riders.get(name, [])]

    def put(new, offset, home):
        for member in [new] + riders.get(new, []):
            done[member] = offset + local.get(member, np.zeros(3))
            station[member] = home
            placed.append(boxes[member] + done[member] + gap * _PAD)

    while pending:
        step = next((s for s in pending if (s["part"] in done) != (s["onto"] in done)), None)
        if step is None:
            break
        new, anchor = ((step["part"], step["onto"]) if step["onto"] in done
                       else (step["onto"], step["part"]))
        home = new if _BASE.search(new) and kinds[new] == "housing" else station[anchor]
        if kinds[new] == "shaft" and _BASE.search(anchor) and "splice" not in step["how"]:
            # the shafts going into one base go in side by side, at one lift (their meshing
            # gears level): the batch
            batch = [s["part"] for s in pending if s["onto"] == anchor and s["part"] not in done
                     and kinds[s["part"]] == "shaft"]
        else:   # a housing's segment comes with the segments spliced to it (one piece)
            batch = spliced.get(new, [new])
        pending = [s for s in pending if s is not step
                   and not (s["onto"] == anchor and s["part"] in batch)
                   and not (s["part"] in done and s["onto"] in done)]
        if "splice" in step["how"]:   # a segment left over: with its neighbour
            put(new, done[anchor].copy(), station[anchor])
            continue
        local.update(_layers([g for shaft in batch for g in riders.get(shaft, [])], boxes, gap))
        start = done[anchor].copy()
        if _ARM.search(new) and station[anchor] != new:   # an arm: out, clear of its carrier
            carriers = [boxes[n] + done[n] for n in done
                        if station[n] == station[anchor] and kinds[n] == "housing"]
            origin = np.vstack(carriers)[:, :2]
            origin = (origin.min(axis=0) + origin.max(axis=0)) / 2   # the carrier's middle
            direction = boxes[new][:, :2].mean(axis=0) - origin
            if np.linalg.norm(direction) > 1e-9:
                direction = direction / np.linalg.norm(direction)
                start[:2] += direction * _radial_clearance(boxes[new] + start, carriers,
                                                           direction, gap)
        sign = _sign(new, anchor, boxes, kinds)
        lift = _clearing_lift([box for part in batch for box in group(part, start)], placed,
                              sign, gap)
        for part in batch:
            put(part, start + sign * lift * _UP, home)
    for name, offset in done.items():
        offsets[name] = offset
    return offsets
