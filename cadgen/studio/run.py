"""Running the studio: ``cadgen studio`` (:func:`run_studio`) and a studio in a thread for tests.

The command line calls :func:`run_studio` through the public API (``cadgen.run_studio``):
it checks the file, binds the port, loads the math libraries single-threaded, announces
the URL and serves until Ctrl-C. fastapi and uvicorn are imported here, on start, so no
other command pays for them.
"""

from __future__ import annotations

import contextlib
import signal
import socket
import threading
import time
from collections.abc import Callable
from pathlib import Path

from cadgen.math_threads import single_threaded_math

__all__ = ["StudioPortError", "run_studio", "serve_in_thread", "single_threaded_math"]


class StudioPortError(OSError):
    """The studio cannot listen on the port asked for (in use, or not allowed)."""


def _listen(port: int) -> socket.socket:
    """A socket listening on 127.0.0.1:``port`` (0: a free one); StudioPortError if it cannot."""
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        listener.bind(("127.0.0.1", port))
        listener.listen(128)   # connections wait from now on, even before uvicorn takes them
    except OSError as exc:
        listener.close()
        hint = " (choose another --port)" if port else ""
        raise StudioPortError(exc.errno, f"cannot listen on 127.0.0.1:{port}: "
                                         f"{exc.strerror or exc}{hint}") from None
    return listener


def run_studio(file: str | Path | None = None, *, port: int = 0, open_browser: bool = True,
               output_root: str | Path = "outputs",
               announce: Callable[[str], None] = print) -> None:
    """Serve the studio on ``file`` (the bundled paper design if None) until Ctrl-C.

    Parameters
    ----------
    file : path, optional
        The parameter file to open; checked first (:class:`cadgen.ParameterError` or
        :class:`cadgen.MechanismError` when it has problems; a problem of a build stage,
        the cam's, does not stop the studio: the page shows it).
    port : int
        0 for a free port. :class:`StudioPortError` when it cannot be used.
    open_browser : bool
        Open the URL in the user's browser (``webbrowser``).
    output_root : path
        Where the page's builds write (``outputs/<name>/``), as ``cadgen build --output-dir``.
    announce : callable
        Receives the URL with its token once the port is bound.

    Raises KeyboardInterrupt again after a clean shutdown on Ctrl-C (uvicorn's way), so the
    caller reports the interruption.
    """
    single_threaded_math()   # before anything loads numpy (see its docstring)
    path = None
    if file is not None:
        from cadgen import load_params

        load_params(file)
        path = Path(file)
    listener = _listen(port)
    try:
        import uvicorn

        from cadgen.studio.server import create_app, new_token

        bound = listener.getsockname()[1]
        token = new_token()
        app = create_app(path, token=token, output_root=Path(output_root), port=bound)
        url = f"http://127.0.0.1:{bound}/?token={token}"
        announce(url)
        if open_browser:
            import webbrowser

            webbrowser.open(url)
        server = _server_class(uvicorn)(uvicorn.Config(
            app, log_level="warning", lifespan="on", access_log=False,
            timeout_graceful_shutdown=GRACEFUL_SHUTDOWN_SECONDS))
        server.run(sockets=[listener])
    finally:
        listener.close()


#: Seconds the server waits, once stopping, for requests still being answered (a slow
#: evaluation) before it cancels them.
GRACEFUL_SHUTDOWN_SECONDS = 2.0


def _server_class(uvicorn):
    """uvicorn's server, stopping the builds first when it stops: a build's event stream
    (an open request while the page watches the build) ends only with the build, and
    uvicorn waits for open requests before the app's own shutdown would stop it."""

    class StudioServer(uvicorn.Server):
        @contextlib.contextmanager
        def capture_signals(self):
            """uvicorn's (SIGINT, SIGTERM: a clean shutdown, then the signal raised again),
            and SIGHUP too (the terminal closed), unless it is ignored (``nohup``)."""
            with super().capture_signals():
                hangup = getattr(signal, "SIGHUP", None)
                if hangup is None or threading.current_thread() is not threading.main_thread() \
                        or signal.getsignal(hangup) is signal.SIG_IGN:
                    yield
                    return
                # put back before uvicorn raises the signals it caught, as it leaves
                previous = signal.signal(hangup, self.handle_exit)
                try:
                    yield
                finally:
                    signal.signal(hangup, previous)

        async def shutdown(self, sockets=None):
            import asyncio

            state = getattr(self.config.app.state, "studio", None)
            if state is not None and state.jobs is not None:
                await asyncio.to_thread(state.jobs.shutdown)
            await super().shutdown(sockets=sockets)

    return StudioServer


def serve_in_thread(path: Path | None = None, *, output_root: Path = Path("outputs"),
                    port: int = 0):
    """Run a studio on 127.0.0.1 in a thread (for tests): ``(url_with_token, stop)``."""
    import uvicorn

    from cadgen.studio.server import create_app, new_token

    token = new_token()
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind(("127.0.0.1", port))
    sock.listen(128)
    bound = sock.getsockname()[1]
    app = create_app(path, token=token, output_root=Path(output_root), port=bound)
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 10
    while not server.started and thread.is_alive() and time.monotonic() < deadline:
        time.sleep(0.02)

    def stop():
        server.should_exit = True
        thread.join(10)
        sock.close()

    return f"http://127.0.0.1:{bound}/?token={token}", stop
