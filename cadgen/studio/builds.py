"""Builds started from the studio: one at a time, in a process of their own, progress streamed.

:class:`BuildJobs` validates the design in the server's process (a bad design is an
answer to the request, not a failed job), then runs :func:`cadgen.build` in a child
process that is a fresh interpreter (``python -m cadgen.studio.builds``, the design on
stdin as JSON), as the "spawn" start method makes one: the server has threads and an
event loop, and a forked copy of a threaded process can hang on a lock some other thread
held. Not a :mod:`multiprocessing` "spawn" child itself: that one first re-runs the
server's main script, all of it when the script lacks the ``if __name__ == "__main__"``
guard (a probe script of the studio did, and built in a loop). The child's own process
group holds the build's forked workers too (the sweeps beside the teeth, the figures),
so stopping a build stops all of them.

The child turns each :class:`~cadgen.pipeline.progress.ProgressEvent` into a plain dict
(``{"type": "progress", "stage", "status": "start|step|end", "elapsed_s", "done",
"total", "text", ...}``, ``text`` the line ``cadgen build`` prints in a log) and sends it
through a pipe; at the end one ``{"type": "done", "exit_code", "report", "glb", "summary",
"error"}``. A pipe (a :class:`multiprocessing.connection.Connection` on its file
descriptor) rather than a :class:`multiprocessing.Queue`: a queue's feeder thread in the
child would be copied, perhaps holding its lock, into the workers the build forks.

The child of the next build is started, and imports what a build will (scipy, trimesh,
matplotlib...: :func:`cadgen.pipeline.warm.warm_all`), as soon as a build ends: it then waits
for its design on stdin, so the designer's next build does not pay the interpreter's start
and those imports (about half its time).

Every child ends with the server, however the server ends (killed too): it watches a
lifeline pipe whose write end only the server holds (:mod:`cadgen.processes.lifeline`; a
pipe rather than a parent-death signal, which would come when the request thread that
started the child ends). At its end a waiting child ends at once, and a building one stops
as on the server's SIGTERM (its staging folder removed), killed with its workers if that
takes longer than :data:`cadgen.processes.ORPHAN_GRACE_SECONDS`.

In the server, a thread per job reads the pipe into the job's event list;
:meth:`BuildJobs.events` replays that list to any subscriber, late ones included, and
then waits for more (woken through its event loop). A child that dies without its
``done`` (killed, out of memory) still ends the job: ``done`` with exit code 3 and
"the build process died (signal N)".
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import secrets
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from cadgen import MechanismError
from cadgen.crash import one_line, write_crash_file

__all__ = ["BuildJobs", "BuildJob", "BuildBusy", "UnknownJob", "EXIT_INTERNAL",
           "EXIT_STOPPED"]

#: Exit code of a build that crashed or whose process died (the CLI's "internal error").
EXIT_INTERNAL = 3
#: Exit code of a build stopped by :meth:`BuildJobs.shutdown` (the CLI's Ctrl-C code).
EXIT_STOPPED = 130
#: Seconds a stopped build gets to clean its staging folder before it is killed.
STOP_GRACE_SECONDS = 10.0
#: Seconds between checks that the child is alive while its pipe is quiet.
POLL_SECONDS = 0.2
#: Finished jobs kept for late subscribers (a designer's session starts a few dozen).
KEPT_JOBS = 32

_STATUS = {"started": "start", "step": "step", "finished": "end"}


class BuildBusy(MechanismError):
    """A build is already running (the studio runs one at a time)."""


class UnknownJob(MechanismError, KeyError):
    """No build has this id (also a KeyError, as a mapping lookup would raise)."""

    def __str__(self) -> str:
        return f"no build {self.args[0]!r}" if self.args else "no such build"


@dataclass
class BuildJob:
    """One build: its events so far and, once over, its ``done`` event.

    ``events`` holds every event in order, the final ``done`` included; :meth:`BuildJobs.get`
    returns a copy, so reading it needs no lock.
    """

    id: str
    name: str
    pid: int | None = None
    events: list = field(default_factory=list)
    done: dict | None = None

    @property
    def running(self) -> bool:
        return self.done is None


class _Job(BuildJob):
    """The live job (the server's side): the child, the pipe, the waiting subscribers."""

    def __init__(self, id: str, name: str):
        super().__init__(id, name)
        self.lock = threading.Lock()
        self.waiters: list = []      # (event loop, asyncio.Event) of subscribers waiting
        self.process = None
        self.drain = None            # the thread reading the child's pipe; the only joiner
        self.stopping = False

    def add(self, event: dict) -> None:
        with self.lock:
            if self.done is not None:
                return               # after done nothing counts (a late message of a dying child)
            self.events.append(event)
            if event.get("type") == "done":
                self.done = event
            waiters, self.waiters = self.waiters, []
        for loop, wake in waiters:
            try:
                loop.call_soon_threadsafe(wake.set)
            except RuntimeError:     # that subscriber's loop is closed: nobody to wake
                pass

    def snapshot(self) -> BuildJob:
        with self.lock:
            return BuildJob(self.id, self.name, self.pid, list(self.events), self.done)


class BuildJobs:
    """The studio's builds into ``output_root`` (``<output_root>/<name>/``), one at a time.

    Parameters
    ----------
    output_root : Path
        Where builds write; the ``done`` event's links are relative to it
        (``/files/<name>/report.html``).
    """

    def __init__(self, output_root: Path):
        self.output_root = Path(output_root)
        self._jobs: dict = {}
        self._lock = threading.Lock()
        self._spare = None           # (Popen, receiving end): the next build's child, waiting
        self._closed = False

    # ------------------------------------------------------------------ starting
    def start(self, params: dict) -> str:
        """Validate ``params`` and start building them; the job's id.

        Raises
        ------
        cadgen.ParameterError
            The design does not validate, a problem of a stage its scene runs (the
            duckbill linkage when the cam is built), or no effect of its scene applies:
            what ``cadgen build`` refuses.
        BuildBusy
            A build is running.
        """
        from cadgen import validate_data
        from cadgen.pipeline.plan import scene_plan

        validated = validate_data(params)
        scene = validated.scene
        scene_plan(validated, scene.effects, scene.case)
        with self._lock:
            running = [job for job in self._jobs.values() if job.running]
            if running:
                raise BuildBusy(f"the build of {running[0].name} is still running")
            job = _Job(secrets.token_urlsafe(9), validated.name)
            process, receiving = self._take_spare() or _start_child()
            _send_request(process, params, self.output_root)
            job.process, job.pid = process, process.pid
            self._jobs[job.id] = job
            self._forget_old_jobs()
        job.drain = threading.Thread(target=self._drain, args=(job, receiving), daemon=True,
                                     name=f"cadgen-studio-build-{job.id}")
        job.drain.start()
        return job.id

    def _take_spare(self):
        """The waiting child, if it is alive (called under the lock), else None."""
        spare, self._spare = self._spare, None
        if spare is None:
            return None
        if spare[0].poll() is None:
            return spare
        spare[1].close()
        _let_go(spare[0])
        return None

    def _start_spare(self) -> None:
        """Start the next build's child, unless one waits, a build runs or the server is
        closing: started after a build, it takes no core from one."""
        with self._lock:
            if self._closed or self._spare is not None \
                    or any(job.running for job in self._jobs.values()):
                return
            try:
                self._spare = _start_child(warm=True)
            except OSError:     # no process to spare now: the next build starts its own
                self._spare = None

    def _close_spare(self) -> None:
        with self._lock:
            self._closed = True
            spare, self._spare = self._spare, None
        if spare is None:
            return
        process, receiving = spare
        _close_stdin(process)       # its design will not come: it ends
        _let_go(process)            # (so does its lifeline)
        try:
            process.wait(STOP_GRACE_SECONDS)
        except subprocess.TimeoutExpired:
            _signal_group(process.pid, signal.SIGKILL)
            process.wait()
        receiving.close()

    def _forget_old_jobs(self) -> None:
        finished = [job_id for job_id, job in self._jobs.items() if not job.running]
        for job_id in finished[:max(0, len(self._jobs) - KEPT_JOBS)]:
            del self._jobs[job_id]

    # ------------------------------------------------------------------ the child's messages
    def _drain(self, job: _Job, receiving) -> None:
        """Read the child's events into the job until its ``done``, or its death."""
        process = job.process
        while job.done is None:
            try:
                if not receiving.poll(POLL_SECONDS):
                    if process.poll() is None:
                        continue
                    if not receiving.poll(0):   # dead, and nothing left in the pipe
                        break
                message = receiving.recv()
            except (EOFError, OSError):    # every writer gone: the child ended
                break
            except Exception:   # a message cut short by the child's death: unreadable
                break
            job.add(message)
        receiving.close()
        try:
            process.wait(STOP_GRACE_SECONDS)
        except subprocess.TimeoutExpired:   # said done but does not end (a worker it awaits)
            _signal_group(process.pid, signal.SIGKILL)
            process.wait()
        _let_go(process)
        if job.done is None:
            job.add(_done(EXIT_STOPPED if job.stopping else EXIT_INTERNAL,
                          error=_death(process.returncode, job.stopping)))
        if not job.stopping:
            self._start_spare()

    # ------------------------------------------------------------------ reading
    def get(self, job_id: str) -> BuildJob:
        """A copy of the job's state (``events``, ``done``, ``pid``); UnknownJob if none."""
        return self._job(job_id).snapshot()

    def _job(self, job_id: str) -> _Job:
        with self._lock:
            job = self._jobs.get(job_id)
        if job is None:
            raise UnknownJob(job_id)
        return job

    async def events(self, job_id: str):
        """Every event of the job, from the first, then new ones as they come; ends after
        ``done``. Raises UnknownJob (a KeyError) at the first step when there is no such job.
        """
        job = self._job(job_id)
        loop = asyncio.get_running_loop()
        sent = 0
        while True:
            wake = asyncio.Event()
            with job.lock:
                new = job.events[sent:]
                if not new:
                    job.waiters.append((loop, wake))
            for event in new:
                yield event
                sent += 1
                if event.get("type") == "done":
                    return
            if not new:
                try:   # the timeout only guards against a lost wake-up
                    await asyncio.wait_for(wake.wait(), timeout=1.0)
                except asyncio.TimeoutError:
                    pass

    # ------------------------------------------------------------------ stopping
    def shutdown(self, timeout: float = STOP_GRACE_SECONDS) -> None:
        """Stop a running build (its process group: the child and the workers it forked).

        SIGTERM first, so the build removes its staging folder; SIGKILL after ``timeout``.
        The job ends with ``done``, exit code 130, "the build was stopped". Returns once
        the child is reaped (by the job's pipe reader: one thread only waits for a child,
        two would race for its exit status).
        """
        self._close_spare()
        with self._lock:
            running = [job for job in self._jobs.values() if job.running]
        for job in running:
            job.stopping = True
            _signal_group(job.pid, signal.SIGTERM)
        for job in running:
            job.drain.join(timeout)
            if job.drain.is_alive():
                _signal_group(job.pid, signal.SIGKILL)
                job.drain.join(timeout)


def _start_child(warm: bool = False):
    """Start ``python -m cadgen.studio.builds``, which waits for its design on stdin (having
    imported what a build will, when ``warm``): ``(Popen, receiving end)``."""
    from multiprocessing.connection import Connection

    import cadgen

    reading, writing = os.pipe()
    # the child's lifeline (see the module docstring): the server keeps the write end
    # (close-on-exec: no other child inherits it), the child reads the other
    alive, lifeline = os.pipe()
    environment = dict(os.environ)
    # the cadgen this server runs, even from a source tree that was never installed
    source = str(Path(cadgen.__file__).resolve().parents[1])
    environment["PYTHONPATH"] = os.pathsep.join(
        [source, *filter(None, [environment.get("PYTHONPATH")])])
    try:
        process = subprocess.Popen(
            [sys.executable, "-m", "cadgen.studio.builds", str(writing), str(alive),
             *(["--warm"] if warm else [])],
            stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, pass_fds=(writing, alive),
            env=environment,
            # a group of its own: shutdown() signals it and the workers the build forks,
            # and the terminal's Ctrl-C reaches the server only, which stops it
            process_group=0)
    except BaseException:
        os.close(reading)
        os.close(lifeline)
        raise
    finally:
        os.close(writing)   # the child's copy is the last: its death closes the pipe
        os.close(alive)
    process.lifeline = lifeline
    return process, Connection(reading, writable=False)


def _let_go(process) -> None:
    """Close the server's end of the child's lifeline (the child has ended, or is told to)."""
    lifeline, process.lifeline = getattr(process, "lifeline", None), None
    if lifeline is not None:
        with contextlib.suppress(OSError):
            os.close(lifeline)


def _send_request(process, params: dict, output_root: Path) -> None:
    """Give the child its design (it builds once its stdin closes)."""
    request = json.dumps({"params": params, "output_root": str(output_root)}).encode()
    try:
        process.stdin.write(request)
    except OSError:         # it died at once: the pipe's end says so
        pass
    finally:
        _close_stdin(process)


def _close_stdin(process) -> None:
    try:
        process.stdin.close()
    except OSError:
        pass


def _signal_group(pid: int | None, signum: int) -> None:
    """Signal the child's process group (the child and the workers its build forked)."""
    if pid is None:
        return
    try:
        os.killpg(pid, signum)
    except (ProcessLookupError, PermissionError):   # every process of it gone already
        pass


def _death(exitcode: int | None, stopping: bool) -> str:
    # Popen's return code: negative for the signal that ended the process
    if stopping:
        return "the build was stopped (the studio is closing)"
    if exitcode is not None and exitcode < 0:
        return f"the build process died (signal {-exitcode})"
    return f"the build process died (exit status {exitcode})"


def _done(exit_code: int, *, report=None, glb=None, summary: str = "", error=None,
          elapsed_s: float | None = None) -> dict:
    return {"type": "done", "exit_code": exit_code, "report": report, "glb": glb,
            "summary": summary, "error": error, "elapsed_s": elapsed_s}


# --------------------------------------------------------------------------- the child
#: In the child: whether it builds (see :func:`_server_gone`).
_CHILD = {"building": False}


def _server_gone() -> None:
    """In the child, at the lifeline's end (the server has ended, however): a child that
    waits for its design ends now; a building one stops as on the server's SIGTERM (its
    staging folder removed), killed with its workers if that takes too long."""
    from cadgen.processes import EXIT_ORPHANED, end_after

    if not _CHILD["building"]:
        os._exit(EXIT_ORPHANED)
    end_after()
    os.kill(os.getpid(), signal.SIGTERM)


def _child_main(arguments: list) -> None:
    """``python -m cadgen.studio.builds FD LIFELINE``: the design on stdin, events down the
    pipe FD; ends with the server (the lifeline's end)."""
    from multiprocessing.connection import Connection

    from cadgen.processes import watch_lifeline

    watch_lifeline(int(arguments[1]), _server_gone)
    sending = Connection(int(arguments[0]), readable=False)
    if "--warm" in arguments[2:]:
        with contextlib.suppress(Exception):   # a build that needs a broken one says so
            from cadgen.pipeline.warm import warm_all

            warm_all()
    text = sys.stdin.buffer.read()
    if not text:            # the server closed without a design for it: nothing to do
        sending.close()
        return
    request = json.loads(text)
    _child_build(request["params"], request["output_root"], sending)


def _child_build(params: dict, output_root: str, sending) -> None:
    """In the child: build ``params`` into ``output_root``, events to ``sending``."""
    from cadgen.processes import Interrupts

    # SIGTERM from the server stops the build (raised again if a library swallows it; a
    # build worker forked from here ends quietly); SIGINT is the server's to decide
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    interrupts = Interrupts(signals=(signal.SIGTERM,)).install()
    _CHILD["building"] = True   # the server's end now stops the build (_server_gone)
    start = time.perf_counter()
    try:
        try:
            done = _build_in_child(params, Path(output_root), sending)
        finally:
            interrupts.stopping = True   # not raised again while the answer is sent
    except KeyboardInterrupt:
        done = _done(EXIT_STOPPED, error="the build was stopped (the studio is closing)")
    except BaseException as error:   # a bug: one line here, the traceback in a crash file
        done = _done(EXIT_INTERNAL, error=_crash(error, params))
    done["elapsed_s"] = round(time.perf_counter() - start, 3)
    _send(sending, done)
    sending.close()
    if done["exit_code"] == EXIT_STOPPED:
        # stopped: its outputs are cleaned up and its answer sent; the interpreter's exit
        # is not waited for (it joins the build's pool thread, which may wait for ever on
        # a result its worker, stopped with it, had half sent)
        with contextlib.suppress(OSError, ValueError):
            sys.stderr.flush()
        os._exit(EXIT_STOPPED)


def _send(sending, message: dict) -> None:
    """Send ``message`` to the server; nobody reading (the server went away) is no error:
    the build goes on and its outputs are written all the same."""
    try:
        sending.send(message)
    except OSError:
        pass


def _build_in_child(params: dict, output_root: Path, sending) -> dict:
    from cadgen import OutputDirError, ParameterError, build, validate_data

    progress = _ProgressRelay(sending)
    try:
        validated = validate_data(params)
        result = build(validated, output_root=output_root, progress=progress)
    except (ParameterError, OutputDirError) as error:   # what `cadgen build` exits 2 for
        return _done(2, error=one_line(error))
    files = set(result.files)
    folder = "/files/" + result.output_dir.relative_to(output_root).as_posix()
    return _done(result.exit_code,
                 report=f"{folder}/report.html" if "report.html" in files else None,
                 glb=f"{folder}/solids/assembly.glb" if "solids/assembly.glb" in files
                 else None,
                 summary=result.summary_text())


class _ProgressRelay:
    """The build's progress callback in the child: each event as a dict down the pipe,
    its ``text`` the line the command line's printer writes to a log."""

    def __init__(self, sending):
        import io

        from cadgen import ProgressPrinter

        self.sending = sending
        self.lines = io.StringIO()
        self.printer = ProgressPrinter(self.lines, tty=False)

    def __call__(self, event) -> None:
        self.printer(event)
        text = self.lines.getvalue().strip()
        self.lines.seek(0)
        self.lines.truncate()
        _send(self.sending, {
            "type": "progress", "stage": event.stage, "status": _STATUS[event.state],
            "elapsed_s": round(event.elapsed, 3), "done": event.step, "total": event.steps,
            "text": text, "seconds": round(event.seconds, 3),
            "outcome": event.status or None, "detail": event.detail, "beside": event.beside})


def _crash(error: BaseException, params: dict) -> str:
    """``internal error: ...`` on one line, the traceback saved as the command line saves it."""
    name = params.get("name") if isinstance(params, dict) else None
    try:
        saved = f"traceback saved to {write_crash_file(error, ['studio', 'build', str(name)])}"
    except Exception as exc:
        saved = f"the traceback could not be saved: {one_line(exc, 120)}"
    return (f"internal error: {type(error).__name__}: {one_line(error)} "
            f"(please report it; {saved})")


if __name__ == "__main__":
    _child_main(sys.argv[1:])
