"""The batch summary (``batch-summary.csv`` and ``.html``), the exit code, the progress line."""

from __future__ import annotations

import csv
import io
import json
import os
import sys
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

from cadgen.batch.html import summary_html
from kinematics.errors import Problem

__all__ = ["SUMMARY_CSV", "SUMMARY_HTML", "EXIT_OK", "EXIT_FAILED", "EXIT_PROBLEMS",
           "summary_csv", "summary_html", "write_summary", "batch_exit_code", "Progress"]

SUMMARY_CSV = "batch-summary.csv"
SUMMARY_HTML = "batch-summary.html"

# The same codes as cadgen.cli (not imported from it: the CLI imports this package).
EXIT_OK = 0
EXIT_FAILED = 1
EXIT_PROBLEMS = 2


def _order(summary: Mapping) -> tuple:
    """Summary order: by name, then source; a file given twice: the built one first."""
    failure = summary["failure"] or {}
    return summary["name"], summary["source"], not summary["ok"], failure.get("code", "")



def _status(summary: Mapping) -> str:
    """``ok`` (built, every stage ran), ``stage_failed`` (built, but a stage failed: its
    ``failure`` says which and why) or ``failed`` (not built)."""
    if not summary["ok"]:
        return "failed"
    return "stage_failed" if summary.get("failure") else "ok"


def _yes_no(value: bool | None) -> str:
    return "" if value is None else ("yes" if value else "no")


def _cell(value: Any) -> str:
    """A CSV cell: floats round-trip exactly (repr), tables and arrays as JSON."""
    if value is None or isinstance(value, (str, int, float)):
        return "" if value is None else repr(value) if isinstance(value, float) else str(value)
    return json.dumps(value)


def _columns(summaries: Sequence[Mapping]) -> tuple[list[str], list[str]]:
    """Grid keys and metric ids of all designs, in first-seen order."""
    grid_keys: dict[str, None] = {}
    metric_ids: dict[str, None] = {}
    for summary in summaries:
        grid_keys.update(dict.fromkeys(summary.get("values", {})))
        metric_ids.update(dict.fromkeys(summary["metrics"]))
    return list(grid_keys), list(metric_ids)


def _failure_codes(summary: Mapping) -> str:
    failure = summary["failure"]
    if not failure:
        return ""
    codes = ([failure["code"]] if failure["code"] == "stage_failed" else []) + \
        [p["code"] for p in failure.get("problems") or ()] or [failure["code"]]
    return ";".join(dict.fromkeys(codes))


def _missed(summary: Mapping) -> str:
    return ";".join(k for k, m in summary["metrics"].items() if m["passed"] is False)


def _why_not(summary: Mapping) -> str:
    """Why a built design did not pass: its missed targets, else its report's first note."""
    missed, notes = _missed(summary), summary.get("notes") or ()
    if missed or not notes:
        return "missed " + (missed.replace(";", ", ") or "its targets")
    return notes[0] + (f" (+{len(notes) - 1} more)" if len(notes) > 1 else "")


def summary_csv(summaries: Sequence[Mapping]) -> str:
    """The batch summary as CSV text: one row per design, ordered by name.

    Columns: ``design``, ``status`` (ok, ``stage_failed``: built but a stage failed, or
    failed), ``passed`` (yes/no, empty without
    targets), ``missed_targets``, one ``grid:<key>`` column per grid key, one column per
    metric id (its value), ``notes`` (why a built design did not pass, when its report
    says), ``failure_code`` (its problems' codes; ``exception`` for an error in the
    build, ``timeout``, ``worker_died``, ``worker_error``: see :mod:`cadgen.batch`),
    ``failure`` (every problem; the time limit, the exit code or the signal), ``source``,
    ``output`` (the folder under the output root). No timings or absolute paths: the same
    batch gives the same file (a timeout's row names the limit, not the time taken).
    """
    ordered = sorted(summaries, key=_order)
    grid_keys, metric_ids = _columns(ordered)
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["design", "status", "passed", "missed_targets",
                     *(f"grid:{k}" for k in grid_keys), *metric_ids,
                     "notes", "failure_code", "failure", "source", "output"])
    for s in ordered:
        metrics = s["metrics"]
        writer.writerow([
            s["name"], _status(s), _yes_no(s["passed"]), _missed(s),
            *(_cell(s.get("values", {}).get(k)) for k in grid_keys),
            *(_cell(metrics[k]["value"]) if k in metrics else "" for k in metric_ids),
            "; ".join(s.get("notes", ())), _failure_codes(s),
            s["failure"]["message"] if s["failure"] else "", s["source"],
            Path(s["output_dir"]).name if s["output_dir"] else "",
        ])
    return stream.getvalue()


def write_summary(summaries: Sequence[dict], output_root: str | os.PathLike, *,
                  title: str = "Batch summary") -> tuple[Path, Path]:
    """Write ``batch-summary.csv`` and ``.html`` atomically under ``output_root``; their paths.

    The page links each built design's ``report.html`` relative to ``output_root`` and,
    for a grid (each summary's ``values``), plots every metric against every varied key
    (see :func:`~cadgen.batch.html.summary_html`); ``title`` heads it.
    """
    from cadgen.export.atomic import write_text_atomic

    root = Path(output_root)
    root.mkdir(parents=True, exist_ok=True)
    return (write_text_atomic(root / SUMMARY_CSV, summary_csv(summaries)),
            write_text_atomic(root / SUMMARY_HTML,
                              summary_html(summaries, title, root=root)))


def batch_exit_code(summaries: Iterable[Mapping], strict: bool = False) -> int:
    """:data:`EXIT_OK` if every design built (and, when ``strict``, none missed a target:
    a design without targets passes), else :data:`EXIT_FAILED`."""
    for s in summaries:
        if not s["ok"] or (strict and s["passed"] is False):
            return EXIT_FAILED
    return EXIT_OK


# --------------------------------------------------------------------------- progress


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    hours, rest = divmod(seconds, 3600)
    return (f"{hours}:" if hours else "") + f"{rest // 60:02d}:{rest % 60:02d}"


def _reason(summary: Mapping) -> str:
    failure = summary["failure"]
    if not failure:
        return ""
    problems = failure.get("problems") or ()
    more = f" (+{len(problems) - 1} more)" if len(problems) > 1 else ""
    first = str(Problem(**problems[0])) if problems else f"{failure['message']} [{failure['code']}]"
    return first + more


class Progress:
    """A one-line progress bar: ``[12/40] 30% ok 11, failed 1, 2 running (r-011, -012),
    26 queued, eta 00:42``.

    On a terminal the line is redrawn in place (failures printed above it); elsewhere (a
    log, CI) it prints one line per change: a design started, a design finished. Designs
    are ``running`` from :meth:`started` (a worker took them) to :meth:`update`; without
    starts (a Dask cluster does not tell them) the line has no running or queued part.

    Parameters
    ----------
    total : int
        Number of designs.
    stream : text stream, default sys.stderr
    tty : bool, optional
        Force the terminal mode on or off (default: ``stream.isatty()``).
    """

    def __init__(self, total: int, stream: TextIO | None = None, tty: bool | None = None):
        self.total = total
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(tty if tty is not None else getattr(self.stream, "isatty", bool)())
        self.done = self.ok = self.failed = 0
        self.running: list[str] = []        # in the order they started
        self._early: list[str] = []         # finished before their start was told
        self._starts = False
        self.start = time.perf_counter()
        if self.tty:  # show the bar at once: the first design may take a while
            self.stream.write(self.line())
            self.stream.flush()

    @property
    def queued(self) -> int:
        """Designs neither started nor finished (meaningful once a start was told)."""
        return max(0, self.total - self.done - len(self.running))

    def line(self) -> str:
        """The current progress line (no line break)."""
        percent = 100 * self.done // self.total if self.total else 100
        text = f"[{self.done}/{self.total}] {percent}% ok {self.ok}, failed {self.failed}"
        if self._starts:
            text += f", {self._activity()}"
        if 0 < self.done < self.total:
            elapsed = time.perf_counter() - self.start
            text += f", eta {_clock(elapsed / self.done * (self.total - self.done))}"
        return text

    def _activity(self) -> str:
        """``2 running (l2-sweep-004, -005), 4 queued``."""
        text = f"{len(self.running)} running"
        if self.running:
            text += f" ({_names(self.running)})"
        return text + f", {self.queued} queued"

    def started(self, name: str) -> None:
        """A worker started design ``name``: show it running."""
        self._starts = True
        if name in self._early:          # its result came first: it is done already
            self._early.remove(name)
            return
        self.running.append(name)
        if self.tty:
            self.stream.write("\r\x1b[K" + self.line())
        else:
            self.stream.write(f"[{self.done}/{self.total}] started {name}; "
                              f"{self._activity()}\n")
        self.stream.flush()

    def update(self, summary: Mapping) -> None:
        """Count one finished design and show it."""
        self.done += 1
        self.ok += bool(summary["ok"])
        self.failed += not summary["ok"]
        if summary["name"] in self.running:
            self.running.remove(summary["name"])
        elif self._starts:
            self._early.append(summary["name"])
        if self.tty:
            if not summary["ok"]:
                self.stream.write(f"\r\x1b[Kfailed {summary['name']}: {_reason(summary)}\n")
            self.stream.write("\r\x1b[K" + self.line())
        else:
            verdict = "ok" if summary["ok"] else f"failed: {_reason(summary)}"
            self.stream.write(f"[{self.done}/{self.total}] {summary['name']} {verdict} "
                              f"({summary['seconds']:.1f} s)"
                              + (f"; {self._activity()}" if self._starts else "") + "\n")
        self.stream.flush()

    def close(self) -> None:
        """End the bar's line (terminal mode)."""
        if self.tty and self.done:
            self.stream.write("\n")
            self.stream.flush()


#: Running designs named on the progress line; more are counted.
_NAMES_SHOWN = 4


def _names(names: Sequence[str], shown: int = _NAMES_SHOWN) -> str:
    """``l2-sweep-004, -005``: a name after the first that shares its stem up to the last
    hyphen is shortened to its suffix; past ``shown`` names, ``+N more``."""
    first = names[0]
    stem = first[:first.rfind("-")] if "-" in first else None
    out = [first]
    for name in names[1:shown]:
        out.append(name[len(stem):] if stem and name.startswith(stem + "-") else name)
    if len(names) > shown:
        out.append(f"+{len(names) - shown} more")
    return ", ".join(out)
