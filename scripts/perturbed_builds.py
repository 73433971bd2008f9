"""Build many perturbed variants of a design and report any that ends in an internal error.

    python scripts/perturbed_builds.py params/xin2024-planter.toml [--count 40] [--spread 0.25]
                                       [--seed 1] [--out DIR]

Each variant moves one to four of the design's numbers (every float of its tables; for the
planting mechanism the pitch curve, train, planter, depth and face width) by a random factor
within +-``spread`` and runs the full build (the file's scene) in this process, writing into
``DIR`` (a temporary folder by default; the gear cache is the user's unless
``CADGEN_CACHE_DIR`` says otherwise). A design the build refuses (ParameterError, exit 2) or
that misses its targets or checks (exit 1) is a verdict; any other exception is a bug: its
file is saved as ``DIR/bug-<seed>-<n>.toml`` with the traceback printed. Prints one line per
variant and the counts; exits 1 if any variant ended in a bug.

The robustness campaign behind it: 180 variants of the three examples (planting at +-25 % and
+-50 %, kernel-a at +-30 %, kernel-b at +-20 % and +-50 %), none an internal error.
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
import time
import traceback
from pathlib import Path

PLANTING_FIELDS = ([("pitch_curve", key) for key in
                    ("a1", "b1", "c1", "d1", "g1", "g2", "f1_rad", "f2_rad")]
                   + [("train", key) for key in ("i12", "i13", "R", "r", "phic_deg",
                                                 "phi0_deg", "n")]
                   + [("planter", "L1"), ("planter", "L2"), ("field", "depth"),
                      ("gears", "face_width")])


def _fields(document) -> list:
    """``[(table, key)]`` of the numbers a variant may move."""
    if str(document.get("mechanism")) == "planting":
        return [(table, key) for table, key in PLANTING_FIELDS
                if table in document and key in document[table]]
    return [(table, key) for table in document if isinstance(document[table], dict)
            for key, value in document[table].items() if isinstance(value, float)]


def main(argv=None) -> int:
    import tomlkit

    import cadgen
    from cadgen import MechanismError, ParameterError

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("design", type=Path)
    parser.add_argument("--count", type=int, default=40)
    parser.add_argument("--spread", type=float, default=0.25)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    if not args.design.is_file():
        parser.error(f"design: no file {args.design}")
    if args.count < 1 or not 0 < args.spread < 1:
        parser.error("--count must be at least 1 and --spread between 0 and 1 (exclusive)")
    out = args.out or Path(tempfile.mkdtemp(prefix="cadgen-perturbed-"))
    out.mkdir(parents=True, exist_ok=True)
    rng = random.Random(args.seed)
    base = args.design.read_text(encoding="utf-8")
    counts, bugs = {}, 0
    for number in range(args.count):
        document = tomlkit.parse(base)
        moved = []
        fields = _fields(document)
        for table, key in rng.sample(fields, min(len(fields), rng.randint(1, 4))):
            value = round(float(document[table][key]) * (1 + rng.uniform(-args.spread,
                                                                         args.spread)), 4)
            document[table][key] = value
            moved.append(f"{table}.{key}={value}")
        text = tomlkit.dumps(document)
        start = time.perf_counter()
        try:
            result = cadgen.build(cadgen.validate_text(text), out / "builds")
            verdict = f"exit {result.exit_code}"
        except ParameterError:
            verdict = "refused (exit 2)"
        except MechanismError as error:
            verdict = f"refused (exit 2, {type(error).__name__})"
        except Exception:   # noqa: BLE001 - what this script looks for
            bugs += 1
            verdict = "BUG"
            saved = out / f"bug-{args.seed}-{number}.toml"
            saved.write_text(text, encoding="utf-8")
            traceback.print_exc()
            print(f"saved {saved}", file=sys.stderr)
        counts[verdict] = counts.get(verdict, 0) + 1
        print(f"{number:3d} {verdict:<20} {time.perf_counter() - start:5.1f} s  "
              f"{' '.join(moved)}", flush=True)
    print(", ".join(f"{verdict}: {count}" for verdict, count in sorted(counts.items())))
    return 1 if bugs else 0


if __name__ == "__main__":
    sys.exit(main())
