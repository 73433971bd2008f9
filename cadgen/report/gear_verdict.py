"""One statement of which gears were cut, for the page's checks, its gears section and the terminal.

A train's gears are cut a pair at a time: when one gear of a pair cannot be cut,
its mate is not cut either (the pair is one job: phased, checked and meshed
together), and ``report.json``'s ``gear_train`` then lists neither gear, only the
failure. Counting only the listed gears, or only the failures, gives two numbers
for one train ("2 could not be cut", "no gears were cut"); :func:`gear_verdict`
counts every gear of the train once, from the report alone: the cut gears (their
pair's name), each failure's gear and pair, and the pair's other gear from the
pitch curves the report lists (a pricking report's ``gears.pitch_curves``, with
their stage), so a reader sees, e.g.::

    no gear cut: intermediate 1 and planet cannot be cut (concave, no pinion cutter
    fits), so their pairs with sun and intermediate 2 were not cut either
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["GearVerdict", "gear_verdict"]


@dataclass(frozen=True)
class GearVerdict:
    """Which gears of a train were cut, and why the others were not.

    Attributes
    ----------
    cut : tuple of str
        The gears cut, in the report's order.
    not_cuttable : tuple of (str, str, str)
        ``(gear, pair, reason)`` for each gear that cannot be cut; ``reason`` in a few words.
    not_cut_with : tuple of (str, str, str)
        ``(gear, pair, mate)`` for each gear not cut because its mate ``mate`` cannot be.
    unknown_pairs : tuple of str
        Pairs not cut whose other gear the report does not name.
    """

    cut: tuple
    not_cuttable: tuple
    not_cut_with: tuple
    unknown_pairs: tuple

    @property
    def total(self) -> int:
        """Every gear of the train the report names."""
        return len(self.cut) + len(self.not_cuttable) + len(self.not_cut_with)

    @property
    def passed(self) -> bool:
        return not self.not_cuttable and not self.unknown_pairs

    def statement(self) -> str:
        """The verdict in one line (the checks row, the gears section and the terminal say it)."""
        count = len(self.cut)
        if self.passed:
            return f"{_plural(count, 'gear')} cut"
        head = ("no gear cut" if count == 0 else
                f"{count} of {self.total} gears cut" if self.total else f"{count} gears cut")
        reasons = list(dict.fromkeys(reason for _, _, reason in self.not_cuttable))
        failing = _names([gear for gear, _, _ in self.not_cuttable])
        text = f"{head}: {failing} cannot be cut ({'; '.join(reasons)})"
        mates = [gear for gear, _, _ in self.not_cut_with]
        if mates:
            own = "their pairs" if len(self.not_cuttable) > 1 else "its pair"
            text += f", so {own} with {_names(mates)} {'were' if len(mates) > 1 else 'was'} " \
                    "not cut either"
        if self.unknown_pairs:
            several = len(self.unknown_pairs) > 1
            text += (f", so {'their pairs' if several else 'its pair'} "
                     f"({_names(self.unknown_pairs)}) {'were' if several else 'was'} not cut")
        return text


def _plural(count: int, noun: str) -> str:
    return f"{count} {noun if count == 1 else noun + 's'}"


def _names(names) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _reason(message: str) -> str:
    """Why a gear cannot be cut, in a few words, from its failure's message."""
    text = message.split("cannot be cut:", 1)[-1].strip()
    if "concave" in text and "no pinion cutter" in text:
        return "concave, no pinion cutter fits"
    if "concave" in text:
        return "concave pitch curve"
    if "do not form a valid outline" in text:
        return "the tooth spaces do not form a valid outline"
    clause = re.split(r"[:;(]", text, maxsplit=1)[0].strip()
    return clause if 0 < len(clause) <= 60 else "see the message below"


def _gear_of(failure: dict) -> str:
    """The gear a failure names: ``the planet gear cannot ...`` or ``gears.planet``."""
    match = re.match(r"(?:the )?(.+?) gear cannot be cut", failure.get("message", ""))
    if match:
        return match[1]
    return str(failure.get("path", "?")).removeprefix("gears.").replace("_", " ")


def _pairs_of(report: dict) -> dict:
    """``pair -> [gear, ...]`` for every pair the report names: the cut gears' and the
    pitch curves' (``stage`` 1 is pair ``"stage 1"``)."""
    pairs: dict = {}
    for gear in report.get("gear_train", {}).get("gears", []):
        pairs.setdefault(str(gear.get("stage")), []).append(gear["gear"])
    for curve in (report.get("gears") or {}).get("pitch_curves", []) or []:
        stage = curve.get("stage")
        pair = f"stage {stage}" if isinstance(stage, int) else str(stage)
        names = pairs.setdefault(pair, [])
        if curve.get("name") not in names:
            names.append(curve.get("name"))
    return pairs


def gear_verdict(report: dict) -> GearVerdict | None:
    """Which gears of the report's train were cut; ``None`` when no teeth were cut in this
    build (the report has no ``gear_train``)."""
    train = report.get("gear_train")
    if train is None:
        return None
    cut = tuple(gear["gear"] for gear in train.get("gears", []))
    pairs = _pairs_of(report)
    failing, mates, unknown = [], [], []
    for failure in train.get("failures", []):
        gear, pair = _gear_of(failure), str(failure.get("stage", "?"))
        failing.append((gear, pair, _reason(failure.get("message", ""))))
    failed_gears = {gear for gear, _, _ in failing}
    for pair in dict.fromkeys(pair for _, pair, _ in failing):
        here = [gear for gear, where, _ in failing if where == pair]
        if pair in pairs:
            mates += [(other, pair, here[0]) for other in pairs[pair]
                      if other not in failed_gears and other not in cut]
        elif len(here) < 2:   # the report does not say which gear the pair's other one is
            unknown.append(pair)
    return GearVerdict(cut, tuple(failing), tuple(mates), tuple(unknown))
