"""The studio's server (cadgen.studio.server) through FastAPI's TestClient, and its command.

Truths come from elsewhere: the metrics and report sections from ``cadgen build
--effects metrics`` (report.json), the animation from the kinematic model
(``PlantingMechanism``) and the cam design, the schema from the pydantic models.
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tomllib
import urllib.request
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

warnings.filterwarnings("ignore", message=".*httpx.*")   # starlette: "install httpx2"
from fastapi.testclient import TestClient  # noqa: E402

from cadgen.studio.server import MAX_BODY_BYTES, create_app  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((REPO / "params").glob("*.toml"))
PLANTING = REPO / "params" / "xin2024-planter.toml"
TOKEN = "test-token"
HEADERS = {"X-Cadgen-Token": TOKEN}


def _load(path: Path) -> dict:
    return tomllib.loads(path.read_text(encoding="utf-8"))


def _nan_to_none(value):
    """report.json writes NaN (Python's json); the API sends null: compare them as equal."""
    if isinstance(value, dict):
        return {k: _nan_to_none(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_nan_to_none(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    app = create_app(PLANTING, token=TOKEN, output_root=tmp_path_factory.mktemp("outputs"))
    with TestClient(app, base_url="http://127.0.0.1", raise_server_exceptions=False) as client:
        yield client


def evaluate(client, params, **kwargs):
    return client.post("/api/evaluate", json={"params": params}, headers=HEADERS, **kwargs)


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """report.json of ``cadgen build --effects metrics`` for every bundled example."""
    from cadgen.cli import main

    root = tmp_path_factory.mktemp("reference")
    out = {}
    for path in EXAMPLES:
        status = main(["build", str(path), "--effects", "metrics", "--output-dir", str(root)])
        assert status in (0, 1)
        name = _load(path)["name"]
        out[path.name] = json.loads((root / name / "report.json").read_text(encoding="utf-8"))
    return out


@pytest.fixture(scope="module")
def planting_answer(client):
    response = evaluate(client, _load(PLANTING))
    assert response.status_code == 200, response.text
    return response.json()


# --------------------------------------------------------------------------- the CLI's figures
@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_evaluate_matches_the_cli_metrics_build(client, reports, path):
    report = reports[path.name]
    response = evaluate(client, _load(path))
    assert response.status_code == 200, response.text
    answer = response.json()
    assert answer["ok"] is True and answer["problems"] == []
    assert answer["kind"] == report["mechanism"]
    warnings_sent = [(w["path"], w["code"], w["message"], w["stage"]) for w in answer["warnings"]]
    assert warnings_sent == [(w["path"], w["code"], w["message"], w.get("stage"))
                             for w in report["warnings"]]
    if report["mechanism"] == "planting":
        for section in ("metrics", "events", "derived"):
            assert answer[section] == _nan_to_none(report[section]), section
        assert [m["key"] for m in answer["margins"]] == [m["key"] for m in report["metrics"]]
    else:
        for section in ("verified", "findings", "linkage", "gears", "verification", "field"):
            assert answer["report"][section] == _nan_to_none(report[section]), section


def test_uncuttable_pricking_design_still_evaluates_and_says_why(client, reports):
    answer = evaluate(client, _load(REPO / "params" / "kernel-a.toml")).json()
    codes = {finding["code"] for finding in answer["report"]["findings"]}
    assert "concave_pitch_curve" in codes
    concave = [curve for curve in answer["pitch_curves"] if not curve["convex"]]
    assert concave and all(curve["concave"] for curve in concave)
    # the ranges (from the report's stretches, found on the analytic curvature) are where the
    # drawn curve itself turns the other way: its turn at each sample, measured here on the
    # design's unrounded table (the answer's points are those, to 0.01 mm)
    from cadgen.design import pricking_design
    from cadgen.params import load_params

    tables = {gear.name: gear.table for gear in
              pricking_design(load_params(REPO / "params" / "kernel-a.toml")).gears}
    for curve in concave:
        table = tables[curve["name"]]
        points = table["radius"][:, None] * np.column_stack([np.cos(table["body_angle"]),
                                                             np.sin(table["body_angle"])])
        assert np.allclose(points, np.column_stack([curve["x"], curve["y"]]), atol=0.005)
        before, after = points - np.roll(points, 1, 0), np.roll(points, -1, 0) - points
        turn = before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]
        backwards = turn * np.sign(turn.sum()) < 0
        flagged = np.zeros(len(points), dtype=bool)
        for start, stop in curve["concave"]:
            assert 0 <= start <= stop < len(points)
            flagged[start:stop + 1] = True
            if stop - start >= 8:
                assert backwards[start:stop + 1].mean() > 0.6, (curve["name"], start, stop)
        runs = np.flatnonzero(np.diff(np.concatenate([[0], backwards.astype(int), [0]])))
        for start, stop in zip(runs[::2], runs[1::2]):
            if stop - start >= 6:   # a real concave stretch, not rounding noise
                assert flagged[max(start - 3, 0):stop + 3].any(), (curve["name"], start, stop)


def test_planting_curves_follow_the_kinematic_model(planting_answer):
    from cadgen.design import build_mechanism
    from cadgen.params import load_params

    mechanism = build_mechanism(load_params(PLANTING))
    series = planting_answer["series"]
    phi = np.radians(series["angle_deg"])
    tip = mechanism.motion(phi, "N").position
    path = planting_answer["relative"]["paths"][0]
    assert np.allclose(path["x"], tip[:, 0], atol=0.005) and np.allclose(path["y"], tip[:, 1],
                                                                         atol=0.005)
    assert np.allclose(series["attitude_deg"], np.degrees(mechanism.attitude(phi)), atol=0.005)
    spacing = planting_answer["absolute"]["spacings"][1]
    absolute = mechanism.absolute_motion(phi, spacing["spacing"]).position
    assert np.allclose(spacing["x"], absolute[:, 0], atol=0.005)
    events = planting_answer["events"]["carrier_angle_deg"]
    assert series["events_deg"]["lowest"] == pytest.approx(events["lowest"], abs=0.005)


# --------------------------------------------------------------------------- the animation
@pytest.fixture(scope="module")
def planting_model():
    import cadgen
    from cadgen.design import build_mechanism

    params = cadgen.load_params(PLANTING)
    mechanism = build_mechanism(params)
    return params, mechanism, cadgen.evaluate(params, mechanism)


def _pairs(flat) -> np.ndarray:
    """The animation's flat SVG list back to (n, 2) mm, y up."""
    points = np.asarray(flat, dtype=float).reshape(-1, 2)
    return np.column_stack([points[:, 0], -points[:, 1]])


def test_animation_tip_is_the_kinematic_tip(planting_answer, planting_model):
    _, mechanism, _ = planting_model
    animation = planting_answer["animation"]
    phi = np.radians(animation["angles"])
    for arm, trail in enumerate(animation["trails"]):
        tip = mechanism.motion(phi, "N", arm).position
        assert np.allclose(_pairs(trail["points"]), tip, atol=0.05 + 1e-9)
    poses = animation["poses"]
    for event in animation["events"]:
        assert event["frame"] == round(event["deg"] / 360 * poses) % poses
    spacings = planting_answer["absolute"]["spacings"]
    assert animation["advance_mm_per_turn"] == {f"{s['spacing']:g}": 2 * s["spacing"]
                                                for s in spacings}


def _arc_lengths(points) -> np.ndarray:
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def test_gear_pitch_curves_meet_at_the_pitch_point_having_rolled_equal_arcs(planting_model):
    from cadgen.studio.animation import gear_pitch_curves

    _, mechanism, _ = planting_model
    samples = 3600
    phi = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)   # pose k at gear sample k
    for arm in (0, 1):
        gears = gear_pitch_curves(mechanism, phi, arm, samples=samples)
        central, intermediate = gears["central"].world(), gears["intermediate"].world()
        frames = np.arange(0, samples, 90)
        # arm 2 is half a turn on: its gears touch at the sample of t = phi + pi
        touching = (frames + arm * samples // 2) % samples
        contact_c, contact_i = central[frames, touching], intermediate[frames, touching]
        centres = gears["centres"]
        # the same point, on the segment C-D at r1(phi) from C
        assert np.allclose(contact_c, contact_i, atol=1e-9)
        t = phi[frames] + np.pi * arm
        r1 = mechanism.pitch_curve.radius(t)
        along = centres["D"][frames] - centres["C"][frames]
        direction = along / np.linalg.norm(along, axis=1)[:, None]
        expected = centres["C"][frames] + r1[:, None] * direction
        assert np.allclose(contact_c, expected, atol=1e-9)
        # each gear's pitch curve, at one pose, walked from sample 0 to sample k: equal lengths
        rolled_c = _arc_lengths(gears["central"].local)
        rolled_i = _arc_lengths(gears["intermediate"].local)
        assert np.allclose(rolled_c[touching], rolled_i[touching], rtol=2e-4, atol=0.01)
        # and the whole curves are the same length (the pair closes 1:1)
        loop = lambda p: _arc_lengths(np.vstack([p, p[:1]]))[-1]   # noqa: E731
        assert loop(gears["central"].local) == pytest.approx(mechanism.pitch_perimeter, rel=1e-5)
        assert loop(gears["intermediate"].local) == pytest.approx(mechanism.pitch_perimeter,
                                                                  rel=1e-5)


def test_circular_pair_rolls_and_carries_the_planter(planting_model):
    from cadgen.studio.animation import gear_pitch_curves

    _, mechanism, _ = planting_model
    phi = np.linspace(0.0, 2 * np.pi, 73)
    for arm in (0, 1):
        gears = gear_pitch_curves(mechanism, phi, arm)
        box = mechanism.phic + phi + np.pi * arm
        turn_d = gears["spoke D"].angle - box
        turn_e = gears["spoke E"].angle - box - np.pi
        assert np.allclose(turn_d, -turn_e)            # 1:1, external: opposite turns
        # the planet carries the planter: its world angle is phic + Psi (the attitude)
        psi = mechanism.attitude(phi + np.pi * arm)
        assert np.allclose(np.cos(gears["spoke E"].angle - np.pi - mechanism.phic - psi), 1.0)
        # the marks start together at the contact point, midway between D and E (at the
        # arm's own start: phi = 0 for arm 1, half a turn on for arm 2)
        start_pose = 36 * arm
        start = [gears[f"spoke {p}"].world()[start_pose, 1] for p in ("D", "E")]
        middle = (gears["centres"]["D"][start_pose] + gears["centres"]["E"][start_pose]) / 2
        assert np.allclose(start, [middle, middle], atol=1e-9)


def _inside(polygon, centre, radius) -> bool:
    """A disc inside a counter-clockwise convex polygon (every edge's line at >= radius)."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.linalg.norm(edges, axis=1)[:, None]
    return bool(np.all(np.einsum("ij,ij->i", normals, polygon - centre) >= radius - 1e-6))


def test_rigid_items_drawn_with_the_svg_transform_are_the_world_shapes(planting_answer,
                                                                       planting_model):
    from cadgen.studio.animation import gear_pitch_curves, housing_outlines

    _, mechanism, evaluation = planting_model
    animation = planting_answer["animation"]
    phi = np.radians(animation["angles"])
    bodies = {f"housing-outline {name}": body for name, body in
              housing_outlines(mechanism, evaluation.housing_circles, phi).items()}
    gears = gear_pitch_curves(mechanism, phi, 1)
    bodies["pitch intermediate arm2"] = gears["intermediate"]
    items = {item["cls"]: item for item in animation["housings"] + animation["pitch_curves"]}
    for cls, body in bodies.items():
        item = items[cls]
        local = np.asarray(item["local"], dtype=float).reshape(-1, 2)
        for k in (0, 17, len(phi) - 1):
            x, y, degrees = item["frames"][k]
            # what the browser does with transform="translate(x, y) rotate(deg)"
            turn = np.radians(degrees)
            rotation = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
            drawn = local @ rotation.T + [x, y]
            assert np.allclose(_pairs(drawn.ravel()), body.world()[k], atol=0.2), (cls, k)


def test_housing_outlines_hold_their_envelope_circles(planting_model):
    from cadgen.studio.animation import housing_outlines

    _, mechanism, evaluation = planting_model
    phi = np.linspace(0.0, 2 * np.pi, 13)
    outlines = housing_outlines(mechanism, evaluation.housing_circles, phi)
    assert set(outlines) == {"gearbox1", "gearbox2 arm1", "gearbox2 arm2"}
    for k in range(len(phi)):
        for circle in evaluation.housing_circles:
            for arm in (0, 1):
                if circle.point == "O":
                    centre = np.zeros(2)
                else:
                    centre = mechanism.positions(phi[k:k + 1], arm=arm,
                                                 points=(circle.point,))[circle.point][0]
                name = "gearbox1" if circle.gearbox == "gearbox1" else f"gearbox2 arm{arm + 1}"
                assert _inside(outlines[name].world()[k], centre, circle.radius), (name, k)


def test_duckbill_opens_by_the_cam_law(planting_answer, planting_model):
    from cadgen.cam.design import design_cam
    from cadgen.studio.animation import blade_opening

    params, mechanism, evaluation = planting_model
    animation = planting_answer["animation"]
    phi = np.radians(animation["angles"])
    beta, linkage, note = blade_opening(params, mechanism, evaluation, phi)
    assert note is None and animation["duckbill_note"] is None
    cam = design_cam(params, mechanism, evaluation.events)
    assert np.allclose(beta, cam.profile.follower_at_carrier(phi, cam.cam_angle)[2], atol=1e-12)
    blades = {item["cls"]: np.array([_pairs(f) for f in item["frames"]])
              for item in animation["duckbill"]}
    right, left = blades["duckbill right arm1"], blades["duckbill left arm1"]
    mouth = np.linalg.norm(right[:, 1] - left[:, 1], axis=1)
    assert np.allclose(mouth, linkage.mouth_width(beta), atol=0.15)
    closed = beta < 1e-9   # the dwell: the lever at rest
    assert closed.any() and (~closed).any()
    tip = mechanism.motion(phi, "N").position
    assert np.allclose(right[closed, 1], tip[closed], atol=0.1)
    assert mouth.max() == pytest.approx(linkage.mouth_width(linkage.opening_angle), abs=0.15)


def test_duckbill_stays_closed_with_a_note_when_the_cam_stage_fails(client):
    params = _load(PLANTING)
    params["cam"]["pot_diameter"] = 400.0   # no blade opening clears it: a cam-stage problem
    answer = evaluate(client, params).json()
    assert answer["ok"] is True
    assert any(w["stage"] == "cam" for w in answer["warnings"])
    note = answer["animation"]["duckbill_note"]
    assert note and "closed" in note
    for item in answer["animation"]["duckbill"]:
        tips = np.array([_pairs(f)[1] for f in item["frames"]])
        hinge = np.array([_pairs(f)[0] for f in item["frames"]])
        # closed: every frame the same blade in the planter's frame (its length unchanged)
        assert np.ptp(np.linalg.norm(tips - hinge, axis=1)) < 0.2


# --------------------------------------------------------------------------- bad requests
def _good(client):
    response = evaluate(client, _load(PLANTING))
    assert response.status_code == 200 and response.json()["ok"] is True


def _with(path: str, value):
    params = _load(PLANTING)
    *tables, key = path.split(".")
    node = params
    for table in tables:
        node = node.setdefault(table, {})
    node[key] = value
    return params


def _body(params) -> bytes:
    return json.dumps({"params": params}).encode()   # allow_nan: NaN and Infinity as JS-ish tokens


BAD_REQUESTS = {
    # name: (request kwargs, status, field)
    "no token": (dict(json={"params": {}}, headers={}), 403, "token"),
    "wrong token": (dict(json={"params": {}}, headers={"X-Cadgen-Token": "nope"}), 403, "token"),
    "wrong host": (dict(json={"params": {}}, headers={**HEADERS, "host": "evil.example:80"}),
                   400, "host"),
    "oversized body": (dict(content=b" " * (MAX_BODY_BYTES + 1), headers=HEADERS), 413, "body"),
    "oversized stream": (dict(content=iter([b" " * 65536] * 17), headers=HEADERS), 413, "body"),
    "not json": (dict(content=b"{params:", headers=HEADERS), 400, "body"),
    "empty": (dict(content=b"", headers=HEADERS), 400, "body"),
    "not an object": (dict(content=b"[1, 2]", headers=HEADERS), 422, "body"),
    "params missing": (dict(json={"parameters": {}}, headers=HEADERS), 422, "params"),
    "params not an object": (dict(json={"params": "planter"}, headers=HEADERS), 422, "params"),
    "NaN": (dict(content=_body(_with("planter.L2", float("nan"))), headers=HEADERS), 422,
            "planter.L2"),
    "Infinity": (dict(content=_body(_with("train.R", float("-inf"))), headers=HEADERS), 422,
                 "train.R"),
    "huge array": (dict(json={"params": _with("field.plant_spacings", [150.0] * 100_000)},
                        headers=HEADERS), 422, "field.plant_spacings"),
    "wrong type": (dict(json={"params": _with("planter.L1", "130")}, headers=HEADERS), 422,
                   "planter.L1"),
    "unknown key": (dict(json={"params": _with("planter.L3", 1.0)}, headers=HEADERS), 422,
                    "planter.L3"),
    "wrong kind": (dict(json={"params": _with("mechanism", "weeding")}, headers=HEADERS), 422,
                   "mechanism"),
    "deep nesting": (dict(content=b'{"params": {"planter": ' + b"[" * 100_000 + b"]" * 100_000
                          + b"}}", headers=HEADERS), 400, "body"),
    "nested past the limit": (dict(json={"params": _with("planter.L1", [[[[[[[[[1.0]]]]]]]]])},
                                   headers=HEADERS), 422, "planter.L1"),
    "huge integer": (dict(content=b'{"params": {"name": ' + b"9" * 5000 + b"}}", headers=HEADERS),
                     400, "body"),
    "not utf-8": (dict(content=b'{"params": "\xff"}', headers=HEADERS), 400, "body"),
}


@pytest.mark.parametrize("name", list(BAD_REQUESTS))
def test_bad_request_gets_a_json_error_naming_the_field(client, name):
    kwargs, status, field = BAD_REQUESTS[name]
    response = client.post("/api/evaluate", **kwargs)
    assert response.status_code == status, response.text
    assert response.headers["content-type"].startswith("application/json")
    answer = response.json()
    assert answer["error"] and isinstance(answer["error"], str)
    assert answer["field"] == field or answer["field"].startswith(field + "."), answer
    assert "Traceback" not in response.text
    _good(client)   # the server keeps serving


@pytest.mark.parametrize("method, path, status", [("GET", "/api/nothing", 404),
                                                  ("GET", "/api/evaluate", 405),
                                                  ("DELETE", "/api/design", 405),
                                                  ("GET", "/static/none.js", 404),
                                                  ("GET", "/static/../server.py", 404),
                                                  ("GET", "/files/../../etc/passwd", 404),
                                                  ("GET", "/files/%00secret", 404)])
def test_framework_errors_are_json_too(client, method, path, status):
    response = client.request(method, path, headers=HEADERS)
    assert response.status_code == status
    assert set(response.json()) >= {"error", "field"}


def test_an_internal_error_is_a_500_with_its_traceback_in_a_file(client, monkeypatch, tmp_path):
    import cadgen.studio.payload as payload

    def broken(params):
        raise ZeroDivisionError("a bug")

    monkeypatch.setenv("CADGEN_CRASH_DIR", str(tmp_path))
    monkeypatch.setattr(payload, "evaluation_payload", broken)
    response = evaluate(client, _load(PLANTING))
    assert response.status_code == 500
    answer = response.json()
    assert answer["error"].startswith("internal error: ZeroDivisionError")
    assert "Traceback" not in response.text
    crash = list(tmp_path.glob("cadgen-crash-*.txt"))
    assert len(crash) == 1 and "ZeroDivisionError: a bug" in crash[0].read_text()
    # any other route too: the guard answers for an exception the app lets through
    import cadgen.studio.schema as schema

    monkeypatch.setattr(schema, "studio_schema", lambda: 1 / 0)
    response = client.get("/api/schema", headers=HEADERS)
    assert response.status_code == 500 and "Traceback" not in response.text
    assert response.json()["error"].startswith("internal error: ZeroDivisionError")
    assert len(list(tmp_path.glob("cadgen-crash-*.txt"))) == 2
    monkeypatch.undo()
    _good(client)


def _json_values():
    scalars = (st.none() | st.booleans() | st.integers() | st.floats(allow_nan=True,
                                                                    allow_infinity=True)
               | st.text(max_size=20))
    return st.recursive(scalars, lambda inner: st.lists(inner, max_size=4)
                        | st.dictionaries(st.text(max_size=8), inner, max_size=4), max_leaves=12)


_PATHS = ["planter.L2", "train.R", "train.n", "pitch_curve.teeth", "pitch_curve.kind",
          "field.plant_spacings", "field.depth", "cam.duckbill", "cam.timing.opening_offset_deg",
          "name", "mechanism", "scene.effects", "housing.gearbox1", "targets"]


@settings(max_examples=40, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(path=st.sampled_from(_PATHS), value=_json_values())
def test_hostile_values_get_an_answer_never_a_crash(client, path, value):
    response = client.post("/api/evaluate", content=_body(_with(path, value)), headers=HEADERS)
    assert response.status_code in (200, 422), response.text
    answer = response.json()
    if response.status_code == 422:
        assert answer["problems"] and answer["field"]


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(table=st.sampled_from(["", "planter", "cam", "cam.timing", "field", "scene"]),
       key=st.text(min_size=1, max_size=30), value=_json_values())
def test_unknown_keys_anywhere_are_named(client, table, key, value):
    from cadgen.studio.schema import studio_schema

    tables = studio_schema()["kinds"]["planting"]["tables"]
    known = {t["name"] for t in tables} | {f["path"] for t in tables for f in t["fields"]}
    if (f"{table}.{key}" if table else key) in known:
        return   # a real key: the test above tries values for those
    params = _load(PLANTING)
    node = params
    for part in filter(None, table.split(".")):
        node = node.setdefault(part, {})
    node[key] = value
    response = client.post("/api/evaluate", content=_body(params), headers=HEADERS)
    assert response.status_code == 422, response.text
    codes = {(p["code"], p["path"].split(".")[0]) for p in response.json()["problems"]}
    assert any(code in ("unknown_key", "unknown_mechanism") for code, _ in codes), codes


# --------------------------------------------------------------------------- other routes
def test_design_and_static_page(client):
    design = client.get("/api/design", headers=HEADERS).json()
    assert design["kind"] == "planting" and design["params"] == _load(PLANTING)
    assert design["path"] == str(PLANTING.resolve()) and design["folder"] == str(REPO / "params")
    assert client.get("/api/design", params={"token": TOKEN}).status_code == 200
    viewer = client.get("/static/vendor/three-viewer.min.js")   # no token for the page
    assert viewer.status_code == 200
    assert viewer.content == (REPO / "cadgen/report/vendor/three-viewer.min.js").read_bytes()
    explode = client.get("/static/vendor/explode.js")   # the report's explode slider's helpers
    assert explode.status_code == 200
    assert explode.content == (REPO / "cadgen/report/explode.js").read_bytes()
    if (REPO / "cadgen/studio/static/index.html").is_file():
        page = client.get("/")
        assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")


def test_bundled_design_is_read_only_and_saves_as_into_the_working_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    app = create_app(None, token=TOKEN, output_root=tmp_path / "outputs")
    with TestClient(app, base_url="http://localhost") as client:
        design = client.get("/api/design", headers=HEADERS).json()
        assert design["path"] is None and design["writable"] is False
        assert design["folder"] == str(tmp_path.resolve())
        params = design["params"]
        refused = client.post("/api/save", json={"params": params, "as": None}, headers=HEADERS)
        assert refused.status_code == 400 and refused.json()["field"] == "as"
        outside = client.post("/api/save", json={"params": params, "as": "../x.toml"},
                              headers=HEADERS)
        assert outside.status_code == 400 and outside.json()["field"] == "as"
        saved = client.post("/api/save", json={"params": params, "as": "mine.toml"},
                            headers=HEADERS)
        assert saved.status_code == 200, saved.text
        assert Path(saved.json()["path"]) == (tmp_path / "mine.toml").resolve()
        again = client.post("/api/save", json={"params": params, "as": "mine.toml"},
                            headers=HEADERS)
        assert again.status_code == 409
        # the file saved as is the one open now, and writable
        assert client.get("/api/design", headers=HEADERS).json()["writable"] is True
        bad = copy.deepcopy(params)
        bad["planter"]["L2"] = -1
        refused = client.post("/api/save", json={"params": bad, "as": None}, headers=HEADERS)
        assert refused.status_code == 422 and refused.json()["field"] == "planter.L2"


def test_build_routes_refuse_bad_parameters_and_unknown_jobs(client):
    bad = _with("planter.L2", -1.0)
    response = client.post("/api/build", json={"params": bad}, headers=HEADERS)
    assert response.status_code == 422 and response.json()["field"] == "planter.L2"
    response = client.get("/api/build/nope/events", headers=HEADERS)
    assert response.status_code == 404 and response.json()["field"] == "job"


def test_files_serves_only_under_the_output_root(client):
    root = client.app.state.studio.output_root
    (root / "design").mkdir(parents=True, exist_ok=True)
    (root / "design" / "report.html").write_text("<p>report</p>", encoding="utf-8")
    assert client.get("/files/design/report.html", params={"token": TOKEN}).text == "<p>report</p>"
    assert client.get("/files/design/report.html").status_code == 403
    assert client.get("/files/%2e%2e/%2e%2e/etc/passwd", headers=HEADERS).status_code == 404


# --------------------------------------------------------------------------- the schema
def _model_fields(model, prefix="") -> dict:
    """Every leaf field of a model, by dotted path, walking into nested models."""
    import types
    import typing

    from pydantic import BaseModel

    out = {}
    for key, field in model.model_fields.items():
        path = f"{prefix}{key}"
        annotation = field.annotation
        members = typing.get_args(annotation) if typing.get_origin(annotation) in (
            typing.Union, types.UnionType) else (annotation,)
        models = [m for m in members if isinstance(m, type) and issubclass(m, BaseModel)]
        if models:
            for member in models:
                out.update(_model_fields(member, path + "."))
        else:
            out[path] = field
    return out


@pytest.mark.parametrize("kind", ["planting", "pricking"])
def test_schema_lists_every_model_field_with_its_bounds_and_default(client, kind):
    from annotated_types import Ge, Gt, Le, Lt
    from pydantic_core import PydanticUndefined

    from cadgen.params import PlantingParameters, PrickingParameters

    model = {"planting": PlantingParameters, "pricking": PrickingParameters}[kind]
    tables = client.get("/api/schema", headers=HEADERS).json()["kinds"][kind]["tables"]
    fields = {f["path"]: f for table in tables for f in table["fields"]}
    expected = _model_fields(model)
    assert set(fields) == set(expected)
    for table in tables:
        for field in table["fields"]:
            assert field["path"] == (f"{table['name']}.{field['key']}" if table["name"]
                                     else field["key"])
            assert field["description"] and "\n" not in field["description"]
    for path, field in expected.items():
        entry = fields[path]
        bounds = {type(m): m for m in field.metadata}
        if Gt in bounds or Ge in bounds:
            low = bounds[Gt].gt if Gt in bounds else bounds[Ge].ge
            assert (entry["minimum"], entry["exclusive_minimum"]) == (low, Gt in bounds), path
        if Lt in bounds or Le in bounds:
            high = bounds[Lt].lt if Lt in bounds else bounds[Le].le
            assert (entry["maximum"], entry["exclusive_maximum"]) == (high, Lt in bounds), path
        default = field.get_default(call_default_factory=True)
        if default is PydanticUndefined:
            assert entry["required"] and entry["default"] is None, path
        elif not isinstance(default, tuple):
            assert entry["default"] == default, path
        if path.endswith("_deg"):
            assert entry["unit"] == "deg"
    units = {path: fields[path]["unit"] for path in fields}
    if kind == "planting":
        assert units["planter.L1"] == "mm" and units["pitch_curve.f1_rad"] == "rad"
        assert units["field.carrier_speed_rpm"] == "r/min" and units["pitch_curve.e1"] is None
        assert fields["field.plant_spacings"]["type"] == "array"
        assert fields["cam.rise_law"]["enum"] == ["cycloidal", "polynomial-345"]
    else:
        assert fields["trajectory.points"]["items"] == "point"
        assert units["trajectory.points"] == "mm"
        assert units["field.forward_speed"] == "mm/s"


# --------------------------------------------------------------------------- the command
def _cadgen(*args, **kwargs):
    return subprocess.Popen([sys.executable, "-m", "cadgen", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kwargs)


def test_studio_command_serves_the_design_behind_its_token(tmp_path):
    design = tmp_path / "design.toml"
    shutil.copyfile(PLANTING, design)
    process = _cadgen("studio", str(design), "--no-browser", "--port", "0", "--output-dir",
                      str(tmp_path / "outputs"), cwd=tmp_path)
    try:
        line = process.stdout.readline()
        match = re.fullmatch(r"cadgen studio: (http://127\.0\.0\.1:(\d+)/)\?token=(\S+)\n", line)
        assert match, line + process.stderr.read() if process.poll() is not None else line
        base, port, token = match.groups()
        request = urllib.request.Request(base + "api/design", headers={"X-Cadgen-Token": token})
        with urllib.request.urlopen(request, timeout=10) as response:
            answer = json.load(response)
        assert answer["path"] == str(design.resolve()) and answer["writable"] is True
        # the port is taken now: a second studio on it says so in one line, exit 2
        second = _cadgen("studio", "--no-browser", "--port", port)
        out, err = second.communicate(timeout=60)
        assert second.returncode == 2 and len(err.strip().splitlines()) == 1, err
        assert "cannot listen" in err
    finally:
        process.terminate()
        process.wait(timeout=20)


def test_studio_command_refuses_a_bad_file_like_validate(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(PLANTING.read_text(encoding="utf-8").replace("L2 = 190.0", "L2 = -190.0"),
                   encoding="utf-8")
    studio = _cadgen("studio", str(bad), "--no-browser")
    out, err = studio.communicate(timeout=60)
    validate = _cadgen("validate", str(bad))
    said, _ = validate.communicate(timeout=60)
    assert studio.returncode == validate.returncode == 2
    assert err.strip().splitlines() == said.strip().splitlines() and len(said.splitlines()) == 1


def test_help_does_not_import_the_web_stack():
    code = ("import sys; from cadgen.cli import build_parser; build_parser(['--help']); "
            "print(sorted(m for m in ('fastapi', 'uvicorn', 'starlette', 'numpy') "
            "if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO)})
    assert done.stdout.strip() == "[]", done.stderr
    # nor does loading the server module load numpy: the studio loads it single-threaded first
    code = ("import sys, cadgen.studio.server; "
            "print(sorted(m for m in ('numpy', 'scipy', 'pydantic') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO)})
    assert done.stdout.strip() == "[]", done.stderr


def test_the_studio_names_each_clearance_as_a_metrics_build_does():
    # the studio evaluates without solids: its clearances are the centre lines' and the
    # envelope circles', under the labels a metrics-only build prints and reports
    from cadgen.params import load_params
    from cadgen.pipeline.build import build
    from cadgen.studio.payload import evaluate_request
    from tests.helpers import REFERENCE, reference_text

    import tomllib

    status, answer = evaluate_request(tomllib.loads(reference_text()))
    assert status == 200
    studio = {m["key"]: m["label"] for m in answer["metrics"] if m.get("spacing_mm") is None}
    report = build(load_params(REFERENCE), None, effects=["metrics"]).report
    built = {m["key"]: m["label"] for m in report["metrics"] if m.get("spacing_mm") is None}
    assert studio["arm_distance"] == built["arm_distance"] == "arm distance (centre lines)"
    assert studio["ground_clearance"] == built["ground_clearance"] == \
        "gearbox ground clearance (envelope circles)"


def test_a_resolution_beyond_the_live_cap_is_evaluated_at_the_cap_and_said():
    # 1,000,000 steps per revolution took 10 s an evaluation: the page evaluates at the fine
    # preset's 36,000 and says so; the answer is the one 36,000 steps give
    import tomllib

    from cadgen.studio.payload import evaluate_request
    from tests.helpers import reference_text

    data = tomllib.loads(reference_text())
    data["resolution"]["steps_per_revolution"] = 36_000
    _, at_cap = evaluate_request(data)
    data["resolution"]["steps_per_revolution"] = 1_000_000
    status, answer = evaluate_request(data)
    assert status == 200
    [warning] = [w for w in answer["warnings"] if w["code"] == "capped_for_live_evaluation"]
    assert warning["path"] == "resolution.steps_per_revolution"
    assert "1,000,000" in warning["message"] and "36,000" in warning["message"]
    assert [m["value"] for m in answer["metrics"]] == [m["value"] for m in at_cap["metrics"]]
    assert data["resolution"]["steps_per_revolution"] == 1_000_000   # the page's own data
