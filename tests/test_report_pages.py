"""The report page and the terminal summary of the three bundled examples, built: numbers to the
precision their tolerance supports, no table without rows, one gear verdict.

Each example is built once (draft preset, every stage the page has a section for, no plots)
into a temporary folder; the page checked is the report.html the build wrote. The scans
read the page's text as a reader sees it: scripts, styles and tags (so data URIs) taken
away, the input hash left out.
"""

from __future__ import annotations

import html
import json
import re

import pytest

from cadgen import build, load_params
from cadgen.report.summary import summary_text
from tests.helpers import REFERENCE

EXAMPLES = ("xin2024-planter", "kernel-a", "kernel-b")
EFFECTS = ["metrics", "teeth", "meshing", "cam", "solids", "arm_interference",
           "ground_clearance", "stl", "report"]
#: The page's rule (docs/report.md): no number with more significant digits than this.
MAX_SIGNIFICANT = 6
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?(?!\w|\.\d)")


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pages")
    out = {}
    for name in EXAMPLES:
        result = build(load_params(REFERENCE.with_name(f"{name}.toml")), folder, effects=EFFECTS,
                       preset="draft")
        page = (result.output_dir / "report.html").read_text(encoding="utf-8")
        report = json.loads((result.output_dir / "report.json").read_text(encoding="utf-8"))
        out[name] = (page, report, result.summary_text())
    return out


def significant_digits(token: str) -> int:
    """Significant digits as printed: leading zeros, and an integer's trailing zeros, are not."""
    mantissa = re.split(r"[eE]", token.lstrip("+-"))[0]
    if "." in mantissa:
        return len(mantissa.replace(".", "").lstrip("0"))
    return len(mantissa.lstrip("0").rstrip("0"))


def page_text(page: str) -> str:
    """What a reader reads: no scripts (the GLB, the poses), styles, tags (data URIs) or hash."""
    page = re.sub(r"<(script|style)\b[^>]*>.*?</\1>", " ", page, flags=re.S)
    page = re.sub(r'<td class="hash">.*?</td>', " ", page, flags=re.S)
    return html.unescape(re.sub(r"<[^>]+>", " ", page))


def over_precise(text: str) -> list[str]:
    return [f"{m[0]} in ...{text[max(0, m.start() - 50): m.end() + 10]!r}"
            for m in NUMBER.finditer(text) if significant_digits(m[0]) > MAX_SIGNIFICANT]


@pytest.mark.parametrize("name", EXAMPLES)
def test_no_number_on_the_page_has_more_than_six_significant_digits(built, name):
    page, report, _ = built[name]
    text = page_text(page)
    assert len(NUMBER.findall(text)) > 500            # the page's numbers are all there
    assert over_precise(text) == []
    # report.json, the data, keeps every digit
    assert any(significant_digits(repr(v)) > 12 for v in _floats(report))


@pytest.mark.parametrize("name", EXAMPLES)
def test_no_number_in_the_terminal_summary_has_more_than_six_significant_digits(built, name):
    assert over_precise(built[name][2]) == []


def _floats(value):
    if isinstance(value, dict):
        for v in value.values():
            yield from _floats(v)
    elif isinstance(value, list):
        for v in value:
            yield from _floats(v)
    elif isinstance(value, float):
        yield value


def test_lengths_angles_and_lives_follow_the_rule(built):
    page, report, _ = built["xin2024-planter"]
    text = page_text(page)
    sweep = report["sweep"]["arm_interference"]
    # a length to 0.001 mm, an angle to 0.01 deg (the sweep's row of the page)
    assert f"{sweep['minimum_mm']:.3f} mm" in text
    assert f"{sweep['carrier_angle_deg']:.2f} deg" in text
    # a bearing's rating life to 3 significant digits (an estimate from loads)
    longest = max(b["l10_h"] for b in report["machine"]["bearings"])
    exponent = len(str(int(longest))) - 3
    assert f" {round(longest, -exponent):.0f} " in text


@pytest.mark.parametrize("name", EXAMPLES)
def test_no_table_without_rows(built, name):
    page, _, summary = built[name]
    for table in re.findall(r"<table\b.*?</table>", page, re.S):
        assert re.search(r"<tbody><tr", table), table[:200]
    lines = summary.splitlines()
    rules = [k for k, line in enumerate(lines) if line.strip() and set(line) <= {"-", " "}]
    assert rules and all(k + 1 < len(lines) and lines[k + 1].strip() for k in rules)


def test_kernel_a_says_one_gear_verdict_everywhere(built):
    page, report, summary = built["kernel-a"]
    curves = [c["name"] for c in report["gears"]["pitch_curves"]]
    not_cuttable = {f["path"].removeprefix("gears.").replace("_", " ")
                    for f in report["gear_train"]["failures"]}
    assert report["gear_train"]["gears"] == [] and len(curves) == 4 and len(not_cuttable) == 2
    (line,) = [x for x in summary.splitlines() if x.startswith("gears: ") and "cut" in x]
    statement = line.removeprefix("gears: ")
    assert statement.startswith("no gear cut: ")
    for gear in curves:                                    # all four gears, each named
        assert gear in statement
    text = page_text(page)
    check = re.search(r"gears cut\s+FAIL\s+(.*?)\s{2,}", text)
    assert check and check[1] == statement
    gears = page.split('<section id="gears">')[1].split("</section>")[0]
    assert html.escape(statement) in gears
    assert f"Gears not cut ({len(curves)} of {len(curves)})" in gears
    assert "could not be cut" not in page and "no gears were cut" not in gears
