"""The studio's page in headless Chromium, driven as a designer would: type, drag, play, save.

Debian's Chromium (``/usr/bin/chromium``) driven by Playwright for Python, with no
``playwright install``. Without Chromium or Playwright the tests are skipped locally and
fail in CI (``CI=true``), where ``.ci/run`` installs Chromium first (as
``tests/test_report_browser.py``).

Each test runs a real studio (``cadgen.studio.run.serve_in_thread``: uvicorn on
127.0.0.1, a free port) on a copy of a bundled design in ``tmp_path``. The values the page
shows are checked against what ``POST /api/evaluate`` answers for the same parameters,
asked separately (httpx), not against the page's own numbers. Every test also checks that
the page logged no error and requested nothing but its own server.
"""

import math
import tomllib
from pathlib import Path

import pytest
from conftest import load_script

REPO = Path(__file__).resolve().parents[1]


SHOTS = load_script("studio_screenshots")


class Studio:
    """A running studio on a copy of a bundled design, and an httpx client to its API."""

    def __init__(self, design: Path, output_root: Path):
        import httpx

        self.design = design
        self.url, self._stop = SHOTS.start_studio(design, output_root)
        base, token = self.url.split("/?token=")
        self.client = httpx.Client(base_url=base, headers={"X-Cadgen-Token": token}, timeout=30)

    def evaluate(self, params: dict) -> dict:
        answer = self.client.post("/api/evaluate", json={"params": params})
        assert answer.status_code == 200, answer.text
        return answer.json()

    def close(self):
        self.client.close()
        self._stop()


@pytest.fixture
def studio(tmp_path, request):
    started = Studio(SHOTS.copy_design(request.param, tmp_path), tmp_path / "outputs")
    yield started
    started.close()


@pytest.fixture
def page(browser, studio):
    page, requests, errors = SHOTS.open_studio(browser, studio.url)
    yield page
    problems = SHOTS.page_problems(page, requests, errors)
    page.close()
    assert not problems, "\n".join(problems)


#: The screen position (and the mm) of the loop's sample half-way between type-value points i, j.
_LOOP_POINT_BETWEEN_JS = """([i, j]) => {
  const answer = window.cadgenStudio.answer, loop = answer.loop, n = loop.x.length;
  const nearest = (p) => {
    let best = 0, distance = Infinity;
    loop.x.forEach((x, k) => {
      const d = (x - p[0]) ** 2 + (loop.y[k] - p[1]) ** 2;
      if (d < distance) { distance = d; best = k; }
    });
    return best;
  };
  const from = nearest(answer.points[i]), to = nearest(answer.points[j]);
  const k = (from + Math.floor((((to - from) % n) + n) % n / 2)) % n;
  const svg = document.querySelector("svg.loop-view"), point = svg.createSVGPoint();
  point.x = loop.x[k];
  point.y = -loop.y[k];
  const screen = point.matrixTransform(svg.getScreenCTM());
  return [screen.x, screen.y, [loop.x[k], loop.y[k]]];
}"""


def _metric_value(page, key: str) -> float:
    return float(page.locator(f'tr[data-key="{key}"] td.value').first.get_attribute("data-value"))


def _api_metric(answer: dict, key: str) -> float:
    return next(m["value"] for m in answer["metrics"] if m["key"] == key)


@pytest.mark.parametrize("studio", [SHOTS.PLANTING], indirect=True, ids=["planting"])
def test_changing_L2_recomputes_the_trajectory_height_and_undo_restores_it(page, studio):
    design = studio.client.get("/api/design").json()
    params = design["params"]
    assert math.isclose(_metric_value(page, "trajectory_height"),
                        _api_metric(studio.evaluate(params), "trajectory_height"), abs_tol=1e-9)
    page.locator("#pin").click()   # the design before the change stays as a column

    before = SHOTS.evaluations(page)
    SHOTS.set_field(page, "planter.L2", "230")
    SHOTS.wait_for_evaluation(page, before)
    expected = _api_metric(studio.evaluate({**params, "planter": {**params["planter"], "L2": 230.0}}),
                           "trajectory_height")
    assert math.isclose(_metric_value(page, "trajectory_height"), expected, abs_tol=1e-9)
    cell = page.locator('tr[data-key="trajectory_height"] td.value')
    assert "changed" in cell.get_attribute("class")
    pinned = page.locator('tr[data-key="trajectory_height"] td.pinned').inner_text()
    assert pinned == f"{_api_metric(studio.evaluate(params), 'trajectory_height'):.2f}"
    for plot in ("#panel-relative", "#panel-absolute", "#panel-animation"):   # the faint overlay
        assert page.locator(f"{plot} .pinned").count() >= 1, plot
    assert page.locator("#panel-angle .u-legend", has_text="pinned").count() == 2

    # an invalid value: the server's message beside the field, the last picture kept and greyed
    before_invalid = page.evaluate("window.cadgenStudio.answer.metrics[0].value")
    SHOTS.set_field(page, "planter.L2", "-5")
    page.wait_for_function("window.cadgenStudio.state === 'invalid'")
    problem = page.locator('.field[data-path="planter.L2"] .field-problem')
    assert problem.is_visible() and problem.inner_text()
    assert "stale" in page.locator("#results").get_attribute("class")
    assert page.evaluate("window.cadgenStudio.answer.metrics[0].value") == before_invalid

    # undo over the edits (Ctrl-Z): back to the file's L2 and its height
    before = SHOTS.evaluations(page)
    page.locator("body").click(position={"x": 5, "y": 5})
    page.keyboard.press("Control+z")
    page.keyboard.press("Control+z")
    SHOTS.wait_for_evaluation(page, before)
    page.wait_for_function("document.querySelector('.field[data-path=\"planter.L2\"] input')"
                           ".value === '190'")
    assert math.isclose(_metric_value(page, "trajectory_height"),
                        _api_metric(studio.evaluate(params), "trajectory_height"), abs_tol=1e-9)

    # the page fits a 1024 px window too
    page.set_viewport_size({"width": 1024, "height": 800})
    page.wait_for_timeout(150)


@pytest.mark.parametrize("studio", [SHOTS.PLANTING], indirect=True, ids=["planting"])
def test_animation_plays_pauses_and_scrubs(page):
    player = page.locator(".player")
    if player.get_attribute("data-playing") == "true":
        page.locator(".anim-play").click()
    held = int(player.get_attribute("data-frame"))
    page.wait_for_timeout(250)
    assert int(player.get_attribute("data-frame")) == held   # paused: the pose holds
    page.locator(".anim-speed select").select_option("4")
    page.locator(".anim-play").click()
    page.wait_for_function(f"document.querySelector('.player').dataset.frame !== '{held}'",
                           timeout=3000)
    page.locator(".anim-play").click()
    page.locator(".anim-slider").fill("90")
    assert player.get_attribute("data-frame") == "90"
    events = page.locator(".anim-event")
    assert events.count() == 4   # catching, entry, lowest, exit on the timeline
    page.locator(".anim-event.lowest").click()
    frame = int(player.get_attribute("data-frame"))
    lowest = page.evaluate("window.cadgenStudio.answer.animation.events"
                           ".find(e => e.name === 'lowest').frame")
    assert frame == lowest


@pytest.mark.parametrize("studio", [SHOTS.PRICKING], indirect=True, ids=["pricking"])
def test_dragging_a_type_value_point_reruns_the_inverse_design(page, studio):
    params = studio.client.get("/api/design").json()["params"]
    original = [list(p) for p in params["trajectory"]["points"]]
    a_before = float(page.locator("#pricking-a").get_attribute("data-value"))
    assert math.isclose(a_before, studio.evaluate(params)["report"]["linkage"]["centre_distance_a_mm"])

    before = SHOTS.evaluations(page)
    SHOTS.drag_point(page, 3, 30, 20)
    SHOTS.wait_for_evaluation(page, before)
    moved = page.evaluate("window.cadgenStudio.params.trajectory.points")
    assert moved[:3] == original[:3] and moved[4:] == original[4:]
    # 30 px right and 20 px down on the screen: x grows, y falls (mm, y up)
    assert moved[3][0] > original[3][0] + 1 and moved[3][1] < original[3][1] - 1
    expected = studio.evaluate({**params, "trajectory": {**params["trajectory"], "points": moved}})
    a_after = float(page.locator("#pricking-a").get_attribute("data-value"))
    assert math.isclose(a_after, expected["report"]["linkage"]["centre_distance_a_mm"])
    assert not math.isclose(a_after, a_before)

    # Alt-click removes a point, undo brings it back
    before = SHOTS.evaluations(page)
    page.locator('.tv-point[data-index="5"]').click(modifiers=["Alt"])
    SHOTS.wait_for_evaluation(page, before)
    assert len(page.evaluate("window.cadgenStudio.params.trajectory.points")) == len(original) - 1
    before = SHOTS.evaluations(page)
    page.locator("#undo").click()
    SHOTS.wait_for_evaluation(page, before)
    assert page.evaluate("window.cadgenStudio.params.trajectory.points") == moved

    # a double-click on the loop half-way between Q5 and Q6 adds a point there, on the loop
    page.locator("svg.loop-view").scroll_into_view_if_needed()
    x, y, on_loop = page.evaluate(_LOOP_POINT_BETWEEN_JS, [4, 5])
    loop = page.evaluate("window.cadgenStudio.answer.loop")
    before = SHOTS.evaluations(page)
    page.mouse.dblclick(x, y)
    SHOTS.wait_for_evaluation(page, before)
    added = page.evaluate("window.cadgenStudio.params.trajectory.points")
    assert len(added) == len(original) + 1 and added[:5] + added[6:] == moved
    assert math.dist(added[5], on_loop) < 3   # where clicked, to a pixel (about 1 mm here)
    assert min(math.dist(added[5], p) for p in zip(loop["x"], loop["y"])) < 0.08   # on the loop


@pytest.mark.parametrize("studio", [SHOTS.PLANTING], indirect=True, ids=["planting"])
def test_save_writes_the_file_keeping_its_comments(page, studio):
    text = studio.design.read_text(encoding="utf-8")
    before = SHOTS.evaluations(page)
    SHOTS.set_field(page, "planter.L2", "201.5")
    SHOTS.wait_for_evaluation(page, before)
    page.locator("#save").click()
    page.wait_for_function("document.getElementById('save-status').dataset.kind === 'ok'")
    assert str(studio.design.name) in page.locator("#save-status").inner_text()
    written = studio.design.read_text(encoding="utf-8")
    assert written != text
    assert tomllib.loads(written)["planter"]["L2"] == 201.5
    comments = [line.split("#", 1)[1] for line in text.splitlines() if "#" in line]
    assert all(comment in written for comment in comments)   # every comment kept


@pytest.mark.parametrize("studio", [SHOTS.PRICKING], indirect=True, ids=["pricking"])
def test_build_reports_its_stages_links_the_report_and_shows_the_assembly(page, studio):
    # a light scene (no teeth, no sweeps, no plots), chosen in the form as a designer would
    page.locator('details[data-table="scene"] summary').click()
    SHOTS.set_field(page, "scene.effects", "metrics, solids, stl, report")
    page.locator('.field[data-path="scene.preset"] select').select_option("draft")
    page.locator("#build").click()
    page.wait_for_function("document.querySelector('.viewer')"
                           " && document.querySelector('.viewer').dataset.state === 'ready'",
                           timeout=120000)
    stages = page.locator(".build-stages li")
    assert {"kinematics", "parts", "write"} <= {stages.nth(i).get_attribute("data-stage")
                                                 for i in range(stages.count())}
    assert page.locator(".build-status").get_attribute("data-kind") == "ok"
    link = page.locator("#build-report-link").get_attribute("href")
    assert link.startswith("/files/kernel-b/report.html?token=")
    report = studio.client.get(link.split("?")[0])
    assert report.status_code == 200 and "<html" in report.text.lower()
    viewer = page.evaluate("window.cadgenStudio.build.viewer.state")
    assert viewer["meshes"] >= 4 and viewer["covers"] >= 1
    page.locator(".viewer-buttons button", has_text="Hide housing covers").click()
    assert page.evaluate("window.cadgenStudio.build.viewer.state.coversHidden") is True
    # the explode slider takes the parts apart by the offsets in the GLB's nodes
    assert viewer["exploding"] >= 4 and viewer["explode"] == 0
    placed = page.evaluate("""() => window.cadgenStudio.build.viewer.exploding.map(
        p => p.node.position.toArray())""")
    page.locator(".viewer-explode input").fill("1")
    assert page.evaluate("window.cadgenStudio.build.viewer.state.explode") == 1
    moved = page.evaluate("""() => window.cadgenStudio.build.viewer.exploding.map(
        p => [p.node.position.toArray(), p.offset])""")
    for before, (after, offset) in zip(placed, moved, strict=True):
        assert after == pytest.approx([b + o for b, o in zip(before, offset)], abs=1e-9)
