"""report.html of both mechanisms in headless Chromium: layout, images, the 3D view, the animation.

Debian's Chromium (``/usr/bin/chromium``) driven by Playwright for Python, with no
``playwright install``. Without Chromium or Playwright the test is skipped locally
and fails in CI (``CI=true``), where ``.ci/run`` installs Chromium first.

The checks (shared with ``scripts/report_screenshots.py``): nothing wider than the
viewport (at 1280 px), every image loaded, the 3D view loaded the embedded
GLB and drew it (pixels unlike its background), the animation's frame advances,
no script error, and nothing fetched but the page itself. Then the contents (they list
every section, mark the one scrolled to, become a bar on a narrow window), the folding
(a folded section is only its heading; the contents fold and unfold them all), the page
with scripts off, and the 3D view's parts against solids/assembly.glb read by trimesh
(every node, named, its box where the file places it). Waits are for conditions, never
for a time.
"""

import re
from pathlib import Path

import pytest
from conftest import load_script

from cadgen import build, load_params

REPO = Path(__file__).resolve().parents[1]
#: The stages a report with solids and figures needs (no teeth, no sweeps: they add time,
#: not page features); the draft preset, for speed.
EFFECTS = ["metrics", "solids", "stl", "plots", "report"]
#: Viewport widths checked for sideways overflow: a desktop, a laptop, a tablet (a wide table
#: scrolls in its own box; the page never does).
WIDTHS = (1280, 1024, 820)


SHOTS = load_script("report_screenshots")


@pytest.fixture(scope="module")
def reports(tmp_path_factory, chromium):
    folder = tmp_path_factory.mktemp("browser")
    pages = {}
    for name in ("xin2024-planter", "kernel-a"):
        result = build(load_params(REPO / "params" / f"{name}.toml"), folder, effects=EFFECTS,
                       preset="draft")
        pages[name] = result.output_dir / "report.html"
    return pages


@pytest.mark.parametrize("design", ["xin2024-planter", "kernel-a"], ids=["planting", "pricking"])
def test_report_renders_and_moves_in_chromium(browser, reports, design):
    page, requests, errors = SHOTS.open_report(browser, reports[design], width=WIDTHS[0])
    try:
        found = SHOTS.page_report(page, wait_ms=600)
        problems = SHOTS.problems_of(found, requests, errors, page.url)
        for width in WIDTHS[1:]:   # a narrower window: still nothing sideways
            page.set_viewport_size({"width": width, "height": 900})
            page.wait_for_timeout(100)
            layout = page.evaluate(SHOTS._OVERFLOW_JS)
            if layout["scrollWidth"] > layout["innerWidth"] or layout["overflowing"]:
                problems.append(f"at {width} px: {layout}")
        # the controls: pausing holds the pose, the slider sets it
        page.locator(".anim-play").click()
        held = page.evaluate("window.cadgenAnimations[0].frame")
        page.wait_for_timeout(300)
        assert page.evaluate("window.cadgenAnimations[0].frame") == held
        page.locator(".anim-slider").fill("90")
        assert page.locator(".cadgen-animation").get_attribute("data-frame") == "90"
        # the housings' covers come off and back: the frame's, gearbox 1's and each arm's
        # gearbox 2's
        covers = {"xin2024-planter": 4, "kernel-a": 1}[design]
        assert page.evaluate("window.cadgenViewer.covers") == covers
        button = page.locator(".viewer-covers")
        button.click()
        assert page.evaluate("window.cadgenViewer.coversHidden") is True
        assert button.inner_text() == "Show covers"
        button.click()
        assert page.evaluate("window.cadgenViewer.coversHidden") is False
    finally:
        page.close()
    assert not problems, "\n".join(problems)
    assert found["viewer"]["meshes"] >= 4


# ---------------------------------------------------------------- the page's data, no browser
def test_animation_poses_are_the_kinematic_model_and_the_page_embeds_them():
    import json

    import numpy as np

    from cadgen.design import build_mechanism
    from cadgen.report.animation import POSES, animation_data, animation_section
    from cadgen.report.html import render_html

    params = load_params(REPO / "params" / "xin2024-planter.toml")
    mechanism = build_mechanism(params)
    data = animation_data(params, {"kinematics": mechanism})
    assert len(data["angles"]) == POSES and data["soil"] is None   # no metrics: no soil line
    phi = np.radians(data["angles"])
    tip = mechanism.motion(phi, "N", 1).position
    trail = np.reshape(data["trails"][1]["points"], (-1, 2)) * [1, -1]
    assert np.allclose(trail, tip, atol=0.051)   # rounded to 0.1 mm
    assert all(len(m["frames"]) == POSES for m in data["moving"])
    section = animation_section(data)
    embedded = section.split('class="anim-data">')[1].split("</script>")[0]
    assert json.loads(embedded) == json.loads(json.dumps(data))
    report = {"design": "x", "mechanism": "planting"}
    page = render_html(report, animation=data)
    assert page == render_html(report, animation=data)          # same input, same bytes
    # without animation or 3D view, the only script is the contents' (cadgen/report/toc.js)
    assert '<a href="#animation">' in page
    assert re.findall(r"<script[^>]*>", render_html(report)) == ['<script id="cadgen-toc-script">']


def test_viewer_takes_binary_gltf_only():
    from cadgen.report.viewer import interactive_sections, viewer_section

    assert interactive_sections() == [] and viewer_section(None) == ""
    with pytest.raises(ValueError, match="binary glTF"):
        viewer_section(b"solid ascii stl")
    section = viewer_section(b"glTF" + bytes(16))
    assert 'id="cadgen-glb">Z2xURg' in section and "CadgenThree" in section
    # the GLB, three.js, the explode helpers, the viewer: none cut short
    assert section.count("</script>") == 4 and "CadgenExplode" in section


# ---------------------------------------------------------------- contents, folding, the 3D view
#: The page's anchors in order, from the DOM (an independent list of what the contents list).
_ANCHORS_JS = """() => ['verdict'].concat(Array.from(document.querySelectorAll('main > section'))
  .map(s => s.id))"""
_CURRENT_JS = """() => { const a = document.querySelector('nav.toc a[aria-current]');
  return a ? a.getAttribute('href').slice(1) : null; }"""
#: Sections taller than most of the window (open ones): scrolled to the top, the one in view.
_TALL_JS = """() => Array.from(document.querySelectorAll('main > section'))
  .filter(s => s.getBoundingClientRect().height > 0.6 * window.innerHeight).map(s => s.id)"""


def _open(browser, path, width=1280, scripts=True):
    context = browser.new_context(viewport={"width": width, "height": 900},
                                  java_script_enabled=scripts)
    page = context.new_page()
    page.goto(Path(path).resolve().as_uri(), wait_until="load")
    return context, page


@pytest.mark.parametrize("design", ["xin2024-planter", "kernel-a"], ids=["planting", "pricking"])
def test_the_contents_list_every_section_and_mark_the_one_in_view(browser, reports, design):
    context, page = _open(browser, reports[design])
    try:
        anchors = page.evaluate(_ANCHORS_JS)
        links = page.eval_on_selector_all("nav.toc ol a", "l => l.map(a => a.hash.slice(1))")
        assert links == anchors and len(anchors) >= 8
        assert page.evaluate(_CURRENT_JS) == "verdict"
        tall = page.evaluate(_TALL_JS)
        for anchor in (tall[len(tall) // 2], tall[-1]):
            page.evaluate(f"document.getElementById('{anchor}').scrollIntoView()")
            page.wait_for_function(f"({_CURRENT_JS})() === '{anchor}'")
            # the contents stay in sight beside the page, the marked link inside them
            toc = page.locator("nav.toc").bounding_box()
            mark = page.locator("nav.toc a[aria-current]").bounding_box()
            assert toc["y"] == 0 and toc["x"] == 0 and toc["width"] < 300
            assert 0 <= mark["y"] and mark["y"] + mark["height"] <= 900
    finally:
        context.close()


def test_sections_fold_and_the_contents_fold_them_all(browser, reports):
    context, page = _open(browser, reports["xin2024-planter"])
    try:
        height = page.evaluate("document.documentElement.scrollHeight")
        anchor = page.evaluate(_TALL_JS)[0]
        section, summary = page.locator(f"#{anchor}"), page.locator(f"#{anchor} summary")
        fold = page.locator(f"#{anchor} details.fold")
        assert section.bounding_box()["height"] > 3 * summary.bounding_box()["height"]
        summary.click()
        assert fold.get_attribute("open") is None
        folded = section.bounding_box()["height"]
        assert folded < summary.bounding_box()["height"] + 60   # the heading and its margins
        assert page.evaluate("document.documentElement.scrollHeight") < height
        # a link of the contents opens the folded section it leads to
        page.locator(f"nav.toc a[href='#{anchor}']").click()
        assert fold.get_attribute("open") is not None
        page.locator("nav.toc button[data-fold='close']").click()
        closed = page.evaluate("Array.from(document.querySelectorAll('details.fold'))"
                               ".every(d => !d.open)")
        assert closed and page.locator("header table").first.is_visible()   # the verdict stays
        all_folded = page.evaluate("document.documentElement.scrollHeight")
        assert all_folded < height / 3
        page.locator("nav.toc button[data-fold='open']").click()
        assert page.evaluate("Array.from(document.querySelectorAll('details.fold'))"
                             ".every(d => d.open)")
    finally:
        context.close()


def test_a_narrow_window_gets_the_contents_as_a_bar(browser, reports):
    context, page = _open(browser, reports["xin2024-planter"], width=820)
    try:
        anchor = page.evaluate(_TALL_JS)[-1]
        page.evaluate(f"document.getElementById('{anchor}').scrollIntoView()")
        page.wait_for_function(f"({_CURRENT_JS})() === '{anchor}'")
        bar = page.locator("nav.toc").bounding_box()
        assert bar["y"] == 0 and bar["height"] < 80 and bar["width"] >= 800
        # the marked link scrolled into the bar's view
        mark = page.locator("nav.toc a[aria-current]").bounding_box()
        assert 0 <= mark["x"] and mark["x"] + mark["width"] <= 820
        # the section's heading is not under the bar
        heading = page.locator(f"#{anchor} summary").bounding_box()
        assert heading["y"] >= bar["height"] - 1
    finally:
        context.close()


def test_the_page_reads_without_scripts(browser, reports):
    context, page = _open(browser, reports["kernel-a"], scripts=False)
    try:
        links = page.locator("nav.toc ol a")
        assert links.count() == page.locator("main > section").count() + 1
        assert links.first.is_visible()
        assert not page.locator("nav.toc .toc-fold").is_visible()   # needs the script
        assert page.locator("header table").first.is_visible()
        # a folded section opens by its heading, natively
        folded = page.locator("details.fold:not([open])").first.element_handle()
        folded.query_selector("summary").click()
        assert folded.get_attribute("open") is not None
    finally:
        context.close()


@pytest.mark.parametrize("design", ["xin2024-planter", "kernel-a"], ids=["planting", "pricking"])
def test_the_3d_view_shows_every_part_of_the_file_named_and_placed(browser, reports, design):
    import io

    import numpy as np
    import trimesh

    glb = (reports[design].parent / "solids" / "assembly.glb").read_bytes()
    scene = trimesh.load_scene(io.BytesIO(glb), file_type="glb", process=False)
    expected = {}
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        placed = trimesh.transform_points(scene.geometry[geometry].vertices, transform)
        expected[node] = np.r_[placed.min(axis=0), placed.max(axis=0)]
    context, page = _open(browser, reports[design])
    try:
        page.wait_for_function("window.cadgenViewer && window.cadgenViewer.state === 'ready'")
        parts = page.evaluate("window.cadgenViewer.parts")
        embedded = page.evaluate("document.getElementById('cadgen-glb').textContent.length")
    finally:
        context.close()
    assert set(parts) == set(expected)
    for name, box in expected.items():   # same place, within the thinning's tolerance (m)
        assert np.allclose(parts[name], box, atol=1.5e-4), name
    assert embedded < len(glb) * 4 / 3   # the page embeds less than the file's base64


@pytest.mark.parametrize("design", ["xin2024-planter", "kernel-a"], ids=["planting", "pricking"])
def test_the_explode_slider_moves_each_part_by_its_offset(browser, reports, design):
    """The slider at t moves each part by t times the offset its GLB node carries (extras
    "explode", metres) and every part stays in the picture (the camera follows); back at 0
    every part is where the file places it."""
    import numpy as np

    from cadgen.report.view_glb import read_glb

    gltf, _ = read_glb((reports[design].parent / "solids" / "assembly.glb").read_bytes())
    offsets = {node["name"]: np.array(node["extras"]["explode"]) for node in gltf["nodes"]
               if "explode" in node.get("extras", {})}
    assert len(offsets) >= 5
    context, page = _open(browser, reports[design])
    try:
        page.wait_for_function("window.cadgenViewer && window.cadgenViewer.state === 'ready'")
        assembled = page.evaluate("window.cadgenViewer.parts")
        assert page.evaluate("window.cadgenViewer.exploding") == len(offsets)
        assert page.evaluate("window.cadgenViewer.inPicture") is True
        slider = page.locator(".viewer-explode input")
        assert slider.is_visible()
        found = {}
        for t in ("1", "0.5", "0"):
            slider.fill(t)
            page.wait_for_function(f"window.cadgenViewer.explode === {t}")
            found[t] = (page.evaluate("window.cadgenViewer.parts"),
                        page.evaluate("window.cadgenViewer.inPicture"))
    finally:
        context.close()
    for t, (parts, in_picture) in found.items():
        assert in_picture, t
        for name, box in assembled.items():
            moved = float(t) * offsets.get(name, np.zeros(3))
            assert np.allclose(parts[name], np.r_[np.add(box[:3], moved), np.add(box[3:], moved)],
                               atol=1e-6), (t, name)
    # fully apart the parts' boxes spread further than assembled, along the shaft axes (z)
    spread = {t: np.ptp([b[i] for n, b in parts.items() if not n.startswith("ground")
                         for i in (2, 5)]) for t, (parts, _) in found.items()}
    assert spread["1"] > 1.5 * spread["0"]
