"""Builds from the studio (cadgen.studio.builds) and their routes: a real build in a spawned
process, its progress events against the same build run in this process, replay, one build
at a time, a killed or stopped build, and the build's files served under the output root only.

The reference is :func:`cadgen.build` run here on the same parameters (its progress events,
its exit code, its summary) and the stage plan of :func:`cadgen.pipeline.build.plan`.
"""

import asyncio
import io
import json
import os
import re
import signal
import time
import tomllib
from pathlib import Path

import pytest

import cadgen
from cadgen.pipeline.build import plan
from cadgen.studio.builds import BuildBusy, BuildJobs, UnknownJob

REPO = Path(__file__).resolve().parents[1]
#: A scene that builds in about a second: metrics, their figures and the report page.
FAST_SCENE = {"effects": ["metrics", "plots", "report"], "preset": "draft"}
STATUS_OF_STATE = {"started": "start", "step": "step", "finished": "end"}


def fast_params() -> dict:
    data = tomllib.loads((REPO / "params" / "xin2024-planter.toml").read_text(encoding="utf-8"))
    data["scene"] = dict(FAST_SCENE)
    return data


async def _collect(stream, on_first_progress=None) -> list:
    events = []
    async for event in stream:
        if on_first_progress is not None and event["type"] == "progress":
            on_first_progress()
            on_first_progress = None
        events.append(event)
    return events


def collect(jobs: BuildJobs, job_id: str, on_first_progress=None) -> list:
    """Every event of the job, waiting for its end (at most a minute)."""
    return asyncio.run(asyncio.wait_for(
        _collect(jobs.events(job_id), on_first_progress), timeout=60))


def kill_group(pid: int) -> None:
    """SIGKILL the build's process group (the child and any worker it forked)."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except ProcessLookupError:
        os.kill(pid, signal.SIGKILL)


@pytest.fixture(scope="module")
def in_process(tmp_path_factory):
    """The same build in this process: (result, its progress events, the printer's lines)."""
    events, log = [], io.StringIO()
    printer = cadgen.ProgressPrinter(log, tty=False)

    def progress(event):
        events.append(event)
        printer(event)

    params = cadgen.validate_data(fast_params())
    result = cadgen.build(params, output_root=tmp_path_factory.mktemp("in-process"),
                          progress=progress)
    return result, events, log.getvalue().splitlines()


@pytest.fixture(scope="module")
def studio_build(tmp_path_factory):
    """A finished studio build: (jobs, job id, its events as a subscriber saw them live)."""
    jobs = BuildJobs(tmp_path_factory.mktemp("studio-outputs"))
    job_id = jobs.start(fast_params())
    events = collect(jobs, job_id)
    yield jobs, job_id, events
    jobs.shutdown()


# --------------------------------------------------------------------------- BuildJobs
def test_events_follow_the_stages_and_end_as_the_build_in_process(studio_build, in_process):
    jobs, job_id, events = studio_build
    result, reference, printed = in_process
    progress, done = events[:-1], events[-1]

    assert all(event["type"] == "progress" for event in progress)
    starts_and_ends = [(e["stage"], e["status"]) for e in progress if e["status"] != "step"]
    assert starts_and_ends == [(e.stage, STATUS_OF_STATE[e.state]) for e in reference
                               if e.state != "step"]
    stages, _ = plan(FAST_SCENE["effects"], "planting", "field")
    assert [stage for stage, status in starts_and_ends if status == "start"] \
        == [*stages, "write"]
    outcomes = {e["stage"]: e["outcome"] for e in progress if e["status"] == "end"}
    assert outcomes == {e.stage: e.status for e in reference if e.state == "finished"}
    assert [e["elapsed_s"] for e in progress] == sorted(e["elapsed_s"] for e in progress)
    # a stage's start and end say what `cadgen build` prints in a log, times and the output
    # folder aside (the steps of the figures interleave differently each run: two processes)
    def masked(lines):
        return [re.sub(r"\d+(\.\d+)?", "#", line) for line in lines if "] write:" not in line]
    assert masked(e["text"] for e in progress if e["status"] != "step") \
        == masked(line for line, e in zip(printed, reference, strict=True) if e.state != "step")

    assert done["type"] == "done"
    assert done["exit_code"] == result.exit_code
    assert done["error"] is None
    assert done["report"] == f"/files/{result.name}/report.html"
    assert (jobs.output_root / result.name / "report.html").is_file()
    assert done["glb"] is None        # no solids in this scene
    assert done["summary"].splitlines()[0] == result.summary_text().splitlines()[0]


@pytest.mark.parametrize("example", ["xin2024-planter", "kernel-b"])
def test_a_solids_build_links_its_assembly(tmp_path, example):
    data = tomllib.loads((REPO / "params" / f"{example}.toml").read_text(encoding="utf-8"))
    data["scene"] = {"effects": ["solids", "stl", "report"], "preset": "draft"}
    reference = cadgen.build(cadgen.validate_data(data), output_root=tmp_path / "in-process")
    jobs = BuildJobs(tmp_path / "studio")

    done = collect(jobs, jobs.start(data))[-1]

    jobs.shutdown()
    assert done["exit_code"] == reference.exit_code
    assert done["glb"] == f"/files/{example}/solids/assembly.glb"
    written = tmp_path / "studio" / example / "solids" / "assembly.glb"
    assert written.read_bytes() == (reference.output_dir / "solids" / "assembly.glb").read_bytes()


def _wait_for(condition, seconds: float = 30.0) -> bool:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


def _loaded(pid: int, *libraries: str) -> bool:
    """Whether the process has these extension modules mapped (Linux: /proc/PID/maps)."""
    try:
        maps = Path(f"/proc/{pid}/maps").read_text()
    except OSError:
        return False
    return all(library in maps for library in libraries)


@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="reads /proc/PID/maps")
def test_the_next_build_runs_in_a_child_made_ready_when_the_last_ended(tmp_path):
    """A studio build paid a fresh interpreter's start and the build's imports (about half of
    it): the next build's child is started once a build ends and imports them before its
    design comes. It builds what a fresh child builds; one that died is not used; the waiting
    child ends with the server."""
    jobs = BuildJobs(tmp_path)
    report = tmp_path / "xin2024-planter" / "report.json"
    try:
        first = collect(jobs, jobs.start(fast_params()))[-1]
        metrics = json.loads(report.read_text())["metrics"]
        assert _wait_for(lambda: jobs._spare is not None)
        spare = jobs._spare[0]
        # matplotlib's font renderer and fcl's bindings, loaded before any design came
        assert _wait_for(lambda: _loaded(spare.pid, "ft2font", "fcl"))
        job_id = jobs.start(fast_params())
        assert jobs.get(job_id).pid == spare.pid
        assert collect(jobs, job_id)[-1]["exit_code"] == first["exit_code"] == 0
        assert json.loads(report.read_text())["metrics"] == metrics
        # the next one dies waiting: the build after starts a child of its own
        assert _wait_for(lambda: jobs._spare is not None)
        dead = jobs._spare[0]
        kill_group(dead.pid)
        dead.wait()
        job_id = jobs.start(fast_params())
        assert jobs.get(job_id).pid != dead.pid
        assert collect(jobs, job_id)[-1]["exit_code"] == 0
        assert _wait_for(lambda: jobs._spare is not None)
        last = jobs._spare[0]
    finally:
        jobs.shutdown()
    assert last.returncode is not None and jobs._spare is None


def test_a_late_subscriber_replays_every_event(studio_build):
    jobs, job_id, events = studio_build
    assert collect(jobs, job_id) == events
    assert jobs.get(job_id).events == events
    assert jobs.get(job_id).done == events[-1]


def test_one_build_at_a_time_and_a_killed_build_ends_with_exit_3(tmp_path):
    jobs = BuildJobs(tmp_path)
    job_id = jobs.start(fast_params())
    pid = jobs.get(job_id).pid
    with pytest.raises(BuildBusy):
        jobs.start(fast_params())

    events = collect(jobs, job_id, on_first_progress=lambda: kill_group(pid))

    done = events[-1]
    assert done["type"] == "done" and done["exit_code"] == 3
    assert done["error"] == f"the build process died (signal {int(signal.SIGKILL)})"
    assert not (tmp_path / "xin2024-planter" / "report.html").exists()
    # the studio can build again
    assert jobs.start(fast_params()) != job_id
    jobs.shutdown()


def test_shutdown_stops_a_running_build(tmp_path):
    jobs = BuildJobs(tmp_path)
    job_id = jobs.start(fast_params())
    events = collect(jobs, job_id, on_first_progress=jobs.shutdown)
    assert events[-1]["exit_code"] == 130
    assert "stopped" in events[-1]["error"]
    process = jobs._jobs[job_id].process
    assert process.returncode is not None     # reaped, not left running


def test_bad_parameters_start_nothing(tmp_path):
    jobs = BuildJobs(tmp_path)
    data = fast_params()
    data["planter"]["L2"] = "long"
    with pytest.raises(cadgen.ParameterError) as refused:
        jobs.start(data)
    assert [p.path for p in refused.value.problems] == ["planter.L2"]
    assert jobs._jobs == {}
    assert list(tmp_path.iterdir()) == []


def test_a_scene_none_of_whose_effects_applies_starts_nothing(tmp_path):
    # what `cadgen build` refuses (exit 2) is refused here before a process starts
    jobs = BuildJobs(tmp_path)
    data = fast_params()
    data["scene"] = {"effects": ["ground_clearance"], "case": "bench"}
    with pytest.raises(cadgen.ParameterError) as refused:
        jobs.start(data)
    assert [(p.path, p.code) for p in refused.value.problems] == [("scene.effects",
                                                                   "nothing_to_build")]
    assert "a bench run has no soil" in refused.value.problems[0].message
    assert jobs._jobs == {}
    assert list(tmp_path.iterdir()) == []


def test_an_unknown_job(tmp_path):
    jobs = BuildJobs(tmp_path)
    with pytest.raises(UnknownJob):
        jobs.get("nope")
    with pytest.raises(KeyError):     # what the events route catches
        asyncio.run(_collect(jobs.events("nope")))


# --------------------------------------------------------------------------- the routes
TOKEN = "test-token-" + "x" * 20


@pytest.fixture
def client(monkeypatch, tmp_path):
    from fastapi.testclient import TestClient

    from cadgen.studio.server import create_app

    # a server error's crash file goes to the test's folder, not the user's temporary one
    monkeypatch.setenv("CADGEN_CRASH_DIR", str(tmp_path / "crashes"))

    design = tmp_path / "designs" / "xin2024-planter.toml"
    design.parent.mkdir()
    design.write_bytes((REPO / "params" / "xin2024-planter.toml").read_bytes())
    (tmp_path / "secret.txt").write_text("the secret outside the output root\n")
    app = create_app(design, token=TOKEN, output_root=tmp_path / "outputs")
    with TestClient(app, base_url="http://127.0.0.1") as test_client:
        yield test_client


def read_stream(client, url: str) -> list:
    events = []
    with client.stream("GET", url, params={"token": TOKEN}) as answer:
        assert answer.status_code == 200
        assert answer.headers["content-type"].startswith("text/event-stream")
        for line in answer.iter_lines():
            if line.startswith("data: "):
                events.append(json.loads(line[len("data: "):]))
    return events


def test_build_route_streams_the_events_and_serves_the_report(client, in_process):
    result, _, _ = in_process
    answer = client.post("/api/build", json={"params": fast_params()},
                         headers={"X-Cadgen-Token": TOKEN})
    assert answer.status_code == 202
    started = answer.json()
    assert started["events"] == f"/api/build/{started['job']}/events"

    events = read_stream(client, started["events"])

    assert events[-1]["type"] == "done"
    assert events[-1]["exit_code"] == result.exit_code
    assert [e for e in events if e["type"] == "progress"][0]["status"] == "start"
    report = client.get(events[-1]["report"], params={"token": TOKEN})
    assert report.status_code == 200
    on_disk = Path(client.app.state.studio.output_root) / result.name / "report.html"
    assert report.content == on_disk.read_bytes()
    assert client.get(events[-1]["report"]).status_code == 403      # no token
    # a replay of the finished build, as a page reloaded later sees it
    assert read_stream(client, started["events"]) == events


def test_build_route_refuses_a_second_build_and_bad_parameters(client):
    headers = {"X-Cadgen-Token": TOKEN}
    bad = fast_params()
    bad["planter"]["L2"] = -5.0
    answer = client.post("/api/build", json={"params": bad}, headers=headers)
    assert answer.status_code == 422
    assert [p["path"] for p in answer.json()["problems"]] == ["planter.L2"]

    first = client.post("/api/build", json={"params": fast_params()}, headers=headers)
    assert first.status_code == 202
    assert client.post("/api/build", json={"params": fast_params()},
                       headers=headers).status_code == 409
    read_stream(client, first.json()["events"])     # let it end before the next test
    assert client.get("/api/build/nope/events", params={"token": TOKEN}).status_code == 404


@pytest.mark.parametrize("path", [
    "/files/../secret.txt", "/files/%2e%2e/secret.txt", "/files/..%2fsecret.txt",
    "/files/%2e%2e%2f%2e%2e%2fetc/passwd", "/files//etc/passwd", "/files/%2fetc%2fpasswd",
    "/files/xin2024-planter/../../secret.txt", "/files/..\\secret.txt",
    "/files/%00secret.txt",
])
def test_files_never_served_from_outside_the_output_root(client, path):
    (Path(client.app.state.studio.output_root) / "xin2024-planter").mkdir(parents=True)
    answer = client.get(path, params={"token": TOKEN})
    assert 400 <= answer.status_code < 500
    assert b"the secret" not in answer.content
    assert b"root:" not in answer.content
