"""report_html: one self-contained, deterministic HTML page per design report."""

import base64
import copy
import html
import importlib.util
import io
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from cadgen.pipeline.build import run_analysis
from cadgen.params import load_params
from cadgen.report.html import figure_caption, overall_checks, render_html, write_html
from tests.helpers import REFERENCE

VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source",
        "track", "wbr"}


class _StrictParser(HTMLParser):
    """Collects structural errors html.parser itself tolerates: unclosed or crossed tags."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors, self.tags = [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_endtag(self, tag):
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1:] or 'nothing'}")
        else:
            self.stack.pop()


def parse(page: str) -> _StrictParser:
    parser = _StrictParser()
    parser.feed(page)
    parser.close()
    assert parser.errors == [] and parser.stack == [], (parser.errors, parser.stack)
    return parser


def section(page: str, anchor: str) -> str:
    match = re.search(rf'<section id="{anchor}">(.*?)</section>', page, re.S)
    assert match, f"no section {anchor!r}"
    return match[1]


def rows(fragment: str) -> list[list[str]]:
    """Text of the cells of every table row (not for rows holding nested tables)."""
    return [[html.unescape(re.sub(r"<[^>]+>", "", cell)).strip()
             for cell in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row, re.S)]
            for row in re.findall(r"<tr[^>]*>(.*?)</tr>", fragment, re.S)]


def tiny_png(seed: int) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(1.0, 0.8), dpi=40)
    FigureCanvasAgg(figure)
    figure.add_subplot().plot([0, 1, 2], [seed, 0, seed * 2])
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", metadata={"Software": None})
    return buffer.getvalue()


@pytest.fixture(scope="module")
def planting():
    params = load_params(REFERENCE)
    # No cam: it would bring the tooth-cutting stage along (seconds); CAM below stands in.
    return run_analysis(params, output_root=None, plots=False, gears=False, cam=False,
                        solids=False).report


@pytest.fixture(scope="module")
def figures():
    names = ["clearance.png", "gears-2-train-1.png", "attitude.png", "cam-contour.png",
             "gears-10-last.png", "assembly.png", "mystery.png", "pitch_curves.png"]
    return {name: tiny_png(k + 1) for k, name in enumerate(names)}


def sweep_entry(minimum, passed, ranges):
    return {"method": "swept solids", "minimum_mm": minimum, "certified_bound_mm": minimum - 0.25,
            "carrier_angle_deg": 83.5, "nearest": ["gearbox2", "ground"],
            "nearest_points_mm": [[1.0, 2.0, 3.0], [4.0, 5.5, 6.0]],
            "interference_ranges_deg": ranges, "kinematic_estimate_mm": minimum + 1.5,
            "target_mm": 20.0, "passed": passed, "evaluations": 977}


PRICKING = {
    "design": "kernel-x", "mechanism": "pricking", "input_sha256": "ab" * 32, "verified": True,
    "findings": [{"path": "gears.planet", "code": "undercut",
                  "message": "the planet gear's pitch curve bends below 17.10 mm"}],
    "linkage": {"centre_distance_a_mm": 51.87, "carrier_sense": "clockwise"},
    "gears": {"teeth": [26, 26], "pitch_curves": [
        {"name": "sun", "stage": 1, "role": "drive", "perimeter_mm": 163.36, "radius_min_mm": 23.9,
         "radius_max_mm": 27.6, "curvature_min_per_mm": 0.0225, "convex": True,
         "pressure_angle_deviation_max_deg": 10.7, "convex_radius_of_curvature_min_mm": 20.4,
         "undercut": False}]},
    "verification": {"forward_deviation_mm": 1.3e-8, "grid_closure_error_rad": 3.7e-12},
    "field": {"carrier_speed_rpm": 75.0, "forward_speed_mm_s": 530.0, "depth_mm": 70.0,
              "angles": "carrier progress in deg", "per_inclination": [
                  {"inclination_deg": incl, "needle_entry_angle_deg": 82.5 - incl / 10,
                   "needle_exit_angle_deg": 72.25, "hole_mouth_mm": 23.5 + incl,
                   "mouth_x_range_mm": [394.0, 417.5], "time_in_soil_deg": 139.125,
                   "slow_windows_deg": [[32.5, 85.0]], "slow_window_total_deg": 52.5,
                   "projected_height_mm": 214.5, "width_mm": 246.75,
                   "needle_root_in_soil": incl > 30} for incl in (6.5, 33.5)]},
    "stages_s": {"inverse_design": 0.5, "field": 0.25},
    "versions": {"cadgen": "0.1.0"},
}

GEAR_TRAIN = {
    "gears": [{"gear": "sun", "stage": "stage 1", "teeth": 26, "module_mm": 2.0, "cutter": "rack",
               "shaper_teeth": None, "convex": True, "undercut_teeth": [5, 6],
               "pointed_teeth": [], "root_thickness_min_mm": 3.1415, "tip_thickness_min_mm": 1.375,
               "problems": [{"code": "undercut", "message": "teeth 5, 6 are undercut"}]}],
    "meshes": [{"stage": "stage 1", "gears": ["sun", "planet"], "centre_distance_mm": 51.87,
                "poses": 208, "interference_poses": 0, "overlap_area_max_mm2": 0.0,
                "backlash_deg": [1e-4, 2.5e-4], "transmission_error_pp_deg": 2.2e-4,
                "tip_relief": None}],
    "failures": [{"stage": "stage 2", "path": "gears.planet", "code": "gear_not_cuttable",
                  "message": "the planet gear cannot be cut"}],
}

SOLIDS = {
    "density_kg_m3": 7850.0, "total_mass_kg": 1.625,
    "parts": [{"part": "gear-case", "kind": "housing", "instances": 1, "volume_mm3": 191772.6,
               "mass_kg": 1.5054, "centre_of_mass_mm": [-1.84, -3e-15, 15.0], "triangles": 776,
               "watertight": True}],
    "assembly": {"file": "solids/assembly.glb", "carrier_angle_deg": 0.0},
    "enclosure": [{"housing": "gear-case", "gears_enclosed": False, "smallest_margin_mm": -0.75,
                   "nearest_gear": "sun", "axial_fit": True}],
}

CAM = {"opening_angle_deg": 13.75, "mouth_mm": 40.0, "cuttable": False, "roller_radius_mm": 6.0,
       "carrier_angle_deg": {"opening": [183.25, 213.25], "lowest": 188.25},
       "laws": {"opening": "cycloidal"},
       "problems": [{"code": "roller_too_large",
                     "message": "the roller radius 6 mm exceeds the convex pitch radius 5.5 mm"}]}


@pytest.mark.parametrize("kind", ["planting", "pricking"])
def test_page_is_well_formed(kind, planting, figures):
    report = planting if kind == "planting" else PRICKING
    page = render_html(report, figures)
    assert page.startswith("<!DOCTYPE html>\n")
    tags = [tag for tag, _ in parse(page).tags]
    assert tags.count("html") == tags.count("body") == tags.count("style") == 1
    assert report["design"] in page and report["input_sha256"] in page


#: The page's precision rule as docs/report.md states it: lengths to 0.001 mm, angles to
#: 0.01 deg, other quantities to 4 significant digits.
RULE = {"mm": ".3f", "deg": ".2f"}


def test_every_metric_label_and_value_is_shown(planting):
    table = rows(section(render_html(planting, {}), "metrics"))
    assert table[0] == ["metric", "plant spacing", "value", "target", "result"]
    expected = [[m["label"], "" if m["spacing_mm"] is None else f"{m['spacing_mm']:g} mm",
                 f"{m['value']:{RULE.get(m['unit'], '.4g')}} {m['unit']}".strip(),
                 f"{m['target']} {m['unit']}".strip(), "PASS"] for m in planting["metrics"]]
    assert table[1:] == expected
    assert len(expected) >= 10


def test_failing_metric_is_marked_fail(planting):
    report = copy.deepcopy(planting)
    report["metrics"][2]["passed"] = False
    report["passed"] = False
    page = render_html(report, {})
    body = section(page, "metrics")
    row_html = re.findall(r"<tr[^>]*>.*?</tr>", body, re.S)[1:]
    assert 'class="fail"' in row_html[2] and ">FAIL<" in row_html[2]
    assert all(">PASS<" in r for k, r in enumerate(row_html) if k != 2)
    assert 'verdict fail">FAIL<' in page
    assert 'verdict pass">PASS<' in render_html(planting, {})


def test_figures_are_embedded_byte_for_byte_in_groups(planting, figures):
    page = render_html(planting, figures)
    images = [attrs for tag, attrs in parse(page).tags if tag == "img"]
    assert len(images) == len(figures)
    by_alt = {attrs["alt"]: attrs["src"] for attrs in images}
    for name, data in figures.items():
        src = by_alt[figure_caption(name)]
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1], validate=True) == data
        assert f"<code>{name}</code>" in page
    order = [re.search(r"<code>([^<]+\.png)</code>", f)[1]
             for f in re.findall(r"<figure>.*?</figure>", page, re.S)]
    assert order == ["attitude.png", "pitch_curves.png", "gears-2-train-1.png",
                     "gears-10-last.png", "cam-contour.png", "assembly.png", "clearance.png",
                     "mystery.png"]


def without_contents_script(page: str) -> str:
    """The page less its one script of its own, the contents' (cadgen/report/toc.js, inlined
    verbatim: it fetches nothing and the page reads the same without it)."""
    import importlib.resources

    script = importlib.resources.files("cadgen.report").joinpath("toc.js").read_text("utf-8")
    tag = f'<script id="cadgen-toc-script">{script}</script>'
    assert page.count(tag) == 1
    return page.replace(tag, "")


def test_no_external_references(planting, figures):
    report = copy.deepcopy(planting)
    report["sweep"] = {"ground_clearance": sweep_entry(25.0, True, [])}
    for page in (render_html(report, figures), render_html(PRICKING, figures)):
        assert "http://" not in page and "https://" not in page
        page = without_contents_script(page)   # no other script without animation or 3D view
        assert "<script" not in page and "<link" not in page and "<iframe" not in page
        assert "url(" not in page and "@import" not in page
        for tag, attrs in parse(page).tags:
            for key in ("src", "href"):
                if key in attrs:
                    value = attrs[key]
                    assert value.startswith(("#", "data:image/png;base64,")), (tag, value)
                    assert "//" not in value.split(",", 1)[0]


@pytest.mark.parametrize("kind", ["planting", "pricking"])
def test_style_sheet_and_skeleton_come_from_package_data(kind, planting):
    """report.css and page.html ship beside the module; the page carries the sheet verbatim
    and no placeholder of the skeleton is left unfilled."""
    import importlib.resources

    folder = importlib.resources.files("cadgen.report")
    css = folder.joinpath("report.css").read_text(encoding="utf-8")
    skeleton = folder.joinpath("page.html").read_text(encoding="utf-8")
    assert "${css}" in skeleton and "${sections}" in skeleton
    page = render_html(planting if kind == "planting" else PRICKING)
    assert page.startswith("<!DOCTYPE html>\n") and page.endswith("</html>\n")
    assert f"<style>\n{css}</style>" in page
    assert "${" not in page


def test_sweep_section_when_present(planting):
    assert '<section id="sweep">' not in render_html(planting, {})
    report = copy.deepcopy(planting)
    report["sweep"] = {"arm_distance": sweep_entry(111.25, True, []),
                       "ground_clearance": dict(sweep_entry(-3.5, False, [[170.5, 189.5],
                                                                          [350.0, 359.5]]),
                                                label="ground clearance (solids)")}
    page = render_html(report, {})
    table = {row[0]: row[1:] for row in rows(section(page, "sweep"))}
    assert table[""] == ["arm distance", "ground clearance (solids)"]
    assert table["result"] == ["PASS", "FAIL"]
    assert table["minimum"] == ["111.250 mm", "-3.500 mm"]
    assert table["certified lower bound"] == ["111.000 mm", "-3.750 mm"]
    assert table["target"] == ["> 20 mm", "> 20 mm"]
    assert table["where (carrier angle)"] == ["83.50 deg", "83.50 deg"]
    assert table["nearest parts"] == ["gearbox2 ↔ ground"] * 2
    assert table["interference ranges"] == ["none", "170.5–189.5 deg, 350.0–359.5 deg"]
    assert table["kinematic estimate"] == ["112.750 mm", "-2.000 mm"]
    assert table["evaluations"] == ["977", "977"]
    checks = {name: ok for name, ok, _ in overall_checks(report)}
    assert checks["sweep: arm distance"] and not checks["sweep: ground clearance (solids)"]
    assert 'verdict fail">FAIL<' in page


def test_output_is_deterministic(planting, figures):
    first = render_html(planting, figures)
    reordered = dict(reversed(list(figures.items())))
    assert render_html(copy.deepcopy(planting), reordered) == first
    assert render_html(planting, figures) == first


def test_text_is_escaped(planting):
    report = copy.deepcopy(planting)
    report["design"] = "a<b & c"
    report["metrics"][0]["label"] = '<script>alert("x")</script> & <em>'
    report["scene"] = {"case": "<case>", "effects": ["soil & stones"]}
    report["preset"] = "<fast>"
    page = render_html(report, {"x<y>&z.png": tiny_png(1)})
    parse(page)
    page = without_contents_script(page)
    assert "<script" not in page and "<em>" not in page and "<case>" not in page
    assert "a&lt;b &amp; c" in page
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &lt;em&gt;" in page
    assert "&lt;case&gt; (effects: soil &amp; stones)" in page and "&lt;fast&gt;" in page
    assert 'alt="X&lt;y&gt;&amp;z"' in page


def test_pricking_field_table_and_findings():
    page = render_html(PRICKING, {})
    table = rows(section(page, "field"))
    header = table[0]
    assert header[:4] == ["inclination", "needle entry", "needle exit", "hole mouth"]
    assert table[1][:4] == ["6.5 deg", "81.85 deg", "72.25 deg", "30.00 mm"]
    assert table[2][0] == "33.5 deg" and table[2][-1] == "FAIL yes"   # needle root in soil
    assert html.escape(PRICKING["findings"][0]["message"]) in page
    assert [name for name, _, _ in overall_checks(PRICKING)] == ["forward kinematic check"]
    assert 'verdict pass">PASS<' in page
    assert 'verdict fail">FAIL<' in render_html(dict(PRICKING, verified=False), {})


def test_gears_solids_and_stages_sections():
    report = dict(PRICKING, gear_train=GEAR_TRAIN, solids=SOLIDS,
                  stages=[{"stage": "gears", "seconds": 1.5, "status": "ok", "message": ""},
                          {"stage": "sweep", "seconds": 0.25, "status": "failed",
                           "message": "fcl <missing>"}])
    page = render_html(report, {})
    gears = rows(section(page, "gears"))
    assert gears[1][:4] == ["sun", "stage 1", "26", "2.0000"] and gears[1][-1] == "WARN undercut"
    assert "the planet gear cannot be cut" in section(page, "gears")
    solids = rows(section(page, "solids"))
    # a report without materials (written before [manufacturing]): a dash in that column
    assert solids[1] == ["gear-case", "housing", "—", "1", "191773", "1.505",
                         "(-1.84, 0.00, 15.00)", "776", "PASS"]
    assert solids[-1] == ["gear-case", "FAIL", "-0.750 mm", "sun", "PASS"]
    stages = rows(section(page, "stages"))
    assert stages[1:] == [["gears", "1.500", "ok", ""],
                          ["sweep", "0.250", "failed", "fcl <missing>"],
                          ["total", "1.750", "", ""]]
    failed = [name for name, ok, _ in overall_checks(report) if not ok]
    assert failed == ["gears cut", "housings enclose their gears", "stages ran"]
    # Timings only (today's reports): a two-column table.
    assert rows(section(render_html(PRICKING, {}), "stages"))[1:] == [
        ["inverse_design", "0.500"], ["field", "0.250"], ["total", "0.750"]]


def test_cam_section_and_its_problems(planting):
    report = dict(planting, cam=CAM)
    body = section(render_html(report, {}), "cam")
    table = {row[0]: row[1] for row in rows(body) if len(row) == 2}
    assert table["opening angle"] == "13.75 deg" and table["roller radius"] == "6 mm"
    assert "<td>opening</td><td>(183.25, 213.25) deg</td>" in body     # nested: carrier angle
    assert "<td>opening</td><td>cycloidal</td>" in body                  # nested: laws
    assert ">FAIL<" in body and html.escape(CAM["problems"][0]["message"]) in body
    assert ("cam", False, "1 problem") in overall_checks(report)


def test_report_failures_decide_the_verdict(planting):
    report = copy.deepcopy(planting)
    report["failures"] = ["gearbox1 does not enclose its gears (margin -1.00 mm at <sun>)"]
    report["passed"] = False
    report["metrics"][0]["kinematic_estimate"] = 99.5
    page = render_html(report, {})
    header = page[page.index("<header>"): page.index("</header>")]
    assert 'verdict fail">FAIL<' in header and html.escape(report["failures"][0]) in header
    # a failure without a row of its own gets one, named by its cause (no "report verdict")
    assert dict((name, ok) for name, ok, _ in overall_checks(report))[report["failures"][0]] \
        is False
    table = rows(section(page, "metrics"))
    assert table[0][-1] == "kinematic estimate"
    assert table[1][-1] == "99.500 mm" and table[2][-1] == ""
    # An undercut finding is a prediction for rack cutting: a warning whether or not the
    # report has failures (the cut teeth decide; see test_verdict_policy.py)
    pricking = render_html(dict(PRICKING, failures=["[undercut] ..."], passed=False), {})
    assert "WARN</span> <code>[undercut]</code>" in section(pricking, "field")
    assert "WARN</span> <code>[undercut]</code>" in section(render_html(PRICKING, {}), "field")


def test_accuracy_is_listed(planting):
    body = section(render_html(planting, {}), "accuracy")
    for key in planting["accuracy"]:
        assert html.escape(key.replace("_", " ").removesuffix(" mm").removesuffix(" rad")) in body


def test_write_html_writes_the_page_atomically(planting, figures, tmp_path):
    path = write_html(planting, figures, tmp_path / "report.html")
    assert path == tmp_path / "report.html"
    assert path.read_text(encoding="utf-8") == render_html(planting, figures)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.html"]


def test_rejects_figures_that_are_not_png(planting):
    with pytest.raises(ValueError, match="'plot.png' is not PNG data"):
        render_html(planting, {"plot.png": b"GIF89a..."})


@pytest.mark.parametrize("name, caption", [
    ("tip_velocity.png", "Tip speed, relative and absolute"),
    ("gears-3-train-1-sun-to-idler-1.png", "Gear pair 3: train 1: sun to idler 1"),
    ("gears-2-1-1-pair-d-to-e.png", "Gear pair 2: 1:1 pair D to E"),
    ("gears-1-non-circular-pair.png", "Gear pair 1: non-circular pair"),
    ("gears-2-stage-2.png", "Gear pair 2: stage 2"),
    ("cam-contour.png", "Cam contour"),
    ("clearance.png", "Clearances of the solids (FCL sweep)"),
    ("my_other-plot.png", "My other plot"),
], ids=["known", "train", "one-to-one", "non-circular", "stage", "dashes", "sweep", "unknown"])
def test_figure_caption(name, caption):
    assert figure_caption(name) == caption


def test_captions_of_a_build_keep_their_punctuation():
    """Every pair name the bundled trains give comes back readable from its file name."""
    from cadgen.report.plots.parts import pair_figure_jobs

    class Stage:
        def __init__(self, name):
            self.name = name

    class Train:
        stages = [Stage("non-circular pair"), Stage("1:1 pair (D to E)"),
                  Stage("train 1: idler 1 to idler 2")]

    captions = [figure_caption(name) for name in pair_figure_jobs(Train())]
    assert captions == ["Gear pair 1: non-circular pair", "Gear pair 2: 1:1 pair D to E",
                        "Gear pair 3: train 1: idler 1 to idler 2"]


@pytest.fixture(scope="module")
def pricking_built():
    from cadgen.pipeline.build import build

    path = REFERENCE.parent / "kernel-b.toml"
    return build(load_params(path), None, effects=["metrics"]).report


def test_pricking_accuracy_section_shows_what_the_inverse_grid_buys(pricking_built):
    report = pricking_built
    rows_by_knob = {r["knob"]: r for r in report["accuracy_achieved"]}
    check = report["verification"]
    grid = rows_by_knob["resolution.inverse_grid"]
    assert grid["value"] == check["inverse_grid"] == 720
    assert f"within {check['forward_deviation_mm']:.1e} mm" in grid["achieved"]
    assert check["forward_deviation_mm"] < 1e-2          # the forward check's tolerance
    closure = float(re.search(r"close to ([0-9.e+-]+) rad", grid["achieved"])[1])
    # the worst of the grid's and the two stages' closures, printed to two digits
    assert float(f"{check['grid_closure_error_rad']:.1e}") <= closure < 1e-9
    fits = rows_by_knob["Chebyshev fits (fixed rtol 1e-13)"]
    tail = float(re.search(r"at most ([0-9.e+-]+) rad", fits["achieved"])[1])
    assert 0 < tail < 1e-11 and re.fullmatch(r"\d+ pieces, degree 24", fits["value"])
    curve = rows_by_knob["trajectory.degree"]
    assert curve["value"] == 5
    through = float(re.search(r"points within ([0-9.e+-]+) mm", curve["achieved"])[1])
    assert through < 1e-9 and "its 12 type-value points" in curve["achieved"]

    body = section(render_html(report, {}), "accuracy")
    table = rows(body.split("<h3>Forward check")[0])
    assert table[0] == ["knob", "value", "achieved", "basis"]
    assert [row[0] for row in table[1:]] == [r["knob"] for r in report["accuracy_achieved"]]
    shown = {row[0]: row for row in table[1:]}
    assert shown["resolution.inverse_grid"][1] == "720"
    assert shown["resolution.inverse_grid"][2] == grid["achieved"]
    forward = {row[0]: row[1] for row in rows(body.split("<h3>Forward check")[1])}
    assert forward["forward deviation"] == f"{check['forward_deviation_mm']:.2e} mm"
    assert forward["inverse grid"] == "720"
    assert "Accuracy achieved" in render_html(report, {})


def test_highest_point_is_shown_as_a_height(planting):
    search = planting["accuracy"]["minimum_searches"]["highest_point"]
    height = planting["events"]["tip_height_mm"]["highest"]
    # searched as the minimum of -y, reported as the height it is, with an upper bound
    assert search["maximum"] and search["value"] == pytest.approx(height)
    body = section(render_html(planting, {}), "accuracy")
    (row,) = [r for r in rows(body) if r and r[0].startswith("highest point")]
    # to the page's 0.001 mm (the gap column says how close value and bound are)
    assert float(row[1]) == pytest.approx(height, abs=5e-4) and float(row[1]) > 0
    assert float(row[2]) >= float(row[1])                 # its bound is an upper one
    assert not any(cell.startswith("-164") for cell in row)


def test_clearances_are_labelled_by_method(planting):
    report = copy.deepcopy(planting)
    report["sweep"] = {"arm_interference": dict(sweep_entry(57.85, True, []),
                                                label="arm distance (solids, FCL)",
                                                carrier_angle_deg=82.8),
                       "ground_clearance": dict(sweep_entry(119.377, True, []),
                                                label="gearbox ground clearance (solids, FCL)",
                                                carrier_angle_deg=0.17)}
    metrics = {m["key"]: m for m in report["metrics"]}
    estimates = {key: metrics[key]["value"] for key in ("arm_distance", "ground_clearance")}
    for key in estimates:
        metrics[key]["kinematic_estimate"] = estimates[key]
    body = section(render_html(report, {}), "motion")
    derived = body.split("<h3>Derived geometry</h3>")[1].split("<h3>Clearances by method")[0]
    assert "arm distance at" not in derived and "ground clearance at" not in derived
    table = rows(body.split("<h3>Clearances by method</h3>")[1])
    assert table[0][1].startswith("kinematic estimate (centre lines C-E-P1-N and housing")
    assert table[0][2] == "FCL on the solids (certified minimum), carrier angle"
    by_name = {row[0]: row[1:] for row in table[1:]}
    derived_values = planting["derived"]
    assert by_name["arm distance"][0] == (
        f"{estimates['arm_distance']:.3f} mm at {derived_values['arm_distance_at_deg']:.2f} deg")
    assert by_name["arm distance"][1].startswith("57.850 mm at 82.80 deg")
    assert by_name["ground clearance"][0].startswith(
        f"{estimates['ground_clearance']:.3f} mm at "
        f"{derived_values['ground_clearance_at_deg']:.2f} deg")
    assert by_name["ground clearance"][1].startswith("119.377 mm at 0.17 deg")
    # without the sweep, the solids' column says so
    plain = rows(section(render_html(planting, {}), "motion")
                 .split("<h3>Clearances by method</h3>")[1])
    assert plain[1][2] == "not run in this build"


def test_slow_windows_read_around_the_dead_centre():
    report = copy.deepcopy(PRICKING)
    report["field"]["per_inclination"][0]["slow_windows_deg"] = [[-77.88907, 51.91818]]
    table = rows(section(render_html(report, {}), "field"))
    assert table[0][5] == "slow windows (from R max)"
    assert table[1][5] == "-77.9 to 51.9 deg" and table[2][5] == "32.5 to 85.0 deg"


def _render_script():
    path = Path(__file__).resolve().parents[1] / "scripts" / "render_report.py"
    spec = importlib.util.spec_from_file_location("render_report", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_render_script_says_when_chromium_is_missing(tmp_path, capsys):
    page = tmp_path / "report.html"
    page.write_text("<!DOCTYPE html><title>x</title>", encoding="utf-8")
    code = _render_script().main([str(page), "--png", str(tmp_path / "shot.png"),
                                  "--chromium", str(tmp_path / "no-such-chromium")])
    assert code == 2
    error = capsys.readouterr().err
    assert "Chromium was not found" in error and "apt-get install -y chromium" in error
    assert not (tmp_path / "shot.png").exists()


#: The standard preset as the README documents it (an independent source of the values).
README_STANDARD = {"resolution.steps_per_revolution": "3600", "resolution.closure_rtol": "1e-13",
                   "resolution.sweep_atol": "1e-06", "gears.flank_points": "96",
                   "gears.chord_tolerance": "0.005", "solids.segments_per_circle": "96",
                   "cam.profile_points": "3600"}


def test_preset_is_a_table_of_knobs_with_their_origin(planting):
    import tomllib

    page = render_html(planting, {})
    parse(page)
    assert "{'" not in page and "&#x27;value&#x27;" not in page and "{&#x27;" not in page
    header = re.search(r"<header>(.*?)</header>", page, re.S)[1]
    preset = re.search(r'<div class="preset">(.*?)</div><div class="wide">(<table>.*?</table>)',
                       header, re.S)
    table = rows(preset[2])
    assert table[0] == ["knob", "value", "from"]
    written = tomllib.loads(REFERENCE.read_text(encoding="utf-8"))
    in_file = {f"{section}.{key}" for section, values in written.items()
               if isinstance(values, dict) for key in values}
    assert {row[0] for row in table[1:]} == set(README_STANDARD)   # one row per knob
    for knob, value, source in table[1:]:
        section, key = knob.split(".")
        if knob in in_file:
            assert source == "the parameter file"
            assert float(value) == float(written[section][key])
        else:
            assert source == "preset standard"
            assert value == README_STANDARD[knob]
    from_file = sum(knob in in_file for knob in README_STANDARD)
    assert html.unescape(preset[1]) == (f"standard ({len(README_STANDARD)} knobs: {from_file} from "
                                        f"the parameter file, {len(README_STANDARD) - from_file} "
                                        "from the preset)")


def test_preset_of_an_older_report_is_text(planting):
    report = dict(planting, preset="fine")
    page = render_html(report, {})
    assert "<tr><td>preset</td><td>fine</td></tr>" in page


def test_an_undecided_metric_and_the_warnings_are_shown(planting):
    # a search whose gap straddles the target is neither pass nor fail; checks of stages
    # the build did not run are listed as warnings with their stage
    report = copy.deepcopy(planting)
    report["metrics"][2].update(passed=False, verdict="undecided")
    report["passed"] = False
    report["warnings"] = [{"path": "cam.lever.roller_arm", "code": "push_rod_inverted",
                           "message": "the push rod would sit above the lever pin", "stage": "cam"}]
    page = render_html(report, {})
    rows = re.findall(r"<tr[^>]*>.*?</tr>", section(page, "metrics"), re.S)[1:]
    assert ">UNDECIDED<" in rows[2] and ">FAIL<" not in rows[2]
    assert "push_rod_inverted" in page and "stage cam, not run in this build" in page
    assert "1 warning (stages not run)" in page
    assert "Warnings" not in render_html(planting, {})


def test_a_predicted_undercut_finding_warns_and_a_concave_one_fails():
    # kernel-a: concave pitch curves fail the design; the rack-undercut prediction only warns
    import json

    report = {"design": "k", "mechanism": "pricking", "failures": ["x"], "findings": [
        {"path": "gears.sun", "code": "concave_pitch_curve", "message": "concave"},
        {"path": "gears.sun", "code": "undercut", "message": "predicted undercut"}]}
    page = render_html(json.loads(json.dumps(report)), {})
    items = re.findall(r"<li>(.*?)</li>", page, re.S)
    concave = next(i for i in items if "concave_pitch_curve" in i)
    undercut = next(i for i in items if "[undercut]" in i)
    assert ">FAIL<" in concave and ">WARN<" in undercut and ">FAIL<" not in undercut


def test_parts_larger_than_the_build_volume_are_listed(planting):
    from cadgen.report.summary import format_solids

    report = copy.deepcopy(planting)
    report["solids"] = {"parts": [], "total_mass_kg": 1.0, "density_kg_m3": 7850.0,
                        "assembly": {"file": "solids/assembly.glb", "carrier_angle_deg": 0.0},
                        "enclosure": []}
    report["solids"]["build_volume_mm"] = [256.0, 256.0, 256.0]
    report["solids"]["too_big_for_build_volume"] = [
        {"part": "gearbox1", "kind": "housing", "print_extents_mm": [100.0, 560.8, 21.0]}]
    body = section(render_html(report, {}), "solids")
    assert "Parts larger than the build volume (256 x 256 x 256 mm)" in body
    (row,) = [r for r in rows(body) if r and r[0] == "gearbox1" and len(r) == 4]
    assert row[2] == "100.0 x 560.8 x 21.0" and row[3] == "TOO BIG"
    text = format_solids(report["solids"])
    assert "warning: gearbox1 (housing) is 100.0 x 560.8 x 21.0 mm" in text
    assert "256 x 256 x 256 mm (manufacturing.build_volume)" in text
