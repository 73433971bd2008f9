"""Progress of a build as it runs: events for a caller's callback (the library never prints).

:func:`cadgen.build` takes ``progress=callable``; the callable receives one
:class:`ProgressEvent` per change: a stage ``started``, a ``step`` of a long stage
(``step`` of ``steps``: a gear pair cut, a figure drawn, a file group written), a stage
``finished`` with its status and time. The command line's printer is
:class:`cadgen.report.progress.ProgressPrinter`.

The callback is called in the calling process, never twice at once (a lock), from the
build's thread or from a relay thread that forwards the events of the build's forked
workers (the FCL sweeps beside the teeth, half of the figures): a worker sends each event
through a pipe as it happens, so the sweeps' progress shows while the teeth are cut.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

__all__ = ["ProgressEvent", "StageProgress", "WRITE_STAGE"]

#: The pseudo-stage of writing the output folder (after every stage of the plan).
WRITE_STAGE = "write"


@dataclass(frozen=True)
class ProgressEvent:
    """One change in a running build.

    Attributes
    ----------
    stage : str
        A stage of :func:`cadgen.pipeline.build.plan`, or ``"write"`` (the output folder).
    state : {"started", "step", "finished"}
    step, steps : int
        ``step`` events: ``step`` of ``steps`` done (steps increase by one, in order);
        ``steps`` is 0 where the count is not known yet.
    seconds : float
        Since the stage started (``finished``: the stage's time, as in the report).
    elapsed : float
        Since the build started.
    status : str
        ``finished`` events: ``"ok"``, ``"failed"`` or ``"skipped"``; else empty.
    detail : str
        What the step did (the gear pair, the figure's file), or the failure's message.
    beside : bool
        Ran in the forked worker beside the teeth (the sweeps, and the parts without
        gears they run on), so its events interleave with the teeth's.
    """

    stage: str
    state: str
    step: int = 0
    steps: int = 0
    seconds: float = 0.0
    elapsed: float = 0.0
    status: str = ""
    detail: str = ""
    beside: bool = False


class StageProgress:
    """A build's event source: counts steps, times stages, calls the callback under a lock.

    In a forked worker, :meth:`forward` makes every call go through a pipe instead, to be
    replayed by :meth:`relay` in the building process (steps are counted there, so the
    steps of both processes are numbered in one sequence).

    Parameters
    ----------
    callback : callable or None
        ``callback(event)``; None: every call is a no-op (no cost beyond a test).
    """

    def __init__(self, callback=None):
        self.callback = callback
        self.start = time.perf_counter()
        self._lock = threading.RLock()
        self._begun: dict = {}
        self._done: dict = {}
        self._steps: dict = {}
        self._finished: set = set()
        self._connection = None
        self._relays: list = []
        self.error: BaseException | None = None

    @property
    def active(self) -> bool:
        return self.callback is not None or self._connection is not None

    def finished_stages(self) -> set:
        return set(self._finished)

    # ------------------------------------------------------------------ the three events
    def started(self, stage: str, *, steps: int = 0, detail: str = "", beside: bool = False):
        if self._forwarded("started", stage, steps=steps, detail=detail, beside=beside):
            return
        key = (stage, beside)    # a stage can run in both processes (the figures): two counts
        with self._lock:
            now = time.perf_counter()
            self._begun[key] = now
            self._done[key] = 0
            self._steps[key] = steps
            self._emit(ProgressEvent(stage, "started", 0, steps, 0.0, now - self.start,
                                     detail=detail, beside=beside))

    def step(self, stage: str, detail: str = "", *, steps: int | None = None,
             beside: bool = False):
        """One more step of ``stage`` done (``steps``: the total, when it becomes known)."""
        if self._forwarded("step", stage, detail, steps=steps, beside=beside):
            return
        key = (stage, beside)
        with self._lock:
            now = time.perf_counter()
            if steps is not None:
                self._steps[key] = steps
            done = self._done[key] = self._done.get(key, 0) + 1
            self._emit(ProgressEvent(stage, "step", done, self._steps.get(key, 0),
                                     now - self._begun.get(key, now), now - self.start,
                                     detail=detail, beside=beside))

    def finished(self, stage: str, status: str, seconds: float | None = None, *,
                 detail: str = "", beside: bool = False):
        if self._forwarded("finished", stage, status, seconds, detail=detail, beside=beside):
            return
        key = (stage, beside)
        with self._lock:
            now = time.perf_counter()
            if seconds is None:
                seconds = now - self._begun.get(key, now)
            self._finished.add(stage)
            self._emit(ProgressEvent(stage, "finished", self._done.get(key, 0),
                                     self._steps.get(key, 0), seconds, now - self.start,
                                     status=status, detail=detail, beside=beside))

    def _emit(self, event: ProgressEvent) -> None:
        if self.callback is not None:
            self.callback(event)

    # ------------------------------------------------------------------ forked workers
    def _forwarded(self, method: str, *args, **kwargs) -> bool:
        if self._connection is None:
            return self.callback is None    # nothing to do without a callback
        try:
            self._connection.send((method, args, kwargs))
        except OSError:     # the building process went away: nobody to tell
            self._connection = None
        return True

    def pipe(self):
        """Before forking a worker: ``(receiving end, sending end)``, or None when inactive.

        The caller forks, calls :meth:`relay` with the receiving end and closes its copy
        of the sending end; the worker calls :meth:`forward` with the sending end.
        """
        if self.callback is None:
            return None
        import multiprocessing

        return multiprocessing.get_context("fork").Pipe(duplex=False)

    def forward(self, connection) -> None:
        """In a forked worker: send every event to the building process."""
        self._connection = connection

    def relay(self, connection) -> threading.Thread:
        """In the building process: replay a worker's events until it closes its end."""
        thread = threading.Thread(target=self._relay, args=(connection,), daemon=True,
                                  name="cadgen-progress-relay")
        thread.start()
        self._relays.append(thread)
        return thread

    def _relay(self, connection) -> None:
        while True:
            try:
                method, args, kwargs = connection.recv()
            except (EOFError, OSError):
                break
            if self.error is not None:
                continue            # keep draining, call no more
            try:
                getattr(self, method)(*args, **kwargs)
            except Exception as error:  # the callback's: raised again in the build's thread
                self.error = error
        connection.close()

    def join(self, timeout: float | None = None) -> None:
        """Wait for the relays (their workers' events all delivered); raise a callback's error."""
        for thread in self._relays:
            thread.join(timeout)
        self._relays = [t for t in self._relays if t.is_alive()]
        if self.error is not None:
            error, self.error = self.error, None
            raise error
