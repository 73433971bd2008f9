"""The build's progress on a terminal or in a log: the printer the command line gives a build.

:class:`ProgressPrinter` is the ``progress`` callback of :func:`cadgen.build` (see
:class:`cadgen.pipeline.progress.ProgressEvent`). It writes to stderr, so stdout keeps
the summary. On a terminal, each finished stage is one line, like the summary's stage
table, and the stages running (the teeth and the sweeps beside them) share one status line
redrawn in place with a bar and a clock (a light thread redraws it four times a second, so
the clock moves in a long step). Elsewhere (a pipe, CI) every event is a plain line,
``[elapsed s] stage: what happened``, nothing redrawn.
"""

from __future__ import annotations

import sys
import threading
import time

__all__ = ["ProgressPrinter", "StatusPrinter", "progress_bar"]

#: Width of a stage's bar on the status line, in characters.
BAR_WIDTH = 16
#: Seconds between redraws of the status line on a terminal.
REDRAW_SECONDS = 0.25
_CLEAR = "\r\x1b[K"


def progress_bar(done: int, total: int, width: int = BAR_WIDTH) -> str:
    """``[######----------]``: ``done`` of ``total`` (an empty bar when the total is unknown)."""
    filled = 0 if total <= 0 else min(width, round(width * done / total))
    return "[" + "#" * filled + "-" * (width - filled) + "]"


class StatusPrinter:
    """What every progress printer shares: the stream, whether it is a terminal (redraw one
    status line in place) or not (plain lines), use as a context manager, clearing the line.

    Parameters
    ----------
    stream : text stream, default sys.stderr
    tty : bool, optional
        Redraw in place (default: ``stream.isatty()``); False prints plain lines.
    """

    def __init__(self, stream=None, tty: bool | None = None):
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(tty if tty is not None else getattr(self.stream, "isatty", bool)())
        self._shown = False      # a status line is on the terminal, to clear

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()
        return False

    def _status(self, line: str) -> None:
        """Redraw the status line (a terminal) with ``line``."""
        self.stream.write(_CLEAR + line)
        self._shown = True

    def _clear_status(self) -> None:
        if self.tty and self._shown:
            self.stream.write(_CLEAR)
            self.stream.flush()
            self._shown = False

    def close(self) -> None:
        """Clear the status line (a terminal); safe to call twice."""
        self._clear_status()


def _name(event) -> str:
    return event.stage + (" (beside)" if event.beside else "")


class ProgressPrinter(StatusPrinter):
    """Print a build's progress events (a callable: ``printer(event)``); :meth:`close` at the end.

    Parameters
    ----------
    stream : text stream, default sys.stderr
    tty : bool, optional
        Redraw in place (default: ``stream.isatty()``); False prints plain lines.
    """

    def __init__(self, stream=None, tty: bool | None = None):
        super().__init__(stream, tty)
        self._running: dict = {}     # (stage, beside) -> [start, done, steps, detail]
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._ticker = None

    # ------------------------------------------------------------------ events
    def __call__(self, event) -> None:
        with self._lock:
            key = (event.stage, event.beside)
            if event.state == "started":
                self._running[key] = [time.perf_counter(), 0, event.steps, event.detail]
            elif event.state == "step":
                entry = self._running.setdefault(key, [time.perf_counter(), 0, 0, ""])
                entry[1:] = [event.step, event.steps, event.detail]
            else:
                self._running.pop(key, None)
            if self.tty:
                self._tty(event)
            else:
                self._plain(event)
            self.stream.flush()

    def _plain(self, event) -> None:
        if event.state == "started":
            text = "started" + (f" ({event.detail})" if event.detail else "")
        elif event.state == "step":
            text = (f"{event.step}/{event.steps or '?'} {event.detail}".rstrip()
                    + f" ({event.seconds:.1f} s)")
        else:
            text = f"{event.status} in {event.seconds:.3f} s" + (
                f": {_first_line(event.detail)}" if event.detail else "")
        self.stream.write(f"[{event.elapsed:6.1f} s] {_name(event)}: {text}\n")

    def _tty(self, event) -> None:
        if event.state == "finished":
            line = f"  {_name(event):<25} {event.status:<8} {event.seconds:8.3f} s"
            if event.detail:
                line += f"  {_first_line(event.detail)}"
            self.stream.write(_CLEAR + line + "\n")
            self._shown = False
        self._draw()
        if self._ticker is None:
            self._ticker = threading.Thread(target=self._tick, daemon=True,
                                            name="cadgen-progress-printer")
            self._ticker.start()

    # ------------------------------------------------------------------ the status line
    def status_line(self) -> str:
        """What runs now: ``teeth [######----] 3/5 train 1: sun to idler 1 2.1 s | ...``."""
        now, parts = time.perf_counter(), []
        for (stage, beside), (start, done, steps, detail) in self._running.items():
            text = stage + (" (beside)" if beside else "")
            if steps:
                text += f" {progress_bar(done, steps)} {done}/{steps}"
                if detail:
                    text += f" {detail}"
            parts.append(f"{text} {now - start:.1f} s")
        return " | ".join(parts)

    def _draw(self) -> None:
        line = self.status_line()
        if line or self._shown:
            self.stream.write(_CLEAR + line)
            self._shown = bool(line)

    def _tick(self) -> None:
        while not self._stop.wait(REDRAW_SECONDS):
            with self._lock:
                if self._running:
                    try:
                        self._draw()
                        self.stream.flush()
                    except (OSError, ValueError):   # the terminal went away
                        return

    def close(self) -> None:
        """Stop redrawing and clear the status line (a terminal); safe to call twice."""
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join()
            self._ticker = None
        with self._lock:
            self._clear_status()


def _first_line(text: str, limit: int = 160) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."
