"""The studio's web server: the app factory, its guards and its routes.

Routes (see docs/studio.md for the answers' shapes):

- ``GET /`` and ``GET /static/...``: the page (no token: they hold no data);
  ``/static/vendor/three-viewer.min.js`` is the report's vendored three.js build, served
  from ``cadgen/report/vendor`` (one copy in the repository), ``/static/vendor/explode.js``
  the report's explode slider's helpers (``cadgen/report/explode.js``);
- ``GET /api/design``, ``GET /api/schema``, ``POST /api/evaluate``, ``POST /api/save``,
  ``POST /api/build``, ``GET /api/build/<id>/events`` and ``GET /files/<path>`` (the build
  outputs under the output root): each needs the token.

The guards sit in one ASGI middleware in front of everything (:class:`_Guard`), so no
route can forget them: the Host header must name this server on the loopback interface
(a web page elsewhere cannot reach it by DNS rebinding), ``/api`` and ``/files`` need the
token in ``X-Cadgen-Token`` or ``?token=`` (EventSource and links cannot set headers),
and a body is read whole, at most :data:`MAX_BODY_BYTES`, before any route sees it (a
``Content-Length`` over the limit is refused unread; a body streamed without one is cut
off at the limit). Every error answer is JSON ``{"error", "field"}``; an unexpected
exception is a 500 whose traceback goes to a crash file (as the command line does),
never to the client.

Evaluation is CPU-bound and the models' caches are not thread-safe to fill: it runs
one at a time under a lock, in a worker thread so the event loop keeps serving.
"""

# no ``from __future__ import annotations``: FastAPI reads the routes' annotations (Request,
# imported inside create_app) at definition time
import json
import logging
import secrets
import threading
from pathlib import Path
from urllib.parse import parse_qs

from cadgen.crash import one_line, write_crash_file


__all__ = ["MAX_BODY_BYTES", "MAX_ARRAY_ITEMS", "MAX_NESTING", "create_app", "new_token"]

#: The largest request body read (bytes): a parameter file is a few kB.
MAX_BODY_BYTES = 1 << 20
#: The longest array a parameter may hold in a request (no parameter has more than a few
#: dozen items: type-value points, plant spacings, inclinations); a longer one is refused
#: before validation, which would otherwise list a problem per item or design a loop
#: through thousands of points.
MAX_ARRAY_ITEMS = 256
#: The deepest nesting of tables and arrays in a request's parameters (the deepest
#: parameter is an array of [x, y] pairs inside a table: depth 3).
MAX_NESTING = 8
#: Host names the server answers to (it binds the loopback interface only).
LOOPBACK_HOSTS = ("127.0.0.1", "localhost")

_STATIC = Path(__file__).with_name("static")
_THREE_VIEWER = Path(__file__).parent.parent / "report" / "vendor" / "three-viewer.min.js"
_EXPLODE = Path(__file__).parent.parent / "report" / "explode.js"

log = logging.getLogger("cadgen.studio")


def new_token() -> str:
    """A fresh random token for one server run (as Jupyter's)."""
    return secrets.token_urlsafe(32)


# --------------------------------------------------------------------------- errors
class RequestProblem(Exception):
    """A bad request: answered ``{"error": message, "field": field}`` with ``status``."""

    def __init__(self, status: int, field: str, message: str, **extra):
        super().__init__(message)
        self.status, self.field, self.message, self.extra = status, field, message, extra


def _error_body(message: str, field: str = "body", **extra) -> bytes:
    return json.dumps({"error": message, "field": field, **extra}).encode()


async def _send_json(send, status: int, body: bytes) -> None:
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"),
                            (b"content-length", str(len(body)).encode()),
                            (b"cache-control", b"no-store")]})
    await send({"type": "http.response.body", "body": body})


def problems_answer(problems, error=None) -> dict:
    """:func:`cadgen.studio.payload.problems_answer`, imported when needed (it loads numpy,
    which :func:`single_threaded_math` must load first)."""
    from cadgen.studio.payload import problems_answer as answer

    return answer(problems, error)


def _crash_file(error: BaseException, what: str) -> str:
    """Save the traceback the way the command line does; the sentence for the client."""
    try:
        saved = f"traceback saved to {write_crash_file(error, ['studio', what])}"
    except Exception as exc:   # the crash file must never hide the crash
        saved = f"the traceback could not be saved: {one_line(exc, 120)}"
    log.error("cadgen studio: internal error in %s: %s: %s (%s)", what, type(error).__name__,
              one_line(error), saved)
    return f"internal error: {type(error).__name__} ({saved}; please report it)"


# --------------------------------------------------------------------------- the guard
class _Guard:
    """ASGI middleware: Host check, token, body size; buffers the body for the routes."""

    def __init__(self, app, *, token: str, state):
        self.app, self.token, self.state = app, token, state

    def _host_ok(self, headers: dict) -> bool:
        host = headers.get(b"host", b"").decode("latin-1").strip().lower()
        name, _, port = host.rpartition(":") if host.count(":") == 1 else (host, "", "")
        if name not in LOOPBACK_HOSTS:
            return False
        expected = self.state.port
        # the port is known once the server is bound; a test client without one sends none
        return expected is None or port == str(expected)

    def _token_ok(self, scope, headers: dict) -> bool:
        given = headers.get(b"x-cadgen-token", b"").decode("latin-1")
        if not given:
            query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
            given = (query.get("token") or [""])[0]
        return bool(given) and secrets.compare_digest(given.encode(), self.token.encode())

    async def _inner(self, scope, receive, send):
        """The app; an exception it lets through is a 500 JSON answer and a crash file (not
        Starlette's error page, and not a traceback on the server's console either)."""
        started = False

        async def sending(message):
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, receive, sending)
        except Exception as error:
            if started:   # too late for an answer: the connection is closed, still on file
                _crash_file(error, f"{scope.get('method')} {scope.get('path')}")
                return
            body = json.dumps({"error": _crash_file(error, f"{scope.get('method')} "
                                                           f"{scope.get('path')}"),
                               "field": None}).encode()
            await _send_json(send, 500, body)

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        headers = dict(scope.get("headers") or [])
        if not self._host_ok(headers):
            return await _send_json(send, 400, _error_body(
                "the Host header must name this server on 127.0.0.1 or localhost "
                "(requests relayed from another site name are refused)", "host"))
        path = scope.get("path", "")
        if path.startswith(("/api/", "/files/")) or path in ("/api", "/files"):
            if not self._token_ok(scope, headers):
                return await _send_json(send, 403, _error_body(
                    "a missing or wrong token: use the URL the studio printed "
                    "(?token=...) or the X-Cadgen-Token header", "token"))
        if scope.get("method") in ("GET", "HEAD", "OPTIONS", "DELETE"):
            return await self._inner(scope, receive, send)
        declared = headers.get(b"content-length")
        if declared is not None:
            try:
                length = int(declared)
            except ValueError:
                return await _send_json(send, 400, _error_body(
                    "the Content-Length header is not a number", "body"))
            if length > MAX_BODY_BYTES:
                return await _send_json(send, 413, _error_body(
                    f"the body of {length} bytes is over the limit of {MAX_BODY_BYTES} bytes",
                    "body"))
        chunks, size = [], 0
        while True:
            message = await receive()
            if message["type"] == "http.disconnect":
                return
            chunk = message.get("body", b"")
            size += len(chunk)
            if size > MAX_BODY_BYTES:   # streamed past the limit, or longer than declared
                return await _send_json(send, 413, _error_body(
                    f"the body is over the limit of {MAX_BODY_BYTES} bytes", "body"))
            chunks.append(chunk)
            if not message.get("more_body", False):
                break
        body = b"".join(chunks)
        delivered = False

        async def replay():
            nonlocal delivered
            if not delivered:
                delivered = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()

        return await self._inner(scope, replay, send)


# --------------------------------------------------------------------------- request bodies
def _shape_problem(data):
    """``(path, message)`` for parameters nested or sized beyond any real file, else None.

    The path is dotted like the validator's (``field.plant_spacings``; ``params`` for the
    whole). Walks without recursion (the data may nest as deep as the JSON reader allowed).
    """
    stack = [("", data, 0)]
    while stack:
        path, value, depth = stack.pop()
        if depth > MAX_NESTING:
            return path or "params", (f"nested {depth} levels deep; no parameter nests deeper "
                                      "than an array of [x, y] pairs in a table")
        if isinstance(value, dict):
            stack += [(f"{path}.{key}" if path else str(key), item, depth + 1)
                      for key, item in value.items()]
        elif isinstance(value, list):
            if len(value) > MAX_ARRAY_ITEMS:
                return path or "params", (f"an array of {len(value)} items; the studio takes at "
                                          f"most {MAX_ARRAY_ITEMS} (no parameter has more than a "
                                          "few dozen)")
            stack += [(f"{path}.{index}" if path else str(index), item, depth + 1)
                      for index, item in enumerate(value)]
    return None


def _read_json_object(body: bytes) -> dict:
    """The request body as a JSON object, or a :class:`RequestProblem` naming what is wrong.

    Python's reader accepts NaN and Infinity: they are left for the parameter validator,
    which names their field (``not_finite``).
    """
    if not body.strip():
        raise RequestProblem(400, "body", "the request has no body: send a JSON object")
    try:
        data = json.loads(body)
    except RecursionError:
        raise RequestProblem(400, "body", "the JSON is nested too deeply to read") from None
    except UnicodeDecodeError:
        raise RequestProblem(400, "body", "the body is not UTF-8 text") from None
    except ValueError as exc:   # JSONDecodeError, and int()'s digit limit
        raise RequestProblem(400, "body", f"the body is not valid JSON: {exc}") from None
    if not isinstance(data, dict):
        raise RequestProblem(422, "body", f"the body must be a JSON object, not "
                                          f"{_json_type(data)}")
    return data


def _json_type(value) -> str:
    """The JSON type of a parsed value with its article: ``"an array"``, ``"a number"``."""
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    return {str: "a string", list: "an array", dict: "an object", type(None): "null"}[type(value)]


def _params_of(data: dict) -> dict:
    if "params" not in data:
        raise RequestProblem(422, "params", 'the body has no "params": send '
                                            '{"params": {...the file\'s tables...}}')
    params = data["params"]
    if not isinstance(params, dict):
        raise RequestProblem(422, "params", f'"params" must be an object (the file\'s tables), '
                                            f"not {_json_type(params)}")
    shape = _shape_problem(params)
    if shape is not None:
        raise RequestProblem(422, *shape, problems=[{"path": shape[0], "code": "too_large",
                                                     "message": shape[1], "stage": None}])
    return params


# --------------------------------------------------------------------------- the app
class _State:
    """What the routes share: the opened file, its folder, the port once bound, the jobs."""

    def __init__(self, path: Path | None, output_root: Path):
        self.path = None if path is None else Path(path).resolve()
        self.folder = self.path.parent if self.path is not None else Path.cwd().resolve()
        self.output_root = Path(output_root)
        self.port: int | None = None
        self.evaluate_lock = threading.Lock()
        self.jobs = None
        self.jobs_lock = threading.Lock()

    def build_jobs(self):
        with self.jobs_lock:
            if self.jobs is None:
                from cadgen.studio.builds import BuildJobs

                self.jobs = BuildJobs(self.output_root)
            return self.jobs


def create_app(path: Path | None, *, token: str, output_root: Path, port: int | None = None):
    """The studio's ASGI app (FastAPI) for the design at ``path`` (None: the bundled one).

    Parameters
    ----------
    path : Path or None
        The opened parameter file; saves go beside it. None opens the bundled paper
        design (read-only: saving needs a new name, written in the working directory).
    token : str
        The secret every ``/api`` and ``/files`` request must carry (:func:`new_token`).
    output_root : Path
        Where builds write (``<output_root>/<name>/``) and ``/files`` serves from.
    port : int, optional
        The port the Host header must name; set later as ``app.state.studio.port`` once
        the server is bound (until then any port on a loopback name is accepted).
    """
    from contextlib import asynccontextmanager

    from fastapi import FastAPI, Request
    from fastapi.exceptions import RequestValidationError
    from fastapi.responses import FileResponse, JSONResponse, StreamingResponse
    from starlette.concurrency import run_in_threadpool
    from starlette.exceptions import HTTPException as StarletteHTTPException
    from starlette.staticfiles import StaticFiles

    state = _State(path, output_root)
    state.port = port

    @asynccontextmanager
    async def lifespan(app):
        yield
        if state.jobs is not None:   # a build still running is stopped with the server
            state.jobs.shutdown()

    app = FastAPI(title="cadgen studio", docs_url=None, redoc_url=None, openapi_url=None,
                  lifespan=lifespan)
    app.state.studio = state

    def problem_response(problem: RequestProblem):
        return JSONResponse({"error": problem.message, "field": problem.field, **problem.extra},
                            status_code=problem.status)

    @app.exception_handler(RequestProblem)
    async def _request_problem(request, exc: RequestProblem):
        return problem_response(exc)

    @app.exception_handler(StarletteHTTPException)
    async def _http_error(request, exc):
        messages = {404: f"nothing at {request.url.path}",
                    405: f"{request.method} is not allowed on {request.url.path}"}
        return JSONResponse({"error": messages.get(exc.status_code, str(exc.detail)),
                             "field": "path" if exc.status_code in (404, 405) else "body"},
                            status_code=exc.status_code, headers=getattr(exc, "headers", None))

    @app.exception_handler(RequestValidationError)
    async def _validation_error(request, exc):
        errors = exc.errors()
        first = errors[0] if errors else {}
        field = ".".join(str(p) for p in first.get("loc", ())) or "body"
        return JSONResponse({"error": first.get("msg", "invalid request"), "field": field},
                            status_code=422)

    async def body_object(request: Request) -> dict:
        return _read_json_object(await request.body())

    # ---------------------------------------------------------------- the page
    @app.get("/", include_in_schema=False)
    async def index():
        page = _STATIC / "index.html"
        if not page.is_file():
            raise StarletteHTTPException(404)
        return FileResponse(page, headers={"cache-control": "no-cache"})

    @app.get("/static/vendor/three-viewer.min.js", include_in_schema=False)
    async def three_viewer():
        return FileResponse(_THREE_VIEWER, media_type="text/javascript")

    @app.get("/static/vendor/explode.js", include_in_schema=False)
    async def explode_helpers():
        return FileResponse(_EXPLODE, media_type="text/javascript")

    # ---------------------------------------------------------------- the API
    @app.get("/api/design")
    async def get_design():
        from cadgen import ParameterError

        try:
            from cadgen.studio.payload import design_answer

            return await run_in_threadpool(design_answer, state.path, state.folder)
        except ParameterError as exc:
            return JSONResponse(problems_answer(exc.problems), status_code=422)
        except OSError as exc:
            raise RequestProblem(404, "path", f"cannot read {state.path}: "
                                              f"{exc.strerror or exc}") from None
        except UnicodeDecodeError:
            raise RequestProblem(422, "path", f"{state.path} is not UTF-8 text") from None

    @app.get("/api/schema")
    async def get_schema():
        from cadgen.studio.schema import studio_schema

        return studio_schema()

    @app.post("/api/evaluate")
    async def post_evaluate(request: Request):
        params = _params_of(await body_object(request))

        def run():
            with state.evaluate_lock:
                try:
                    from cadgen.studio.payload import evaluate_request

                    return evaluate_request(params)
                except Exception as exc:   # a bug: the traceback to a file, not to the client
                    return 500, {"ok": False, "error": _crash_file(exc, "POST /api/evaluate"),
                                 "field": None, "problems": []}

        status, answer = await run_in_threadpool(run)
        return JSONResponse(answer, status_code=status)

    @app.post("/api/save")
    async def post_save(request: Request):
        from cadgen import ParameterError

        data = await body_object(request)
        params = _params_of(data)
        name = data.get("as")
        if name is not None and not isinstance(name, str):
            raise RequestProblem(400, "as", f'"as" must be a file name or null, not '
                                            f"{_json_type(name)}")
        overwrite = data.get("overwrite", False)
        if not isinstance(overwrite, bool):
            raise RequestProblem(400, "overwrite", '"overwrite" must be true or false')
        from cadgen import MechanismError
        from cadgen.studio.save import SaveError, save_design

        def run():
            with state.evaluate_lock:   # validation fills the same caches as evaluation
                return save_design(params, original=state.path, folder=state.folder,
                                   name=name, overwrite=overwrite)
        try:
            written = await run_in_threadpool(run)
        except SaveError as exc:
            raise RequestProblem(exc.status, exc.field, exc.message) from None
        except ParameterError as exc:
            return JSONResponse(problems_answer(exc.problems, "the parameters do not validate: "
                                                 "nothing written"), status_code=422)
        except MechanismError as exc:   # a check that could not finish: still the design's
            raise RequestProblem(422, "params", " ".join(str(exc).split())) from None
        # the design saved under a new name is the one open from now on (as in an editor)
        state.path = Path(written).resolve()
        state.folder = state.path.parent
        return {"path": str(state.path)}

    @app.post("/api/build", status_code=202)
    async def post_build(request: Request):
        from cadgen import ParameterError
        from cadgen.studio.builds import BuildBusy

        params = _params_of(await body_object(request))
        jobs = state.build_jobs()

        def start():
            with state.evaluate_lock:   # start() validates: the same caches as evaluation
                return jobs.start(params)
        try:
            job = await run_in_threadpool(start)
        except BuildBusy as exc:
            raise RequestProblem(409, "build", str(exc) or "a build is already running") from None
        except ParameterError as exc:
            return JSONResponse(problems_answer(exc.problems), status_code=422)
        return JSONResponse({"job": job, "events": f"/api/build/{job}/events"}, status_code=202)

    @app.get("/api/build/{job}/events")
    async def build_events(job: str):
        jobs = state.jobs
        if jobs is None:
            raise RequestProblem(404, "job", f"no build {job!r}")
        stream = jobs.events(job).__aiter__()
        try:
            first = await stream.__anext__()   # an unknown job fails here, before the stream
        except KeyError:
            raise RequestProblem(404, "job", f"no build {job!r}") from None
        except StopAsyncIteration:
            first = None

        async def lines():
            if first is not None:
                yield f"data: {json.dumps(first)}\n\n"
            async for event in stream:
                yield f"data: {json.dumps(event)}\n\n"

        return StreamingResponse(lines(), media_type="text/event-stream",
                                 headers={"cache-control": "no-store", "x-accel-buffering": "no"})

    @app.get("/files/{file_path:path}")
    async def files(file_path: str):
        root = state.output_root.resolve()
        missing = RequestProblem(404, "path", f"no file {file_path!r} under the output folder")
        try:   # resolve() follows links: a link out of the root is outside it
            target = (root / file_path).resolve()
            if not target.is_relative_to(root) or not target.is_file():
                raise missing
        except (OSError, ValueError):   # a NUL byte, a name too long
            raise missing from None
        return FileResponse(target)

    app.mount("/static", StaticFiles(directory=_STATIC, check_dir=False), name="static")
    # outermost but for Starlette's error middleware: every request passes the guard first
    app.add_middleware(_Guard, token=token, state=state)
    return app

# --------------------------------------------------------------------------- running it
