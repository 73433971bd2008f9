#!/usr/bin/env python3
"""Screenshot a cadgen HTML report with headless Chromium, to look at its layout.

Usage::

    python scripts/render_report.py outputs/xin2024-planter/report.html --png /tmp/report.png
    python scripts/render_report.py report.html --png shot.png --width 1000 --height 9000

Chromium runs headless, offline-minded (no sync, no component updates, no QUIC,
no background networking) with a fresh throw-away profile, and writes one PNG of
the top ``--height`` pixels of the page at ``--width`` pixels wide. Headless
Chromium cannot size the window to the page, so choose a tall height for a whole
report (the default is 8000) and expect blank space below a short one.

On Debian or Ubuntu: ``apt-get install -y chromium``. Another binary can be given
with ``--chromium`` or the ``CHROMIUM`` environment variable.

Exit status: 0 when the PNG was written, 2 when Chromium or the page is missing,
1 when Chromium failed.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

CANDIDATES = ("/usr/bin/chromium", "chromium", "chromium-browser", "google-chrome",
              "google-chrome-stable")


def find_chromium(explicit: str | None = None) -> str | None:
    """The Chromium executable: ``explicit`` if given, else ``$CHROMIUM`` or the first found."""
    names = [explicit] if explicit else [os.environ.get("CHROMIUM"), *CANDIDATES]
    for name in names:
        if name:
            found = shutil.which(name)
            if found:
                return found
    return None


def chromium_command(chromium: str, page: Path, png: Path, profile: Path,
                     width: int, height: int) -> list[str]:
    """The headless screenshot command for ``page`` (an existing file)."""
    return [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
            "--no-first-run", "--disable-background-networking", "--disable-component-update",
            "--disable-sync", "--hide-scrollbars", f"--user-data-dir={profile}",
            f"--screenshot={png}", f"--window-size={width},{height}", page.resolve().as_uri()]


def render(page: Path, png: Path, width: int = 1400, height: int = 8000,
           chromium: str | None = None, timeout: float = 120.0) -> Path:
    """Write a screenshot of ``page`` to ``png``; raise ``RuntimeError`` when it fails."""
    page, png = Path(page), Path(png).resolve()
    if not page.is_file():
        raise FileNotFoundError(f"no report at {page}")
    executable = find_chromium(chromium)
    if executable is None:
        raise FileNotFoundError(
            f"Chromium was not found (tried {chromium or ', '.join(CANDIDATES)})"
            + "; install it, e.g. `apt-get install -y chromium` on Debian or Ubuntu")
    png.parent.mkdir(parents=True, exist_ok=True)
    if png.exists():
        png.unlink()  # so a stale file is never mistaken for this run's screenshot
    with tempfile.TemporaryDirectory(prefix="render-report-") as profile:
        command = chromium_command(executable, page, png, Path(profile), width, height)
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired as error:
            raise RuntimeError(f"Chromium did not finish within {timeout:g} s") from error
    if done.returncode != 0 or not png.is_file():
        raise RuntimeError(f"Chromium failed (exit {done.returncode}) and wrote no {png}:\n"
                           + done.stderr[-2000:])
    return png


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("page", type=Path, help="the report.html to render")
    parser.add_argument("--png", type=Path, required=True, help="where to write the screenshot")
    parser.add_argument("--width", type=int, default=1400, help="window width in px (1400)")
    parser.add_argument("--height", type=int, default=8000, help="window height in px (8000)")
    parser.add_argument("--chromium", help="Chromium executable (default: $CHROMIUM or PATH)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds to wait (120)")
    args = parser.parse_args(argv)
    if args.width < 200 or args.height < 200:
        parser.error(f"window size must be at least 200 x 200, not {args.width} x {args.height}")
    try:
        png = render(args.page, args.png, args.width, args.height, args.chromium, args.timeout)
    except FileNotFoundError as error:
        print(f"render_report: {error}", file=sys.stderr)
        return 2
    except RuntimeError as error:
        print(f"render_report: {error}", file=sys.stderr)
        return 1
    print(f"wrote {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
