"""Write docs/parameters.md: every key of every parameter-file table, from the schema.

Run:  python scripts/parameter_reference.py > docs/parameters.md

The parameter models (``cadgen/params/``) are the only source: the tables, keys, types,
defaults, bounds and descriptions are read through :func:`cadgen.studio.schema.kind_tables`,
the same walk that builds the studio's form, so a field added to a model appears here (and
in the form) with nothing else to edit. ``tests/test_parameter_reference.py`` fails when the
committed file differs from this script's output. The output is deterministic: the models'
own order, no dates, no machine details.
"""

from __future__ import annotations

import re
import sys

from cadgen.params import PlantingParameters, PrickingParameters
from cadgen.studio.schema import kind_tables

COMMAND = "python scripts/parameter_reference.py > docs/parameters.md"

KINDS = (
    ("planting", PlantingParameters,
     "the high-catching low-planting differential planetary planting mechanism"),
    ("pricking", PrickingParameters,
     "the inclined hole-pricking mechanism, inverse-designed from its needle-tip loop"),
)

INTRO = f"""\
# Parameter reference

Generated from the parameter models (`cadgen/params/`) by
`{COMMAND}`; do not edit by hand
(`tests/test_parameter_reference.py` fails when this file falls behind the models).

Every key of every table of a parameter file, for both mechanism kinds. Lengths are in mm,
angles in degrees (radians only where the key ends in `_rad`). **required** keys have no
default; a key whose default is *not set* may be left out, and its description says what then
applies (most are derived from the design). The resolution knobs' defaults are the `standard` accuracy preset's:
`[scene] preset` or `--preset` changes every knob the file leaves out (see
[the user guide](guide.md#accuracy-presets)). A number is never larger than 1e6 in magnitude.
What each symbol means: [mechanisms.md](mechanisms.md); worked files: `params/*.toml`.
"""


def _number(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value) if isinstance(value, float) else str(value)


def _value(value) -> str:
    """A value as it is written in TOML."""
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(item) for item in value) + "]"
    return _number(value)


def _code(text: str) -> str:
    return f"`{text}`" if text else ""


def _cell(text: str) -> str:
    """Plain text safe in a table cell (docstring ``code`` as Markdown, pipes escaped)."""
    return (text.replace("``", "`").replace("|", "\\|").replace("*", "\\*")).strip()


def _type(field: dict) -> str:
    kind = field["type"]
    if kind == "array":
        items = {"number": "numbers", "integer": "integers", "point": "[x, y] points",
                 "enum": "strings"}.get(field["items"], field["items"])
        count = ""
        if field["min_items"] is not None and field["min_items"] == field["max_items"]:
            count = f" {field['min_items']}"
        text = f"array of{count} {items}"
    elif kind == "point":
        text = "[x, y]"
    elif kind == "enum":
        text = "integer" if all(isinstance(v, int) for v in field["enum"]) else "string"
    elif field["enum"] is not None:   # a number or a named choice (gears.split_exponent)
        text = f"{kind} or string"
    else:
        text = kind
    return text + (" (optional)" if field["nullable"] else "")


def _bounds(field: dict) -> str:
    parts = []
    low, high = field["minimum"], field["maximum"]
    prefix = "each " if field["type"] == "array" else ""
    if low is not None:
        parts.append(f"{prefix}{'>' if field['exclusive_minimum'] else '>='} {_number(low)}")
        prefix = ""
    if high is not None:
        parts.append(f"{prefix}{'<' if field['exclusive_maximum'] else '<='} {_number(high)}")
    text = ", ".join(parts)
    if field["enum"] is not None:
        choices = ", ".join(_code(_value(v)) for v in field["enum"])
        if field["type"] == "array":
            text = f"each one of {choices}"
        elif text:   # a number or a named choice (gears.split_exponent)
            text = f"{choices} or a number {text}"
        elif len(field["enum"]) == 1:
            text = choices
        else:
            text = f"one of {choices}"
    if field["type"] == "array":
        low_n, high_n = field["min_items"], field["max_items"]
        if low_n is not None and low_n != high_n:
            text += ("; " if text else "") + f"at least {low_n} item{'s' if low_n != 1 else ''}"
        if high_n is not None and low_n != high_n:
            text += ("; " if text else "") + f"at most {high_n} items"
    return text


def _default(field: dict) -> str:
    if field["required"]:
        return "**required**"
    if field["default"] is None:
        return "*not set*" if field["nullable"] else ""
    if field["type"] == "array" and field["enum"] and field["default"] == field["enum"]:
        return "every one"
    return _code(_value(field["default"]))


def _description(field: dict, table: dict) -> str:
    """The field's description without the unit the unit column gives; empty when the model
    has none of its own (the schema then repeats the table's description, shown above)."""
    text = field["description"]
    doc = table["description"]
    if doc and text == f"{field['key']}: {doc[:1].lower() + doc[1:]}":
        return ""
    unit = field["unit"]
    if unit:
        text = re.sub(rf",\s*{re.escape(unit)}(?=$|\s*[(,;:])", "", text, count=1)
    return _cell(text)


def table_lines(table: dict) -> list[str]:
    name = table["name"]
    title = f"### `[{name}]`" if name else "### Top level (before the first table)"
    lines = [title, ""]
    if table["description"]:
        lines += [_cell(table["description"]), ""]
    lines += ["| key | type | default | bounds / choices | unit | description |",
              "|---|---|---|---|---|---|"]
    for field in table["fields"]:
        lines.append("| " + " | ".join([
            _code(field["key"]), _type(field), _default(field), _bounds(field),
            field["unit"] or "", _description(field, table)]) + " |")
    return lines + [""]


def reference() -> str:
    """The whole text of docs/parameters.md."""
    lines = [INTRO]
    for kind, model, what in KINDS:
        lines += [f"## `mechanism = \"{kind}\"`: {what}", ""]
        for table in kind_tables(model):
            lines += table_lines(table)
    return "\n".join(lines).rstrip("\n") + "\n"


def main() -> int:
    sys.stdout.write(reference())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
