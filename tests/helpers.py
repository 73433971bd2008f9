"""Small helpers shared by tests: edited copies of the reference parameter file."""

import re
from pathlib import Path

REFERENCE = Path(__file__).resolve().parents[1] / "params" / "xin2024-planter.toml"


def reference_text() -> str:
    return REFERENCE.read_text(encoding="utf-8")


def edited(**changes) -> str:
    """The reference file with ``key = value`` lines replaced (key names are unique in it)."""
    text = reference_text()
    for key, value in changes.items():
        text, count = re.subn(rf"(?m)^{re.escape(key)}\s*=\s*[^#\n]*", f"{key} = {value} ", text)
        assert count == 1, f"key {key!r} not found exactly once in the reference file"
    return text
