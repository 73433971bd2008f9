#!/usr/bin/env python3
"""Measure cadgen report pages: size in bytes, height at a window width, the embedded 3D model.

Usage::

    python scripts/report_measure.py outputs/*/report.html
    python scripts/report_measure.py outputs/*/report.html --width 1280 --shots /tmp/shots

For each page it prints one line: the file's size; the page's full height in CSS
pixels at ``--width`` (Playwright in headless Chromium) as it opens, with every
foldable section open, and with every one folded; the size of the GLB embedded for
the 3D view beside ``solids/assembly.glb`` next to the page, and the vertex counts of
both (every mesh once, as stored). With ``--shots`` it also writes, per page,
``<design>-top.png`` (the first screen), ``<design>-toc-middle.png`` (the window
scrolled half way, the table of contents highlighting the section in view),
``<design>-folded.png`` (the first folded section) and ``<design>-view-3d.png``.

Chromium and Playwright as for ``scripts/report_screenshots.py`` (whose launch and
page helpers this uses). Exit status: 0, or 2 when Chromium or Playwright is missing.
"""

from __future__ import annotations

import argparse
import base64
import json
import re
import struct
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: The page's height as it opens, with every foldable section open, and with every one closed.
_HEIGHTS_JS = """() => {
  const root = document.documentElement;
  const folds = Array.from(document.querySelectorAll('details.fold'));
  const before = folds.map(d => d.open);
  const opened = root.scrollHeight;
  folds.forEach(d => d.open = true);
  const unfolded = root.scrollHeight;
  folds.forEach(d => d.open = false);
  const folded = root.scrollHeight;
  folds.forEach((d, k) => d.open = before[k]);
  return {opened, unfolded, folded, sections: folds.length};
}"""


def _screenshots_module():
    import importlib.util

    spec = importlib.util.spec_from_file_location("report_screenshots",
                                                  REPO / "scripts" / "report_screenshots.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def glb_of(page_text: str) -> bytes | None:
    """The GLB the page embeds for its 3D view, or None."""
    match = re.search(r'<script type="application/octet-stream" id="cadgen-glb">([^<]*)</script>',
                      page_text)
    return base64.b64decode(match[1]) if match else None


def vertices(glb: bytes | None) -> int | None:
    """The vertex count of a binary glTF: its meshes' POSITION accessors, each mesh once."""
    if glb is None:
        return None
    length = struct.unpack_from("<I", glb, 12)[0]
    gltf = json.loads(glb[20:20 + length])
    return sum(gltf["accessors"][p["attributes"]["POSITION"]]["count"]
               for mesh in gltf.get("meshes", []) for p in mesh["primitives"])


def measure(browser, shots_module, page_path: Path, width: int, shots: Path | None) -> dict:
    text = page_path.read_text(encoding="utf-8")
    embedded = glb_of(text)
    full = page_path.parent / "solids" / "assembly.glb"
    row = {"page": str(page_path), "bytes": page_path.stat().st_size,
           "glb_embedded": len(embedded) if embedded else None,
           "glb_file": full.stat().st_size if full.is_file() else None,
           "vertices_embedded": vertices(embedded),
           "vertices_file": vertices(full.read_bytes()) if full.is_file() else None}
    page, _, _ = shots_module.open_report(browser, page_path, width=width)
    try:
        page.wait_for_function("document.readyState === 'complete'")
        if page.locator("#cadgen-viewer").count():
            page.wait_for_function(
                "window.cadgenViewer && window.cadgenViewer.state !== 'loading'", timeout=30000)
        row.update(page.evaluate(_HEIGHTS_JS))
        if shots is not None:
            shots.mkdir(parents=True, exist_ok=True)
            stem = page_path.parent.name
            page.screenshot(path=str(shots / f"{stem}-top.png"))
            page.evaluate("window.scrollTo(0, document.documentElement.scrollHeight / 2)")
            page.wait_for_timeout(300)
            page.screenshot(path=str(shots / f"{stem}-toc-middle.png"))
            first = page.locator("details.fold").first
            if first.count():
                first.evaluate("d => { d.open = false; d.scrollIntoView(); }")
                page.wait_for_timeout(200)
                page.screenshot(path=str(shots / f"{stem}-folded.png"))
                first.evaluate("d => { d.open = true; }")
            if page.locator("#view-3d").count():
                page.locator("#view-3d").scroll_into_view_if_needed()
                page.wait_for_timeout(300)
                page.locator("#view-3d").screenshot(path=str(shots / f"{stem}-view-3d.png"))
    finally:
        page.close()
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pages", nargs="+", type=Path, help="report.html files")
    parser.add_argument("--width", type=int, default=1280, help="window width in px (1280)")
    parser.add_argument("--shots", type=Path, help="folder for screenshots (none by default)")
    parser.add_argument("--chromium", help="Chromium executable (default: $CHROMIUM or PATH)")
    args = parser.parse_args(argv)
    shots_module = _screenshots_module()
    chromium = shots_module.find_chromium(args.chromium)
    if chromium is None:
        print("report_measure: Chromium was not found; apt-get install -y chromium",
              file=sys.stderr)
        return 2
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        print("report_measure: Playwright is missing; pip install playwright", file=sys.stderr)
        return 2
    with sync_playwright() as playwright:
        browser = shots_module.launch(playwright, chromium)
        for page_path in args.pages:
            row = measure(browser, shots_module, page_path, args.width, args.shots)
            glb = ("no 3D view" if row["glb_embedded"] is None else
                   f"3D view {row['glb_embedded']:,} B ({row['vertices_embedded']:,} vertices) "
                   f"of assembly.glb {row['glb_file']:,} B ({row['vertices_file']:,} vertices)")
            print(f"{row['page']}: {row['bytes']:,} B; {row['opened']:,} px tall at {args.width} px"
                  f" as it opens, {row['unfolded']:,} px with every section open, "
                  f"{row['folded']:,} px with its {row['sections']} sections folded; {glb}")
        browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
