"""A study's progress on stderr, as ``cadgen build`` and ``cadgen batch`` show theirs.

:class:`OptimizePrinter` is the ``progress`` callback of :func:`cadgen.optimize.run.optimize`.
On a terminal it redraws one status line in place: the evaluations done against the budget
with a bar, the generation, and the best feasible objective so far (or, before any design
is feasible, the smallest constraint violation); then the exact evaluations of the final
designs. In a log or a pipe it writes plain lines instead, one each time the screen passes
another tenth of the budget, and one per certified design, nothing redrawn.
"""

from __future__ import annotations

from cadgen.report.progress import StatusPrinter, progress_bar

__all__ = ["OptimizePrinter", "describe_progress"]

#: Plain lines (a pipe) while screening: one each time another 1/PLAIN_STEPS of the budget is done.
PLAIN_STEPS = 10


def describe_progress(event) -> str:
    """One line for an :class:`~cadgen.optimize.run.OptimizeProgress`."""
    if event.stage == "certify":
        return (f"certify {progress_bar(event.done, event.total)} {event.done}/{event.total} "
                "designs through the exact evaluator")
    if event.best is None:
        state = f"no feasible design yet: smallest constraint violation {event.violation:.4g}"
    else:
        word = "largest" if event.sense == "max" else "smallest"
        state = f"best feasible {event.objective} {event.best:.6g} ({word} wanted)"
    return (f"screen {progress_bar(event.evaluations, event.budget)} {event.evaluations}/"
            f"{event.budget} evaluations, generation {event.generation}, {state}")


class OptimizePrinter(StatusPrinter):
    """Print a study's progress (a callable: ``printer(event)``); :meth:`close` at the end.

    Parameters
    ----------
    stream : text stream, default sys.stderr
    tty : bool, optional
        Redraw in place (default: ``stream.isatty()``); False prints plain lines.
    """

    def __init__(self, stream=None, tty: bool | None = None):
        super().__init__(stream, tty)
        self._next_plain = 0     # the next step (of PLAIN_STEPS) that earns a plain line

    def __call__(self, event) -> None:
        line = describe_progress(event)
        if self.tty:
            self._status(line + f" {event.elapsed:.1f} s")
        elif event.stage != "screen" or event.evaluations >= event.budget or (
                event.evaluations * PLAIN_STEPS >= self._next_plain * event.budget):
            if event.stage == "screen":
                self._next_plain = event.evaluations * PLAIN_STEPS // event.budget + 1
            self.stream.write(f"[{event.elapsed:6.1f} s] {line}\n")
        self.stream.flush()
