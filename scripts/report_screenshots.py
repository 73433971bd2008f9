#!/usr/bin/env python3
"""Screenshots of cadgen reports' animation and 3D view, in headless Chromium (Playwright).

Usage::

    python scripts/report_screenshots.py                      # builds both bundled examples
    python scripts/report_screenshots.py outputs/*/report.html --out /tmp/shots

With no report given, it builds ``params/xin2024-planter.toml`` and
``params/kernel-a.toml`` (their files' scenes) into a temporary folder. For each
report it writes ``<design>-animation.png`` and ``<design>-view-3d.png`` (those two
sections) and ``<design>-top.png`` (the first screen), and prints what the page
checks found: layout overflow, images that did not load, the viewer's state and
how much it drew, whether the animation advanced.

Chromium is Debian's (``apt-get install -y chromium``), driven by Playwright for
Python (``pip install playwright``; no ``playwright install``: the system browser is
used). Another binary: ``--chromium`` or ``$CHROMIUM``. The browser runs with
``--disable-gpu``; WebGL then falls back to Chromium's software renderer.

Exit status: 0 when every page passed its checks, 1 when one did not, 2 when
Chromium or Playwright is missing.

The functions here (:func:`launch`, :func:`open_report`, :func:`page_report`) are
what ``tests/test_report_browser.py`` uses too.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = ("params/xin2024-planter.toml", "params/kernel-a.toml")
CHROMIUM_ARGS = ["--no-sandbox", "--headless=new", "--disable-gpu"]
CANDIDATES = ("/usr/bin/chromium", "chromium", "chromium-browser")

#: Every element's box against the viewport; an element inside a container that clips or
#: scrolls sideways (overflow-x other than visible) is that container's business, not the page's.
_OVERFLOW_JS = """() => {
  const width = document.documentElement.clientWidth, bad = [];
  for (const el of document.body.querySelectorAll('*')) {
    const box = el.getBoundingClientRect();
    if ((box.width === 0 && box.height === 0) || (box.right <= width + 0.5 && box.left >= -0.5))
      continue;
    let parent = el.parentElement, clipped = false;
    for (; parent && parent !== document.body; parent = parent.parentElement)
      if (getComputedStyle(parent).overflowX !== 'visible') { clipped = true; break; }
    if (!clipped) bad.push(`${el.tagName.toLowerCase()}${el.id ? '#' + el.id : ''}` +
      `${el.className && el.className.baseVal === undefined && el.className ? '.' + el.className : ''}` +
      ` spans ${Math.round(box.left)}..${Math.round(box.right)} px`);
  }
  return {scrollWidth: document.documentElement.scrollWidth, innerWidth: window.innerWidth,
          overflowing: bad};
}"""

#: The WebGL canvas copied to a small 2D canvas: the share of pixels unlike the background.
_PIXELS_JS = """() => {
  const source = document.querySelector('#cadgen-viewer canvas');
  if (!source) return null;
  const copy = document.createElement('canvas');
  copy.width = 96; copy.height = 64;
  const context = copy.getContext('2d');
  context.drawImage(source, 0, 0, copy.width, copy.height);
  const data = context.getImageData(0, 0, copy.width, copy.height).data;
  let drawn = 0;
  for (let i = 0; i < data.length; i += 4) {
    const d = Math.abs(data[i] - 0xf4) + Math.abs(data[i + 1] - 0xf5) + Math.abs(data[i + 2] - 0xf7);
    if (d > 24) drawn += 1;
  }
  return drawn / (copy.width * copy.height);
}"""

_IMAGES_JS = """() => Array.from(document.images).map(img => ({
  alt: img.alt, complete: img.complete, width: img.naturalWidth}))"""


def find_chromium(explicit: str | None = None) -> str | None:
    """The Chromium executable: ``explicit``, else ``$CHROMIUM``, else the first found."""
    for name in ([explicit] if explicit else [os.environ.get("CHROMIUM"), *CANDIDATES]):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def launch(playwright, chromium: str):
    """Headless Chromium from ``chromium`` (a system binary), offline-minded."""
    return playwright.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)


def open_report(browser, page_path: Path, width: int = 1280, height: int = 900):
    """A new page showing ``page_path``; returns ``(page, requests, errors)`` as lists that
    keep filling: every URL requested and every script error or console error."""
    page = browser.new_page(viewport={"width": width, "height": height})
    requests, errors = [], []
    page.on("request", lambda request: requests.append(request.url))
    page.on("pageerror", lambda error: errors.append(f"page error: {error}"))
    page.on("console", lambda message: errors.append(f"console: {message.text}")
            if message.type == "error" else None)
    page.goto(Path(page_path).resolve().as_uri(), wait_until="load")
    return page, requests, errors


def page_report(page, wait_ms: int = 800) -> dict:
    """What the checks look at, on an open report page.

    ``layout`` (scroll width, viewport width, overflowing elements), ``images``
    (alt, complete, natural width each), ``viewer`` (``window.cadgenViewer``: state,
    meshes, renders; ``pixels``: the share drawn), ``frames`` (the animation's frame
    index now and ``wait_ms`` later, per animation).
    """
    page.wait_for_function("document.readyState === 'complete'")
    has_viewer = page.locator("#cadgen-viewer").count() > 0
    if has_viewer:
        page.wait_for_function("window.cadgenViewer && window.cadgenViewer.state !== 'loading'",
                               timeout=15000)
    before = page.evaluate("(window.cadgenAnimations || []).map(a => a.frame)")
    page.wait_for_timeout(wait_ms)
    after = page.evaluate("(window.cadgenAnimations || []).map(a => a.frame)")
    return {"layout": page.evaluate(_OVERFLOW_JS), "images": page.evaluate(_IMAGES_JS),
            "viewer": page.evaluate("window.cadgenViewer || null") if has_viewer else None,
            "pixels": page.evaluate(_PIXELS_JS) if has_viewer else None,
            "frames": list(zip(before, after)),
            "animation_errors": page.evaluate(
                "Array.from(document.querySelectorAll('.cadgen-animation[data-error]'))"
                ".map(e => e.dataset.error)")}


def problems_of(found: dict, requests: list, errors: list, page_url: str) -> list[str]:
    """Every check a page failed, as sentences (empty when it passed)."""
    out = []
    layout = found["layout"]
    if layout["scrollWidth"] > layout["innerWidth"]:
        out.append(f"page scrolls sideways: {layout['scrollWidth']} > {layout['innerWidth']} px")
    out += [f"overflows the viewport: {text}" for text in layout["overflowing"][:10]]
    if not found["images"]:
        out.append("no images")
    out += [f"image did not load: {img['alt']}" for img in found["images"] if img["width"] <= 0]
    viewer = found["viewer"]
    if viewer is None:
        out.append("no 3D viewer")
    elif viewer.get("state") != "ready" or not viewer.get("meshes"):
        out.append(f"3D viewer did not start: {viewer}")
    elif not found["pixels"] or found["pixels"] < 0.01:
        out.append(f"3D viewer drew nothing ({found['pixels']!r} of its pixels)")
    if not found["frames"]:
        out.append("no animation")
    out += [f"animation did not advance (frame {a} then {b})" for a, b in found["frames"] if a == b]
    out += [f"animation failed: {text}" for text in found["animation_errors"]]
    fetched = [u for u in requests if u != page_url and not u.startswith(("data:", "blob:"))]
    out += [f"fetched {url}" for url in fetched]
    out += errors
    return out


def build_examples(folder: Path) -> list[Path]:
    """Build the bundled examples (their files' scenes) into ``folder``: their report pages."""
    sys.path.insert(0, str(REPO))
    from cadgen import build, load_params

    pages = []
    for name in EXAMPLES:
        result = build(load_params(REPO / name), folder)
        pages.append(result.output_dir / "report.html")
    return pages


def screenshots(pages, out: Path, chromium: str, width: int = 1280) -> int:
    from playwright.sync_api import sync_playwright

    out.mkdir(parents=True, exist_ok=True)
    failed = 0
    with sync_playwright() as playwright:
        browser = launch(playwright, chromium)
        for page_path in pages:
            start = time.perf_counter()
            page, requests, errors = open_report(browser, page_path, width)
            found = page_report(page)
            stem = Path(page_path).parent.name
            page.screenshot(path=str(out / f"{stem}-top.png"))   # before anything scrolls it
            written = [out / f"{stem}-top.png"]
            for section in ("animation", "view-3d"):
                if page.locator(f"#{section}").count():
                    target = out / f"{stem}-{section}.png"
                    page.locator(f"#{section}").screenshot(path=str(target))
                    written.append(target)
            problems = problems_of(found, requests, errors, page.url)
            failed += bool(problems)
            size = Path(page_path).stat().st_size / 1e6
            print(f"{page_path} ({size:.2f} MB, {time.perf_counter() - start:.1f} s): "
                  f"{'ok' if not problems else 'PROBLEMS'}; viewer {found['viewer']}, "
                  f"{found['pixels'] or 0:.0%} drawn, frames {found['frames']}")
            for problem in problems:
                print(f"  {problem}")
            for path in written:
                print(f"  wrote {path}")
            page.close()
        browser.close()
    return 1 if failed else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pages", nargs="*", type=Path,
                        help="report.html files (default: build the bundled examples)")
    parser.add_argument("--out", type=Path, default=Path("screenshots"),
                        help="folder for the PNGs (screenshots/)")
    parser.add_argument("--width", type=int, default=1280, help="viewport width in px (1280)")
    parser.add_argument("--chromium", help="Chromium executable (default: $CHROMIUM or PATH)")
    args = parser.parse_args(argv)
    chromium = find_chromium(args.chromium)
    if chromium is None:
        print("report_screenshots: Chromium was not found; apt-get install -y chromium",
              file=sys.stderr)
        return 2
    try:
        import playwright  # noqa: F401
    except ImportError:
        print("report_screenshots: Playwright is missing; pip install playwright", file=sys.stderr)
        return 2
    missing = [p for p in args.pages if not p.is_file()]
    if missing:
        print(f"report_screenshots: no report at {missing[0]}", file=sys.stderr)
        return 2
    if args.pages:
        return screenshots(args.pages, args.out, chromium, args.width)
    with tempfile.TemporaryDirectory(prefix="cadgen-shots-") as folder:
        return screenshots(build_examples(Path(folder)), args.out, chromium, args.width)


if __name__ == "__main__":
    sys.exit(main())
