"""Compare two output trees file by file: the check that a refactor changed no output.

    python scripts/compare_outputs.py [--loose-dxf] BEFORE_DIR AFTER_DIR

Bytes, except what differs between two runs of the same code: the stage times in
report.json and report.html. ``--loose-dxf`` also ignores the order of the CLASSES and
OBJECTS sections of DXF files, for outputs made before the writer fixed the CLASSES order
(it depended on the string hashing, run to run). Prints each file found in one tree only or
differing, then the counts; exits 1 if any differs.
"""
import json, re, sys
from pathlib import Path

def dxf_canonical(data: bytes) -> bytes:
    text = data.decode("utf-8", "replace")
    lines = text.split("\n")
    out, skip = [], False
    for i, line in enumerate(lines):
        if line.strip() in ("OBJECTS", "CLASSES") and i and lines[i - 1].strip() == "2":
            skip = True
        if skip and line.strip() == "ENDSEC":
            skip = False
            continue
        if not skip:
            out.append(line)
    return "\n".join(out).encode()

def drop_seconds(x):
    if isinstance(x, dict):
        # timings and the gear cache's hits and misses differ run to run
        return {k: drop_seconds(v) for k, v in x.items()
                if k not in ("seconds", "elapsed_s", "gear_cache")}
    if isinstance(x, list):
        return [drop_seconds(v) for v in x]
    if isinstance(x, str):
        # the plots stage's message: how the figures fell between the two processes, with
        # each side's time ("12 of 16 figures drawn beside the teeth ... (0.23 s here, ...)")
        return re.sub(r"^\d+ of (\d+ figures drawn beside).*$", r"N of \1", x)
    return x

def normal(path: Path) -> bytes:
    data = path.read_bytes()
    if path.suffix == ".dxf" and LOOSE_DXF:
        return dxf_canonical(data)
    if path.suffix == ".json":
        return json.dumps(drop_seconds(json.loads(data)), sort_keys=True).encode()
    if path.suffix == ".html":
        data = re.sub(rb'<section id="stages">.*?</section>', b"", data, flags=re.S)
    if path.suffix in (".html", ".csv") or path.name.endswith(".txt"):
        return re.sub(rb"\d+\.\d+( ?)(s|ms)\b", rb"T\1\2", data)
    return data

arguments = sys.argv[1:]
LOOSE_DXF = "--loose-dxf" in arguments
a, b = (Path(p) for p in arguments if p != "--loose-dxf")
files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
bad = 0
for rel in sorted(files_a ^ files_b):
    print("only in one:", rel); bad += 1
for rel in sorted(files_a & files_b):
    if normal(a / rel) != normal(b / rel):
        print("differs:", rel); bad += 1
print(f"{len(files_a & files_b)} files compared, {bad} differ")
sys.exit(1 if bad else 0)
