"""Children that end with the process that started them, however it ends.

A process cadgen starts (the worker beside a build's teeth, a batch's workers and the
designs they fork, the optimiser's pool, the studio's build process and its spare) must
not outlive its parent: killed (SIGKILL, an out-of-memory kill, a CI job's time limit),
crashed, or ended by a signal it handles. Nothing here polls; the platform tells:

- the parent-death signal (Linux, ``prctl(PR_SET_PDEATHSIG)``): the kernel sends the child
  a signal when the *thread* that started it ends (so it is only for children started
  from a thread that lives as long as they are needed: the one that waits for them). It
  is set first thing in the child (:func:`die_with_parent`); a parent that died before
  that is seen by ``os.getppid()`` no longer being its pid, and the child ends at once.
  Pool workers get it through :func:`process_pool`'s initializer.
- a lifeline pipe: the parent holds the write end and never writes; a thread in the
  child blocks reading the other end (:func:`watch_lifeline`) and gets end-of-file when
  every copy of the write end is closed, that is when the parent *process* ends, whichever
  of its threads started the child (the studio starts its builds from request threads),
  on any POSIX system. The write end is close-on-exec, so no other program inherits it;
  a process forked from the parent does, which is why the pipe is made for one child
  and closed once it has ended.

A child with nothing to clean up is killed outright (SIGKILL: a pool worker holds no
file of its own). One that may hold a staging folder gets a signal it handles as an
interrupt (SIGTERM), unwinds as on Ctrl-C (the folder is removed on the way) and is
killed anyway after :data:`ORPHAN_GRACE_SECONDS` (:func:`end_after`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time

__all__ = ["EXIT_ORPHANED", "ORPHAN_GRACE_SECONDS", "die_with_parent", "orphaned",
           "process_pool", "stop_pool", "watch_lifeline", "end_after"]

#: Exit status of a child that ended because its parent had (the lifeline's end, or a
#: parent that died before the child could ask to be told).
EXIT_ORPHANED = 70
#: Seconds an orphaned child that cleans up (a batch worker removing its design's staging
#: folder, the studio's build) has before it is killed with what it started.
ORPHAN_GRACE_SECONDS = 1.5
#: Seconds :func:`stop_pool` waits for killed workers to be reaped.
REAP_SECONDS = 2.0
_PR_SET_PDEATHSIG = 1   # <linux/prctl.h>

#: prctl from the C library, looked up once in the parent (see :func:`_prctl`).
_PRCTL: list = []


def _prctl():
    """The C library's ``prctl``, or None (not Linux). Looked up before a fork, by the
    parent: a lookup (dlopen) in a child forked from a threaded process could wait on the
    loader's lock, held by a thread that does not exist there."""
    if not _PRCTL:
        function = None
        if sys.platform.startswith("linux"):
            with contextlib.suppress(OSError, AttributeError):
                import ctypes

                function = ctypes.CDLL(None, use_errno=True).prctl
                function.restype = ctypes.c_int
                function.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_ulong,
                                     ctypes.c_ulong, ctypes.c_ulong]
        _PRCTL.append(function)
    return _PRCTL[0]


def die_with_parent(parent: int, signum: int = signal.SIGKILL) -> bool:
    """In a child, first thing: be sent ``signum`` when the thread that started it ends.

    Parameters
    ----------
    parent : int
        The parent's pid, as the parent gave it (``os.getpid()`` there, before starting).
    signum : int
        SIGKILL for a child with nothing to clean up; a signal it handles (SIGTERM) for
        one that must remove what it was writing.

    Returns
    -------
    bool
        Whether the platform sends it (Linux); elsewhere the caller relies on a lifeline.
        A child whose parent has already died does not return: it ends at once with
        :data:`EXIT_ORPHANED` (nothing of its work has begun).
    """
    prctl = _prctl()
    armed = prctl is not None and prctl(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0) == 0
    # set after the parent died (the race the signal cannot cover): already re-parented
    if os.getppid() != parent:
        os._exit(EXIT_ORPHANED)
    return armed


def orphaned(parent: int) -> bool:
    """Whether the process ``parent`` that started this one has ended (it was re-parented)."""
    return os.getppid() != parent


def _start_worker(parent: int, signum: int, initializer, initargs: tuple) -> None:
    """A pool worker's initializer: die with the parent, then the pool's own initializer
    (imported only now when given as ``"module:name"``), then take the interrupts held back
    while it was started (see :func:`process_pool`)."""
    from cadgen.processes.interrupts import release_deferred_sigint

    came: list = []

    def starting(number, frame):
        if orphaned(parent):
            os._exit(EXIT_ORPHANED)
        came.append(number)

    if signum != signal.SIGKILL:
        # until the initializer has put its own handler in place (a batch worker's imports
        # take seconds on a busy core): the parent's death ends the worker at once (it holds
        # nothing yet); a signal meant for it is passed on to that handler after
        previous = signal.signal(signum, starting)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signum})
    die_with_parent(parent, signum)
    if isinstance(initializer, str):
        import importlib

        module, _, name = initializer.partition(":")
        initializer = getattr(importlib.import_module(module), name)
    if initializer is not None:
        initializer(*initargs)
    if signum != signal.SIGKILL and signal.getsignal(signum) is starting:
        signal.signal(signum, previous)
    for number in came:
        os.kill(os.getpid(), number)
    release_deferred_sigint()


def process_pool(workers: int, context, *, initializer=None, initargs: tuple = (),
                 death_signal: int = signal.SIGKILL):
    """A :class:`concurrent.futures.ProcessPoolExecutor` whose workers die with this thread.

    Each worker sets its parent-death signal (``death_signal``) before ``initializer``
    runs. The workers are started by the pool's ``submit`` (``map``), from the calling
    thread, which must wait for them (it does: a build, a batch, a search wait for their
    results). Submit inside :func:`cadgen.processes.sigint_deferred`: a worker is then
    started and registered whole (an interrupt between the two left one the pool did not
    know, and its manager thread waiting for ever), and a worker starts with the
    interrupt signals held back until its handler is in place.

    Parameters
    ----------
    workers : int
    context : multiprocessing context
        ``fork`` or ``spawn``.
    initializer, initargs
        As for the executor (a spawned worker needs them picklable; a module-level
        initializer is sent by name, imported once the worker dies with this thread).
    death_signal : int
        See :func:`die_with_parent`.
    """
    from concurrent.futures import ProcessPoolExecutor

    _prctl()   # looked up here, before any fork
    if initializer is not None and context.get_start_method() != "fork" \
            and "." not in initializer.__qualname__:
        # a new interpreter unpickles the initializer before running any of it: by name, its
        # module (a batch worker's imports the parameter schema, seconds on a busy core) is
        # imported after the worker has asked to die with this thread, not before
        initializer = f"{initializer.__module__}:{initializer.__qualname__}"
    return ProcessPoolExecutor(max_workers=workers, mp_context=context,
                               initializer=_start_worker,
                               initargs=(os.getpid(), int(death_signal), initializer,
                                         tuple(initargs)))


def stop_pool(pool, reap_seconds: float = REAP_SECONDS) -> None:
    """End ``pool`` now: kill its workers (SIGKILL), cancel what is queued, reap them.

    For a pool whose work is abandoned (an interrupt, an error): ``shutdown(wait=True)``
    would wait for the tasks running, and the interpreter's exit would wait for its
    manager thread, which waits for them. Killed, the workers' ends are seen by the manager
    thread, which marks the pool broken and ends.
    """
    if pool is None:
        return
    processes = list((getattr(pool, "_processes", None) or {}).values())
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            process.kill()
    with contextlib.suppress(Exception):
        pool.shutdown(wait=False, cancel_futures=True)
    deadline = time.monotonic() + reap_seconds
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AssertionError, AttributeError):
            process.join(max(0.0, deadline - time.monotonic()))


def watch_lifeline(fd: int, on_end) -> threading.Thread:
    """In a child: a daemon thread that blocks reading the lifeline ``fd`` and calls
    ``on_end()`` at its end-of-file (the parent process has ended, or closed its end to
    say the child is no longer wanted). Nothing is ever written on it."""

    def watch():
        try:
            while os.read(fd, 512):
                pass
        except OSError:
            pass
        on_end()

    thread = threading.Thread(target=watch, name="cadgen-lifeline", daemon=True)
    thread.start()
    return thread


def end_after(seconds: float = ORPHAN_GRACE_SECONDS) -> threading.Timer:
    """Kill this process after ``seconds`` (its process group with it when it leads one):
    the bound on an orphan's clean-up, which may be stuck where nothing interrupts it."""

    def end():
        if hasattr(os, "killpg") and os.getpgrp() == os.getpid():
            with contextlib.suppress(OSError):
                os.killpg(os.getpid(), signal.SIGKILL)
        os._exit(EXIT_ORPHANED)

    timer = threading.Timer(seconds, end)
    timer.daemon = True
    timer.start()
    return timer
