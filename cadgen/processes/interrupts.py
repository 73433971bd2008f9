"""Ctrl-C that always stops a command: one line, exit 130, nothing half-written.

SIGTERM (a service manager, ``kill``, a CI runner's time limit) and SIGHUP (the terminal
closed) are taken the same way (:data:`INTERRUPT_SIGNALS`): the command stops as on
Ctrl-C and exits 128 + the signal's number (143, 129).

Python turns SIGINT into a KeyboardInterrupt raised wherever the main thread happens to be.
Most of the time that unwinds the command, its staged outputs are removed on the way and
the command line says ``cadgen: interrupted``. But the interrupt can land where a library
catches it: trimesh wraps its optional imports in ``except BaseException`` (114 places),
and a finaliser cannot raise at all. Then the exception is gone and the build used to run
to its end, write every file, and only then report the interrupt.

:class:`Interrupts` (the command line's, for the whole command) therefore remembers the
interrupt and, until the command has stopped, raises it again every
:data:`REPEAT_SECONDS` from a watchdog thread (``_thread.interrupt_main``, which runs the
handler in the main thread) whenever the main thread is not already unwinding or handling
an exception: a cleanup (``finally``, ``__exit__``, an ``except`` block) is never cut
short, and an interrupt that was swallowed is raised again a tenth of a second later, in
code that lets it through.

:func:`sigint_deferred` is for starting child processes: a child spawned while SIGINT is
blocked inherits the block, and a signal that comes while it is still importing waits for
it to install its own handler (:func:`release_deferred_sigint`) instead of printing a
KeyboardInterrupt traceback from ``multiprocessing/spawn.py``. The parent's own pending
signal is delivered the moment the block ends, so nothing is lost.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["Interrupts", "REPEAT_SECONDS", "EXIT_INTERRUPTED", "INTERRUPT_SIGNALS",
           "interrupted_status", "sigint_deferred", "release_deferred_sigint"]

#: Exit status of an interrupted command (128 + SIGINT, the shell's convention).
EXIT_INTERRUPTED = 128 + signal.SIGINT
#: The signals that stop a command as Ctrl-C does: SIGINT, SIGTERM and SIGHUP (where the
#: platform has it). A command exits with :func:`interrupted_status` of the one that came.
INTERRUPT_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                          if hasattr(signal, name))
#: How often an interrupt that did not stop the command is raised again (s).
REPEAT_SECONDS = 0.1
#: How many :func:`sigint_deferred` blocks are open: while one is, the handler only remembers
#: an interrupt (a signal blocked in the main thread may still be taken by another thread,
#: whose Python handler then runs in the main thread), and the watchdog raises it after.
_DEFERRING = [0, False]   # [blocks open, an interrupt remembered meanwhile]


class Interrupts:
    """While a command runs: Ctrl-C becomes a KeyboardInterrupt that cannot be lost.

    Installs a SIGINT handler on the main thread (unless SIGINT is ignored, as in a
    background job started with ``nohup`` or ``&`` from a non-interactive shell) that
    remembers the interrupt and raises KeyboardInterrupt in this process, into code that
    runs normally: a second Ctrl-C that comes while the first unwinds (a ``finally``, an
    ``__exit__``, an ``except`` block removing staged outputs) does not cut that short.
    Until :attr:`stopping` is set (the command has caught the interrupt and is ending),
    and while ``active()`` says so, a watchdog raises it again whenever it was swallowed
    (see the module docstring). A process forked from this one (the build's worker beside
    its teeth) inherits the handler and ends at once, quietly, with
    :data:`EXIT_INTERRUPTED`: the terminal signals the whole process group, and this
    process reports it once. A KeyboardInterrupt that Python cannot raise (it landed in a
    finaliser) is not printed; it is remembered and raised again.

    Parameters
    ----------
    repeat_seconds : float
        How often a swallowed interrupt is raised again.
    active : callable, optional
        Raise only while ``active()`` is true (a batch worker: while it runs a design; an
        idle one only remembers). Default: always, until :attr:`stopping`.
    signals : tuple of int
        The signals taken as an interrupt (default :data:`INTERRUPT_SIGNALS`; the
        studio's build process is stopped by SIGTERM only). :attr:`signal` is the first
        that came.
    on_signal : callable, optional
        Called with the signal's number first thing in the handler (in this process, not
        a forked one): a batch worker ends there when its parent has died and it holds no
        design (:mod:`cadgen.processes.lifeline`).
    """

    def __init__(self, repeat_seconds: float = REPEAT_SECONDS, *, active=None,
                 signals: tuple = INTERRUPT_SIGNALS, on_signal=None):
        self.owner = os.getpid()
        self._on_signal = on_signal
        self.signals = tuple(signals)
        self.signal: int | None = None
        self.seen = False
        self.stopping = False
        self.repeat_seconds = repeat_seconds
        self._active = active
        self._previous: dict = {}
        self._previous_hook = None
        self._watchdog: threading.Thread | None = None
        self._ended = threading.Event()
        self._lock = threading.RLock()

    def _raising(self) -> bool:
        return (not self.stopping and not _DEFERRING[0]
                and (self._active is None or bool(self._active())))

    # -- the handler, in the main thread
    def _handle(self, signum, frame):
        if os.getpid() != self.owner:
            os._exit(128 + signum)   # a forked worker: its parent reports the interrupt
        if self._on_signal is not None:
            self._on_signal(signum)
        self.seen = True
        self.signal = self.signal or signum
        self._watch()
        if _DEFERRING[0] and not self.stopping:
            # raised as the block ends (sigint_deferred), if it would be raised now
            _DEFERRING[1] = self._active is None or bool(self._active())
        elif (self._raising() and sys.exc_info()[1] is None   # else unwinding: let it
              and not _initialising_extension(frame)):   # else the watchdog's next try
            _DEFERRING[1] = False
            raise KeyboardInterrupt

    def _unraisable(self, unraisable):
        if issubclass(unraisable.exc_type, KeyboardInterrupt):
            self.seen = True            # the watchdog raises it again where it can be
            self._watch()
            return
        self._previous_hook(unraisable)

    # -- the watchdog
    def _watch(self) -> None:
        # re-entrant: a second signal's handler may run inside this one (between any two
        # bytecodes), and a finaliser may call it from another thread
        with self._lock:
            if self._watchdog is None:
                watchdog = threading.Thread(target=self._repeat, name="cadgen-interrupt",
                                            daemon=True, args=(threading.main_thread().ident,))
                if self._watchdog is None:   # (not made by a handler nested in this one)
                    self._watchdog = watchdog
                    watchdog.start()

    def _repeat(self, main: int) -> None:
        import _thread

        while not self._ended.wait(self.repeat_seconds):
            if self.stopping:
                return
            # the main thread is unwinding or in an except block (the interrupt on its way,
            # or a cleanup): let it finish; raise only into code running normally
            if self._raising() and _handling(main) is None:
                _thread.interrupt_main(self.signal or self.signals[0])

    # -- the context
    def install(self) -> Interrupts:
        """Install the handler (as entering the context does) for the process's life: on
        each of :attr:`signals` not ignored (a background job's SIGINT, say)."""
        self._previous = {}
        if threading.current_thread() is threading.main_thread():
            for signum in self.signals:
                if signal.getsignal(signum) is not signal.SIG_IGN:
                    self._previous[signum] = signal.signal(signum, self._handle)
        self._previous_hook = sys.unraisablehook
        sys.unraisablehook = self._unraisable
        return self

    def __enter__(self) -> Interrupts:
        return self.install()

    def __exit__(self, *exc_info) -> bool:
        self.stopping = True
        self._ended.set()
        if self._watchdog is not None and self._watchdog is not threading.current_thread():
            # an interrupt it raised just before it stopped is pending: taken by this
            # handler (which only remembers it now), not by the one put back below
            self._watchdog.join(1.0)
            _take_pending_signals()
        sys.unraisablehook = self._previous_hook
        for signum, previous in self._previous.items():
            signal.signal(signum, previous)
        return False


def interrupted_status(signum: int | None) -> int:
    """The exit status of a command stopped by ``signum``: 128 + its number (the shell's
    convention: 130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP); 130 if unknown."""
    return 128 + int(signum or signal.SIGINT)


def _initialising_extension(frame) -> bool:
    """Whether ``frame`` runs inside the initialisation of a compiled extension module.

    An extension built with pybind11 or nanobind (manifold3d, say) may run Python code as it
    initialises (importing numpy); an exception raised there, an interrupt included, cannot
    leave the C++ initialiser, and the process aborts ("terminate called after throwing an
    instance of 'nanobind::python_error'"). Seen from Python, such code runs below the
    import system's ``create_module`` or ``exec_module`` of an ``ExtensionFileLoader``.
    """
    while frame is not None:
        code = frame.f_code
        if (code.co_name in ("create_module", "exec_module")
                and code.co_filename.startswith("<frozen importlib")
                and type(frame.f_locals.get("self")).__name__ == "ExtensionFileLoader"):
            return True
        frame = frame.f_back
    return False


def _take_pending_signals() -> None:
    """A Python call: the interpreter runs the handlers of signals pending in this thread
    at a call's start (its eval breaker)."""


def _handling(thread: int) -> BaseException | None:
    """The exception the thread ``thread`` is handling or unwinding with, or None."""
    current = sys._current_exceptions().get(thread)
    if isinstance(current, tuple):   # Python 3.11: (type, value, traceback), Nones if none
        current = current[1]
    return current


@contextmanager
def sigint_deferred() -> Iterator[None]:
    """Hold Ctrl-C back in this thread while the block runs: a block that must be done
    whole or not at all (child processes started, a folder made and named, a swap).
    Every one of :data:`INTERRUPT_SIGNALS` is held back, SIGTERM and SIGHUP as SIGINT.

    A child started meanwhile (fork, or fork and exec) inherits the block: a Ctrl-C that
    reaches it before it has installed its handler stays pending until it calls
    :func:`release_deferred_sigint`. This thread's own pending SIGINT is delivered when
    the block ends; one that another thread took meanwhile is remembered by
    :class:`Interrupts` and raised here as the block ends (so nothing the block makes is
    left half made: a semaphore registered but never given its finaliser leaks). The
    blocking does nothing where signals cannot be blocked (not POSIX). In a
    thread other than the main one (where Python raises no interrupt) it only blocks.
    """
    blocking = hasattr(signal, "pthread_sigmask")
    main = threading.current_thread() is threading.main_thread()
    previous = (signal.pthread_sigmask(signal.SIG_BLOCK, set(INTERRUPT_SIGNALS)) if blocking
                else None)
    if main:   # (a signal another thread takes runs the handler here all the same)
        _DEFERRING[0] += 1
    try:
        yield
    finally:
        if main:
            _DEFERRING[0] -= 1
        if blocking:   # this thread's pending SIGINT is handled here, raising
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        if main and _DEFERRING[1] and not _DEFERRING[0]:   # one another thread took meanwhile
            _DEFERRING[1] = False
            raise KeyboardInterrupt


def release_deferred_sigint() -> None:
    """In a child started under :func:`sigint_deferred`, once its handler is in place:
    unblock the interrupt signals, so one that came meanwhile reaches the handler now."""
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(INTERRUPT_SIGNALS))
