"""The HTML report's building blocks: escaping, numbers with units, tables and badges.

Shared by :mod:`cadgen.report.html` (the page and its verdict) and
:mod:`cadgen.report.html_sections` (one section per part of the report). Every
function returns HTML text; cells passed in are HTML already, anything else is
escaped here. The names keep their leading underscore: they are the page's
internals, not part of the report API.

Numbers follow one rule (report.json keeps every digit; only the page rounds):
integers as they are; lengths to 0.001 mm, angles to 0.01 deg, areas to 0.001 mm²,
volumes to 1 mm³, masses to 0.001 kg, times to 0.001 s, speeds to 0.01 mm/s; ratios,
coefficients and anything else to 4 significant digits; a value whose accuracy the
report states (a round part's volume, ``accuracy_achieved``) to no finer digit than that
accuracy; a value that rounds to 0 at its decimals (an error, a gap) to 3 significant
digits; and no number to more than :data:`MAX_SIGNIFICANT` significant digits, free text
(messages, accuracy statements) included (:func:`_prose`). Hashes are not numbers.
"""

from __future__ import annotations

import html
import math
import re

__all__ = ["MAX_SIGNIFICANT", "SIGNIFICANT_OTHERWISE", "FAILING_MARKS", "_e", "_number",
           "_quantity", "_to_accuracy", "_prose", "_precision", "_split_unit", "_badge",
           "_pass_badge", "_scientific", "_degrees_ranges", "_point", "_plural", "_row", "_table",
           "_is_number", "_records_table", "_value_html", "_vector_items", "_key_values",
           "_problem_list", "_section"]

#: The page's precision rule (the HTML and the terminal round; report.json keeps every digit):
#: no number shows more than this many significant digits ...
MAX_SIGNIFICANT = 6
#: ... lengths to 0.001 mm, angles to 0.01 deg, and so on by unit (decimals) ...
_DECIMALS = {"mm": 3, "mm²": 3, "mm³": 0, "deg": 2, "mm/s": 2, "s": 3, "kg": 3}
#: ... and other quantities (ratios, coefficients, rad, 1/mm, no unit) to 4 significant digits.
SIGNIFICANT_OTHERWISE = 4
#: A decimal number in text (not part of a word, a version or a hash).
_NUMBER = r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
_NUMBER_IN_TEXT = re.compile(rf"(?<![\w.]){_NUMBER}(?!\w|\.\d)")

#: What marks a failing row or item in the page's HTML (a section holding one opens).
FAILING_MARKS = ('class="fail"', 'class="badge fail"')

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


def _significant(value: float, significant: int) -> str:
    """``value`` to ``significant`` significant digits, without an exponent from 1e-4 up:
    ``0.7608862`` -> ``0.7609``, ``21534745.3`` (3) -> ``21500000``, ``1e-13`` -> ``1e-13``."""
    if value == 0:
        return "0"
    if abs(value) >= 10 ** significant:
        exponent = math.floor(math.log10(abs(value)))
        return str(int(round(value, significant - 1 - exponent)))
    if abs(value) < 1e-4:
        return f"{value:.{min(significant, 3)}g}"
    return f"{value:.{significant}g}"


def _significant_digits(text: str) -> int:
    """Significant digits of a number as printed (an integer's trailing zeros are not)."""
    mantissa = text.lstrip("+-").split("e")[0].split("E")[0]
    if "." in mantissa:
        return len(mantissa.replace(".", "").lstrip("0"))
    return len(mantissa.lstrip("0").rstrip("0"))


def _number(value, digits: int | None = 3, trim: bool = False,
            significant: int | None = None) -> str:
    """A number as text, to the precision the page's rule gives it.

    Integers as they are, a float with ``digits`` decimals (3 significant digits when that
    would show 0), or with ``significant`` significant digits instead when that is given;
    never more than :data:`MAX_SIGNIFICANT` significant digits (report.json keeps them all).
    """
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
    if significant is not None or digits is None:
        return _significant(value, min(significant or MAX_SIGNIFICANT, MAX_SIGNIFICANT))
    text = f"{value:.{digits}f}"
    if float(text) == 0:
        return f"{value:.3g}"
    if _significant_digits(text) > MAX_SIGNIFICANT:
        return _significant(value, MAX_SIGNIFICANT)
    if trim and "." in text:
        text = text.rstrip("0").rstrip(".")
    return text


def _precision(unit: str) -> dict:
    """The page's rule for a quantity in ``unit``: decimals or significant digits."""
    digits = _DECIMALS.get(unit)
    return {"digits": digits} if digits is not None else {"significant": SIGNIFICANT_OTHERWISE}


def _quantity(value, unit: str = "", digits: int | None = None, trim: bool = False) -> str:
    """``value unit``, to ``digits`` decimals or, without them, to the rule for ``unit``."""
    rule = {"digits": digits} if digits is not None else _precision(unit)
    text = _number(value, trim=trim, **rule)
    return f"{text} {unit}" if unit and value is not None and not isinstance(value, bool) else text


def _to_accuracy(value, error: float | None, unit: str = "") -> str:
    """``value`` with no digit finer than its stated ``error`` allows (its last digit the one
    of the error's leading digit), nor finer than the rule for ``unit``: ``191772.6`` with an
    error of 136 -> ``191800``."""
    if value is None or not isinstance(value, float) or not error or not math.isfinite(error) \
            or not math.isfinite(value):
        return _number(value, **_precision(unit))
    decimals = -math.floor(math.log10(abs(error)))
    rule = _precision(unit).get("digits")
    if rule is not None:
        decimals = min(decimals, rule)
    if decimals >= 0:
        return _number(value, decimals)
    return _number(float(round(value, decimals)), 0)


def _prose(text) -> str:
    """Free text (a message, an accuracy statement) with its numbers held to the page's rule:
    a number of more than :data:`MAX_SIGNIFICANT` significant digits is rounded to that, and
    an interval of such numbers is rounded by the rule of the unit after it, or, when its
    ends would then read the same, ``[57.848863, 57.848864] mm``, as its middle and half
    width, ``57.849 ± 5.0e-07 mm``."""
    def interval(match):
        low, high, unit = float(match[1]), float(match[2]), match[3] or ""
        if max(_significant_digits(match[1]), _significant_digits(match[2])) <= MAX_SIGNIFICANT:
            return match[0]
        rule = _precision(unit.strip()) if unit else {"significant": MAX_SIGNIFICANT}
        ends = [_number(low, **rule), _number(high, **rule)]
        if ends[0] != ends[1]:   # still two numbers at the page's precision: the interval
            return f"[{ends[0]}, {ends[1]}]{unit}"
        return f"{_number((low + high) / 2, **rule)} ± {(high - low) / 2:.1e}{unit}"

    def number(match):
        return (_significant(float(match[0]), MAX_SIGNIFICANT)
                if _significant_digits(match[0]) > MAX_SIGNIFICANT else match[0])

    text = re.sub(rf"\[({_NUMBER}), ({_NUMBER})\]( mm\b| deg\b)?", interval, str(text))
    return _NUMBER_IN_TEXT.sub(number, text)


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


def _table(headers, rows, numeric=(), row_classes=None, empty: str = "none") -> str:
    """An HTML table; cells are HTML already, ``numeric`` column indices are right-aligned.

    No rows: no table (a header over nothing), but ``empty``, a statement, as a note.
    """
    if not rows:
        return f'<p class="note">{_e(empty)}</p>'
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


def _shown(value, unit: str = "", digits: int | None = None,
           significant: int | None = None) -> str:
    """A number of a generic table: ``significant`` digits when given (values as written, the
    parameters), else ``digits`` decimals, else the rule for ``unit``; trailing zeros off."""
    if significant is not None:
        return _number(value, significant=significant)
    rule = {"digits": digits} if digits is not None else _precision(unit)
    return _number(value, trim=True, **rule)


def _records_table(records: list, index: list | None = None, unit: str = "",
                   digits: int | None = None, significant: int | None = None) -> str:
    """Dicts as the rows of one table (columns: the union of their keys, in order)."""
    keys = list(dict.fromkeys(k for r in records for k in r))
    headers = [_split_unit(k)[0] for k in keys]
    rows = [[_value_html(r.get(k), _split_unit(k)[1] or unit, digits, significant) for k in keys]
            for r in records]
    if index is not None:
        headers = ["", *headers]
        rows = [[_e(name), *row] for name, row in zip(index, rows)]
    return _table(headers, rows)


def _value_html(value, unit: str = "", digits: int | None = None,
                significant: int | None = None) -> str:
    """Any JSON value as HTML: dicts and lists of dicts as nested tables, numbers with units
    (to ``digits`` decimals or ``significant`` digits when given, else to the rule for
    their unit)."""
    if isinstance(value, dict):
        if len(value) > 1 and all(isinstance(v, dict) and v for v in value.values()):
            # e.g. {"lowest_point": {"value": ..., "certified": ...}, ...}: one row each
            return _records_table(list(value.values()), [_split_unit(str(k))[0] for k in value],
                                  unit, digits, significant)
        return _key_values(value, unit, digits, significant)
    if isinstance(value, (list, tuple)):
        if not value:
            return "none"
        if all(isinstance(v, dict) for v in value):
            return _records_table(list(value), None, unit, digits, significant)
        if all(isinstance(v, (list, tuple)) for v in value):
            return ", ".join(_value_html(v, unit, digits, significant) for v in value)
        text = ", ".join(_vector_items(value, digits, unit, significant))
        return _e(f"({text}) {unit}".rstrip() if unit else f"({text})")
    if _is_number(value):
        text = _shown(value, unit, digits, significant)
        return _e(f"{text} {unit}" if unit else text)
    return _e(_prose(_number(value)))


def _vector_items(values, digits: int | None = None, unit: str = "",
                  significant: int | None = None) -> list[str]:
    """Items of a list as text; a number's round-off noise (1e-14 next to 140) reads as 0."""
    scale = max((abs(v) for v in values if _is_number(v)), default=0.0)
    return [_shown(0.0 if abs(v) < 1e-9 * scale else v, unit, digits, significant)
            if _is_number(v) else _prose(_number(v)) for v in values]


def _key_values(mapping: dict, unit: str = "", digits: int | None = None,
                significant: int | None = None) -> str:
    """A two-column table of a dict; keys lose their unit suffix, values gain the unit."""
    if not mapping:
        return '<span class="note">none</span>'
    rows = []
    for key, value in mapping.items():
        label, own_unit = _split_unit(str(key))
        shown = f"{label} ({own_unit})" if own_unit and isinstance(value, dict) else label
        cell = _value_html(value, own_unit or unit, digits, significant)
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
                     f"{_e(_prose(p.get('message', '')))}</li>")
    return f'<ul class="issues">{"".join(items)}</ul>'


def _section(anchor: str, title: str, body: str, *, folded: bool = False,
             gist: str = "") -> str:
    """A major section of the page: its heading folds it (``<details>``, no script needed).

    ``folded``: closed when the page opens (reference material the reader opens), unless
    it holds a failing row or item; ``gist``: a few words beside the heading, seen while
    the section is folded.
    """
    if folded and any(mark in body for mark in FAILING_MARKS):
        folded = False
    gist = f'<span class="gist">{_e(gist)}</span>' if gist else ""
    return (f'<section id="{anchor}"><details class="fold"{"" if folded else " open"}>'
            f"<summary><h2>{_e(title)}</h2>{gist}</summary>{body}</details></section>")
