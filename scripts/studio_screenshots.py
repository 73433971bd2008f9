#!/usr/bin/env python3
"""Screenshots of the cadgen studio's pages in headless Chromium (Playwright), to look at.

Usage::

    python scripts/studio_screenshots.py --out /tmp/studio-shots

It copies the bundled designs (``params/xin2024-planter.toml``, ``params/kernel-b.toml``)
to a temporary folder, runs a studio on each (``cadgen.studio.run.serve_in_thread``,
127.0.0.1, a free port) and writes:

- ``planting-loaded.png``: the planting page as it opens (1280 x 900), and
  ``planting-loaded-full.png`` (a tall window: every panel) and ``planting-1024.png``;
- ``planting-pinned.png``: the design pinned, then ``planter.L2`` changed (the pinned
  design faint on every plot, its column in the metrics table, the changed cells marked);
- ``planting-invalid.png``: two invalid values, their messages beside the fields;
- ``planting-animation.png`` and ``planting-animation-absolute.png``: the animation paused
  mid-cycle, relative and absolute at the first spacing;
- ``pricking-dragged.png`` (+ ``-full``): kernel-b after dragging a type-value point;
- ``pricking-animation.png``: its needle's motion mid-cycle.

It prints what the checks found on each page: sideways overflow, script or console
errors, requests that left 127.0.0.1. Exit status: 0 when none, 1 when some, 2 when
Chromium or Playwright is missing.

The helpers (:func:`start_studio`, :func:`open_studio`, :func:`wait_for_evaluation`,
:func:`drag_point`, :func:`page_problems`) are what ``tests/test_studio_browser.py`` uses.
"""

from __future__ import annotations

import argparse
import importlib.util
import shutil
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PLANTING, PRICKING = "xin2024-planter", "kernel-b"


def _report_shots():
    """scripts/report_screenshots.py: finding and launching Chromium, the overflow check."""
    spec = importlib.util.spec_from_file_location("report_screenshots",
                                                  REPO / "scripts" / "report_screenshots.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


REPORT_SHOTS = _report_shots()
find_chromium, launch = REPORT_SHOTS.find_chromium, REPORT_SHOTS.launch


def copy_design(name: str, folder: Path) -> Path:
    """A writable copy of the bundled design ``name`` in ``folder``."""
    target = folder / f"{name}.toml"
    shutil.copyfile(REPO / "params" / f"{name}.toml", target)
    return target


def start_studio(design: Path | None, output_root: Path):
    """A studio on 127.0.0.1 in a thread: ``(url_with_token, stop)``."""
    sys.path.insert(0, str(REPO))
    from cadgen.studio.run import serve_in_thread

    return serve_in_thread(design, output_root=output_root)


#: API answers the page expects and shows (invalid parameters, a name that exists); Chromium
#: logs every HTTP error response as a console error all the same.
_EXPECTED_STATUSES = ("status of 422", "status of 409")


def _expected_answer(message) -> bool:
    location = (message.location or {}).get("url", "")
    return ("/api/" in location and message.text.startswith("Failed to load resource")
            and any(status in message.text for status in _EXPECTED_STATUSES))


def open_studio(browser, url: str, width: int = 1280, height: int = 900):
    """A page on the studio at ``url``, after its first evaluation: ``(page, requests, errors)``,
    lists that keep filling (every URL requested; page errors and console errors)."""
    page = browser.new_page(viewport={"width": width, "height": height})
    requests, errors = [], []
    page.on("request", lambda request: requests.append(request.url))
    page.on("pageerror", lambda error: errors.append(f"page error: {error}"))
    page.on("console", lambda message: errors.append(f"console: {message.text}")
            if message.type == "error" and not _expected_answer(message) else None)
    page.goto(url, wait_until="load")
    page.wait_for_function("window.cadgenStudio && window.cadgenStudio.evaluations > 0",
                           timeout=20000)
    return page, requests, errors


def evaluations(page) -> int:
    return page.evaluate("window.cadgenStudio.evaluations")


def wait_for_evaluation(page, after: int, timeout: float = 15000) -> None:
    """Waits until the page has shown an answer newer than its ``after``-th."""
    page.wait_for_function(
        f"window.cadgenStudio.evaluations > {after} && window.cadgenStudio.state === 'ready'",
        timeout=timeout)


def set_field(page, path: str, text: str) -> None:
    """Types ``text`` into the form's field for ``path`` (as a person would: replaces it)."""
    page.locator(f'.field[data-path="{path}"] input').fill(text)


def drag_point(page, index: int, dx: float, dy: float, steps: int = 8) -> None:
    """Drags type-value point ``index`` by ``(dx, dy)`` screen pixels with the mouse."""
    handle = page.locator(f'.tv-point[data-index="{index}"]')
    handle.scroll_into_view_if_needed()
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + dx, y + dy, steps=steps)
    page.mouse.up()


def page_problems(page, requests: list, errors: list) -> list[str]:
    """What is wrong with an open studio page, as sentences (empty when nothing is)."""
    origin = page.url.split("/?")[0]
    layout = page.evaluate(REPORT_SHOTS._OVERFLOW_JS)
    out = []
    if layout["scrollWidth"] > layout["innerWidth"]:
        out.append(f"page scrolls sideways: {layout['scrollWidth']} > {layout['innerWidth']} px")
    out += [f"overflows the viewport: {text}" for text in layout["overflowing"][:10]]
    out += [f"requested {url}" for url in requests
            if not url.startswith((origin + "/", "data:", "blob:"))]
    return out + list(errors)


def _shoot_planting(browser, url: str, out: Path) -> tuple[list, list]:
    written, problems = [], []
    page, requests, errors = open_studio(browser, url)
    page.wait_for_timeout(400)
    page.screenshot(path=str(out / "planting-loaded.png"))
    written.append(out / "planting-loaded.png")
    page.set_viewport_size({"width": 1280, "height": 2600})
    page.wait_for_timeout(300)
    page.screenshot(path=str(out / "planting-loaded-full.png"))
    written.append(out / "planting-loaded-full.png")
    page.set_viewport_size({"width": 1024, "height": 800})
    page.wait_for_timeout(300)
    page.screenshot(path=str(out / "planting-1024.png"))
    written.append(out / "planting-1024.png")
    problems += [f"at 1024 px: {p}" for p in page_problems(page, [], [])]
    page.set_viewport_size({"width": 1280, "height": 2600})
    page.locator("#pin").click()
    before = evaluations(page)
    set_field(page, "planter.L2", "230")
    wait_for_evaluation(page, before)
    page.wait_for_timeout(300)
    page.screenshot(path=str(out / "planting-pinned.png"))
    written.append(out / "planting-pinned.png")
    # two invalid values: both messages beside their fields, the last valid picture greyed
    set_field(page, "planter.L1", "abc")
    set_field(page, "planter.L2", "-5")
    page.wait_for_function("window.cadgenStudio.state === 'invalid'"
                           " && window.cadgenStudio.problems.length >= 2")
    page.set_viewport_size({"width": 1280, "height": 900})
    page.locator('.field[data-path="planter.L1"]').scroll_into_view_if_needed()
    page.screenshot(path=str(out / "planting-invalid.png"))
    written.append(out / "planting-invalid.png")
    page.locator("#undo").click()
    page.locator("#undo").click()
    page.wait_for_function("window.cadgenStudio.state === 'ready'")
    page.set_viewport_size({"width": 1280, "height": 2600})
    page.locator("#unpin").click()
    page.locator(".anim-play").click() if page.locator(".player").get_attribute(
        "data-playing") == "true" else None
    page.locator(".anim-slider").fill(str(int(page.locator(".anim-slider").get_attribute("max")) // 2))
    page.locator("#panel-animation").screenshot(path=str(out / "planting-animation.png"))
    written.append(out / "planting-animation.png")
    page.locator(".player-options select").first.select_option("absolute")
    page.locator(".anim-event.lowest").click()   # the tip at its lowest point, in the soil
    page.locator("#panel-animation").screenshot(path=str(out / "planting-animation-absolute.png"))
    written.append(out / "planting-animation-absolute.png")
    written += _shoot_build(page, out, "planting")
    problems += page_problems(page, requests, errors)
    page.close()
    return written, problems


def _shoot_pricking(browser, url: str, out: Path) -> tuple[list, list]:
    written, problems = [], []
    page, requests, errors = open_studio(browser, url)
    page.locator("#pin").click()
    before = evaluations(page)
    drag_point(page, 3, 40, 25)
    wait_for_evaluation(page, before)
    page.wait_for_timeout(300)
    page.screenshot(path=str(out / "pricking-dragged.png"))
    written.append(out / "pricking-dragged.png")
    page.set_viewport_size({"width": 1280, "height": 2400})
    page.wait_for_timeout(300)
    page.screenshot(path=str(out / "pricking-dragged-full.png"))
    written.append(out / "pricking-dragged-full.png")
    if page.locator(".player").get_attribute("data-playing") == "true":
        page.locator(".anim-play").click()
    page.locator(".anim-slider").fill(str(int(page.locator(".anim-slider").get_attribute("max")) // 2))
    page.locator("#panel-animation").screenshot(path=str(out / "pricking-animation.png"))
    written.append(out / "pricking-animation.png")
    problems += page_problems(page, requests, errors)
    page.close()
    return written, problems


def _shoot_build(page, out: Path, name: str) -> list:
    """Press Build (the file's own scene: every effect), wait for the 3D view, shoot it with
    the covers on and off."""
    page.set_viewport_size({"width": 1280, "height": 1000})
    page.locator("#build").click()
    page.wait_for_function("document.querySelector('.viewer')"
                           " && document.querySelector('.viewer').dataset.state === 'ready'",
                           timeout=180000)
    page.wait_for_timeout(500)
    panel = page.locator("#panel-build")
    panel.scroll_into_view_if_needed()
    written = [out / f"{name}-build.png", out / f"{name}-build-covers-hidden.png"]
    panel.screenshot(path=str(written[0]))
    page.locator(".viewer-buttons button", has_text="Hide housing covers").click()
    page.wait_for_timeout(300)
    panel.screenshot(path=str(written[1]))
    return written


def screenshots(out: Path, chromium: str) -> int:
    from playwright.sync_api import sync_playwright

    out.mkdir(parents=True, exist_ok=True)
    failed = 0
    with tempfile.TemporaryDirectory(prefix="cadgen-studio-shots-") as folder, \
            sync_playwright() as playwright:
        browser = launch(playwright, chromium)
        for name, shoot in ((PLANTING, _shoot_planting), (PRICKING, _shoot_pricking)):
            url, stop = start_studio(copy_design(name, Path(folder)), Path(folder) / "outputs")
            try:
                written, problems = shoot(browser, url, out)
            finally:
                stop()
            failed += bool(problems)
            print(f"{name}: {'ok' if not problems else 'PROBLEMS'}")
            for problem in problems:
                print(f"  {problem}")
            for path in written:
                print(f"  wrote {path}")
        browser.close()
    return 1 if failed else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("screenshots/studio"),
                        help="folder for the PNGs (screenshots/studio/)")
    parser.add_argument("--chromium", help="Chromium executable (default: $CHROMIUM or PATH)")
    args = parser.parse_args(argv)
    chromium = find_chromium(args.chromium)
    if chromium is None:
        print("studio_screenshots: Chromium was not found; apt-get install -y chromium",
              file=sys.stderr)
        return 2
    try:
        import playwright  # noqa: F401
    except ImportError:
        print("studio_screenshots: Playwright is missing; pip install playwright", file=sys.stderr)
        return 2
    return screenshots(args.out, chromium)


if __name__ == "__main__":
    sys.exit(main())
