"""report.html of both mechanisms in headless Chromium: layout, images, the 3D view, the animation.

Debian's Chromium (``/usr/bin/chromium``) driven by Playwright for Python, with no
``playwright install``. Without Chromium or Playwright the test is skipped locally
and fails in CI (``CI=true``), where ``.ci/run`` installs Chromium first.

The checks (shared with ``scripts/report_screenshots.py``): nothing wider than the
viewport (at 1280 px), every image loaded, the 3D view loaded the embedded
GLB and drew it (pixels unlike its background), the animation's frame advances,
no script error, and nothing fetched but the page itself.
"""

import time
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
    start = time.perf_counter()
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
        # the housings' covers come off and back: gearbox 1's and each arm's gearbox 2's
        covers = {"xin2024-planter": 3, "kernel-a": 1}[design]
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
    assert time.perf_counter() - start < 15


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
    assert '<a href="#animation">' in page and "<script" not in render_html(report)


def test_viewer_takes_binary_gltf_only():
    from cadgen.report.viewer import interactive_sections, viewer_section

    assert interactive_sections() == [] and viewer_section(None) == ""
    with pytest.raises(ValueError, match="binary glTF"):
        viewer_section(b"solid ascii stl")
    section = viewer_section(b"glTF" + bytes(16))
    assert 'id="cadgen-glb">Z2xURg' in section and "CadgenThree" in section
    assert section.count("</script>") == 3   # the GLB, three.js, the viewer: none cut short
