"""The HTML report's building blocks: escaping, numbers with units, tables and badges.

Shared by :mod:`cadgen.report.html` (the page and its verdict) and
:mod:`cadgen.report.html_sections` (one section per part of the report). Every
function returns HTML text; cells passed in are HTML already, anything else is
escaped here. The names keep their leading underscore: they are the page's
internals, not part of the report API.
"""

from __future__ import annotations

import html
import math

__all__ = ["_e", "_number", "_quantity", "_split_unit", "_badge", "_pass_badge", "_scientific",
           "_degrees_ranges", "_point", "_plural", "_row", "_table", "_is_number",
           "_records_table", "_value_html", "_vector_items", "_key_values", "_problem_list",
           "_section"]

# Suffixes of report keys that name a unit, longest first so "_mm_s" wins over "_s".
_UNIT_SUFFIXES = (
    ("_kg_mm2", "kg·mm²"), ("_kg_m3", "kg/m³"), ("_mm_s", "mm/s"), ("_per_mm", "1/mm"),
    ("_mm2", "mm²"), ("_mm3", "mm³"), ("_mm", "mm"), ("_deg", "deg"), ("_rad", "rad"),
    ("_rpm", "r/min"), ("_kg", "kg"), ("_s", "s"),
)


# ----------------------------------------------------------------------------------------------
# formatting


def _e(value) -> str:
    """Escape any value as HTML text (quotes too, so it is also safe inside attributes)."""
    return html.escape(str(value), quote=True)


def _number(value, digits: int = 3, trim: bool = False) -> str:
    """A number as text: ``digits`` decimals, or 3 significant digits when that would show 0."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if not isinstance(value, float):
        return str(value)
    if not math.isfinite(value):
        return str(value)
    if value == 0:
        return "0"
    text = f"{value:.{digits}f}"
    if float(text) == 0 or abs(value) >= 1e9:
        return f"{value:.3g}"
    if trim and "." in text:
        text = text.rstrip("0").rstrip(".")
    return text


def _quantity(value, unit: str = "", digits: int = 3, trim: bool = False) -> str:
    text = _number(value, digits, trim)
    return f"{text} {unit}" if unit and value is not None and not isinstance(value, bool) else text


def _split_unit(key: str) -> tuple[str, str]:
    """``"hole_width_mm"`` -> ``("hole width", "mm")``."""
    for suffix, unit in _UNIT_SUFFIXES:
        if key.endswith(suffix) and len(key) > len(suffix):
            return key[: -len(suffix)].replace("_", " "), unit
    return key.replace("_", " "), ""


def _badge(state: str) -> str:
    """``state`` is "pass", "fail" or "warn"."""
    return f'<span class="badge {state}">{state.upper()}</span>'


def _pass_badge(passed) -> str:
    return _badge("pass" if passed else "fail")


def _scientific(value) -> str:
    """Small quantities (overlaps, backlash, errors) in 2 significant digits; 0 as "0"."""
    return "0" if value == 0 else f"{value:.1e}"


def _degrees_ranges(ranges) -> str:
    if not ranges:
        return "none"
    return ", ".join(f"{_number(a, 1)}–{_number(b, 1)} deg" for a, b in ranges)


def _point(point, digits: int = 1) -> str:
    """A position or vector with fixed decimals: round-off noise (1e-15) shows as 0."""
    return "(" + ", ".join(f"{c + 0.0:.{digits}f}".replace(f"-{0:.{digits}f}", f"{0:.{digits}f}")
                           for c in point) + ")"


def _plural(count: int, noun: str, plural: str = "") -> str:
    return f"{count} {noun if count == 1 else plural or noun + 's'}"


def _row(*blocks: str) -> str:
    """Blocks side by side, wrapping when the page is narrow."""
    return '<div class="row">' + "".join(f"<div>{b}</div>" for b in blocks if b) + "</div>"


# ----------------------------------------------------------------------------------------------
# generic blocks


def _table(headers, rows, numeric=(), row_classes=None) -> str:
    """An HTML table; cells are HTML already, ``numeric`` column indices are right-aligned."""
    head = "".join(f"<th>{_e(h)}</th>" for h in headers)
    body = []
    for k, row in enumerate(rows):
        css = f' class="{row_classes[k]}"' if row_classes and row_classes[k] else ""
        cells = "".join(f'<td class="num">{c}</td>' if i in numeric else f"<td>{c}</td>"
                        for i, c in enumerate(row))
        body.append(f"<tr{css}>{cells}</tr>")
    # a wide table scrolls in its own box: the page never scrolls sideways
    return (f'<div class="wide"><table><thead><tr>{head}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody></table></div>")


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _records_table(records: list, index: list | None = None, unit: str = "",
                   digits: int = 3) -> str:
    """Dicts as the rows of one table (columns: the union of their keys, in order)."""
    keys = list(dict.fromkeys(k for r in records for k in r))
    headers = [_split_unit(k)[0] for k in keys]
    rows = [[_value_html(r.get(k), _split_unit(k)[1] or unit, digits) for k in keys]
            for r in records]
    if index is not None:
        headers = ["", *headers]
        rows = [[_e(name), *row] for name, row in zip(index, rows)]
    return _table(headers, rows)


def _value_html(value, unit: str = "", digits: int = 3) -> str:
    """Any JSON value as HTML: dicts and lists of dicts as nested tables, numbers with units."""
    if isinstance(value, dict):
        if len(value) > 1 and all(isinstance(v, dict) and v for v in value.values()):
            # e.g. {"lowest_point": {"value": ..., "certified": ...}, ...}: one row each
            return _records_table(list(value.values()), [_split_unit(str(k))[0] for k in value],
                                  unit, digits)
        return _key_values(value, unit, digits)
    if isinstance(value, (list, tuple)):
        if not value:
            return "none"
        if all(isinstance(v, dict) for v in value):
            return _records_table(list(value), None, unit, digits)
        if all(isinstance(v, (list, tuple)) for v in value):
            return ", ".join(_value_html(v, unit, digits) for v in value)
        text = ", ".join(_vector_items(value, digits))
        return _e(f"({text}) {unit}".rstrip() if unit else f"({text})")
    if _is_number(value):
        return _e(_quantity(value, unit, digits, trim=True))
    return _e(_number(value))


def _vector_items(values, digits: int = 3) -> list[str]:
    """Items of a list as text; a number's round-off noise (1e-14 next to 140) reads as 0."""
    scale = max((abs(v) for v in values if _is_number(v)), default=0.0)
    return [_number(0.0 if abs(v) < 1e-9 * scale else v, digits, trim=True) if _is_number(v)
            else _number(v) for v in values]


def _key_values(mapping: dict, unit: str = "", digits: int = 3) -> str:
    """A two-column table of a dict; keys lose their unit suffix, values gain the unit."""
    rows = []
    for key, value in mapping.items():
        label, own_unit = _split_unit(str(key))
        shown = f"{label} ({own_unit})" if own_unit and isinstance(value, dict) else label
        cell = _value_html(value, own_unit or unit, digits)
        rows.append(f"<tr><td>{_e(shown)}</td><td>{cell}</td></tr>")
    return f'<table class="kv"><tbody>{"".join(rows)}</tbody></table>'


def _problem_list(problems, state: str = "fail") -> str:
    """``problems``: dicts with "code" and "message" (and optionally "path" or "stage")."""
    if not problems:
        return ""
    items = []
    for p in problems:
        where = p.get("path") or p.get("stage") or ""
        where = f" <code>{_e(where)}</code>" if where else ""
        items.append(f"<li>{_badge(state)} <code>[{_e(p.get('code', ''))}]</code>{where} "
                     f"{_e(p.get('message', ''))}</li>")
    return f'<ul class="issues">{"".join(items)}</ul>'


def _section(anchor: str, title: str, body: str) -> str:
    return f'<section id="{anchor}"><h2>{_e(title)}</h2>{body}</section>'
