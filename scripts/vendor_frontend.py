#!/usr/bin/env python3
"""Vendor the studio's front-end libraries into the package (run by a maintainer, not by pip).

Usage::

    python scripts/vendor_frontend.py            # writes cadgen/studio/static/vendor/uplot/
    python scripts/vendor_frontend.py --check    # verifies the vendored files, writes nothing

The studio works offline and ``pip install`` needs no node, so every front-end
file it serves is committed under ``cadgen/studio/static/vendor/``. This script
is how they got there: npm's own client (``npm view`` and ``npm pack``, so the
registry is whatever npm is configured with) fetches the package's tarball at a
pinned version; the tarball must match both the registry's ``dist.integrity``
(SHA-512) and the SHA-256 pinned below, or nothing is written. Only the files
the page loads and the licence are extracted, and a README beside them records
the package, version, licence, each file's SHA-256 and this command.

The three.js bundle is not here: the studio's server serves the report's
(``cadgen/report/vendor/three-viewer.min.js``, its own README says how it was made).

Exit status: 0 done (or ``--check`` passed), 1 a digest did not match, 2 npm missing.
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import io
import json
import shutil
import subprocess
import sys
import tarfile
import tempfile
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
VENDOR = REPO / "cadgen" / "studio" / "static" / "vendor"


@dataclass(frozen=True)
class Package:
    """One npm package to vendor: what to take out of its tarball, and its pinned digests."""

    name: str
    version: str
    licence: str
    #: the registry's ``dist.integrity`` for this version (SSRI: ``sha512-<base64>``)
    integrity: str
    #: SHA-256 of the tarball itself, pinned so a changed registry answer is caught too
    tarball_sha256: str
    #: tarball member (under ``package/``) -> file name in the vendor folder
    files: dict
    folder: str
    purpose: str


UPLOT = Package(
    name="uplot", version="1.6.32", licence="MIT",
    integrity="sha512-KIMVnG68zvu5XXUbC4LQEPnhwOxBuLyW1AHtpm6IKTXImkbLgkMy+jabjLgSLMasNuGGzQm/"
              "ep3tOkyTxpiQIw==",
    tarball_sha256="4b8a8191e425658e3ea8c8c1314b0fc679c861ee3a1af2b20c7b16ba50b5133d",
    files={"dist/uPlot.iife.min.js": "uPlot.iife.min.js", "dist/uPlot.min.css": "uPlot.min.css",
           "LICENSE": "LICENSE"},
    folder="uplot",
    purpose="the studio's plots against carrier angle (attitude, tip speed, the pricking "
            "mechanism's ratio); loaded as a classic script that defines `window.uPlot`",
)

PACKAGES = (UPLOT,)


class VendorError(RuntimeError):
    """A digest did not match, or npm failed: nothing was written."""


def _npm(*args: str, cwd: Path | None = None) -> str:
    npm = shutil.which("npm")
    if npm is None:
        raise FileNotFoundError("npm is not installed (apt-get install -y npm)")
    done = subprocess.run([npm, *args], cwd=cwd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise VendorError(f"npm {' '.join(args)} failed: {done.stderr.strip()[-400:]}")
    return done.stdout


def _sri_sha512(data: bytes) -> str:
    return "sha512-" + base64.b64encode(hashlib.sha512(data).digest()).decode("ascii")


def fetch_tarball(package: Package, folder: Path) -> bytes:
    """The package's tarball, checked against the registry's integrity and the pinned digests."""
    spec = f"{package.name}@{package.version}"
    registry_integrity = json.loads(_npm("view", spec, "dist.integrity", "--json"))
    if registry_integrity != package.integrity:
        raise VendorError(f"{spec}: the registry's integrity {registry_integrity} is not the "
                          f"pinned {package.integrity}")
    packed = json.loads(_npm("pack", spec, "--json", "--pack-destination", str(folder)))
    data = (folder / packed[0]["filename"]).read_bytes()
    if _sri_sha512(data) != package.integrity:
        raise VendorError(f"{spec}: the tarball's SHA-512 {_sri_sha512(data)} is not the "
                          f"registry's {package.integrity}")
    sha256 = hashlib.sha256(data).hexdigest()
    if sha256 != package.tarball_sha256:
        raise VendorError(f"{spec}: the tarball's SHA-256 {sha256} is not the pinned "
                          f"{package.tarball_sha256}")
    return data


def extract(package: Package, tarball: bytes) -> dict[str, bytes]:
    """The wanted members' bytes (by their vendored names); only regular files, named exactly."""
    out = {}
    with tarfile.open(fileobj=io.BytesIO(tarball), mode="r:gz") as archive:
        for member, target in package.files.items():
            info = archive.getmember(f"package/{member}")
            if not info.isfile():
                raise VendorError(f"{package.name}: {member} is not a regular file in the tarball")
            out[target] = archive.extractfile(info).read()
    return out


def readme(package: Package, files: dict[str, bytes]) -> str:
    rows = "\n".join(f"| `{name}` | {len(data):,} | `{hashlib.sha256(data).hexdigest()}` |"
                     for name, data in files.items())
    return (
        f"# Vendored: {package.name} {package.version} ({package.licence})\n\n"
        f"npm package `{package.name}@{package.version}`, licence {package.licence} (`LICENSE`, "
        f"the package's own), for {package.purpose}.\n\n"
        "Written by `python scripts/vendor_frontend.py` (npm's client: `npm view` + `npm pack`), "
        "which checks the tarball against the registry's `dist.integrity` "
        f"(`{package.integrity}`) and the SHA-256 pinned in the script "
        f"(`{package.tarball_sha256}`) before writing anything; "
        "`python scripts/vendor_frontend.py --check` re-verifies these files.\n\n"
        "| file | bytes | SHA-256 |\n|---|---:|---|\n"
        f"{rows}\n")


def vendor(package: Package, *, check: bool = False) -> list[str]:
    """Write (or with ``check`` compare) the package's vendored files; the lines to print."""
    target = VENDOR / package.folder
    with tempfile.TemporaryDirectory(prefix="cadgen-vendor-") as folder:
        files = extract(package, fetch_tarball(package, Path(folder)))
    files["README.md"] = readme(package, files).encode("utf-8")
    if check:
        stale = [name for name, data in files.items()
                 if not (target / name).is_file() or (target / name).read_bytes() != data]
        if stale:
            raise VendorError(f"{target}: differs from {package.name}@{package.version}: "
                              + ", ".join(stale))
        return [f"{target}: matches {package.name}@{package.version}"]
    target.mkdir(parents=True, exist_ok=True)
    for name, data in files.items():
        (target / name).write_bytes(data)
    return [f"wrote {target / name} ({len(data):,} bytes)" for name, data in files.items()]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="verify the vendored files against the pinned packages; write nothing")
    args = parser.parse_args(argv)
    try:
        for package in PACKAGES:
            for line in vendor(package, check=args.check):
                print(line)
    except FileNotFoundError as error:
        print(f"vendor_frontend: {error}", file=sys.stderr)
        return 2
    except VendorError as error:
        print(f"vendor_frontend: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
