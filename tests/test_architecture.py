"""The layout of docs/architecture.md holds: what each package may import, module sizes, the API.

Read from the source with ``ast`` (imports inside functions included), so a new import that
points the wrong way fails here rather than in a review.
"""

import ast
import importlib.resources
from pathlib import Path

import pytest

import cadgen

REPO = Path(__file__).resolve().parents[1]

#: Each unit and the units it may import (besides itself), lowest floor first. A unit is a
#: package under cadgen/, a top-level module, ``kinematics``, or ``cadgen.params.feasibility``:
#: the design checks a file gets at load time run the models, so that one module of params
#: sits above them (it imports them inside its functions).
ALLOWED = {
    "kinematics": set(),
    "cadgen.crash": {"cadgen"},      # a bug's one line and crash file (cli, studio)
    "cadgen.math_threads": set(),    # one math thread for the commands and the studio
    "cadgen.processes": set(),       # interrupts and child processes (standard library only)
    "cadgen.geometry": set(),
    # loading calls the design checks, inside a function (see cadgen.params.feasibility)
    "cadgen.params": {"kinematics", "cadgen.params.feasibility"},
    "cadgen.gears": {"kinematics"},
    "cadgen.cam": {"kinematics"},
    # shafts, keys, bearings and fits: the machine-design rules (numbers and tables, no solids)
    "cadgen.machine": {"kinematics", "cadgen.params", "cadgen.geometry", "cadgen.gears"},
    # the assembly model: the machine's records as parts, joints (with their bought items from
    # the machine's catalogues) and placements; no numpy
    "cadgen.assembly": {"cadgen.machine"},
    "cadgen.solids": {"kinematics", "cadgen.params", "cadgen.geometry", "cadgen.gears",
                      "cadgen.machine", "cadgen.assembly"},
    "cadgen.design": {"kinematics", "cadgen.solids"},
    # the dynamics: the kinematics' motion, the drive, journals and spring of the machine's
    # records, the cam's contact (follower), the solids' mass properties
    "cadgen.dynamics": {"kinematics", "cadgen.params", "cadgen.gears", "cadgen.cam",
                        "cadgen.machine", "cadgen.solids"},
    "cadgen.sweep": {"kinematics", "cadgen.solids"},
    "cadgen.params.feasibility": {"kinematics", "cadgen.params", "cadgen.design", "cadgen.cam"},
    # (cadgen.processes: a staged folder is made and swapped in with Ctrl-C held back)
    "cadgen.export": {"kinematics", "cadgen.geometry", "cadgen.gears", "cadgen.solids",
                      "cadgen.machine", "cadgen.processes"},
    "cadgen.report": {"kinematics", "cadgen", "cadgen.cam", "cadgen.export", "cadgen.gears",
                      "cadgen.solids", "cadgen.machine", "cadgen.assembly", "cadgen.dynamics"},
    "cadgen.pipeline": {"kinematics", "cadgen.params", "cadgen.params.feasibility",
                        "cadgen.geometry", "cadgen.gears", "cadgen.cam", "cadgen.machine",
                        "cadgen.solids", "cadgen.design", "cadgen.sweep", "cadgen.export", "cadgen.report",
                        "cadgen.dynamics",
                        # the worker beside the teeth: started whole, dying with the build
                        "cadgen.processes"},
    "cadgen.batch": {"kinematics", "cadgen.params", "cadgen.export", "cadgen.pipeline",
                     "cadgen.processes"},
    # the studio: over the public API, the parameter models (its form's schema, its saves),
    # the evaluation's sections as report.json holds them, and the build's stage plan
    "cadgen.studio": {"kinematics", "cadgen", "cadgen.params", "cadgen.design", "cadgen.cam",
                      "cadgen.solids", "cadgen.report", "cadgen.export", "cadgen.pipeline",
                      "cadgen.crash", "cadgen.math_threads", "cadgen.processes"},
    # the optimiser: the planting screen (kinematics.population), the exact path (design,
    # report's sections), the build's own checks (cam, machine, solids' housing rules, gears'
    # circular sizing), and the studio's parameter schema and comment-keeping writer (one
    # definition each: the study is validated as the form is, best.toml written as a save)
    "cadgen.optimize": {"kinematics", "cadgen", "cadgen.params", "cadgen.design", "cadgen.gears",
                        "cadgen.cam", "cadgen.machine", "cadgen.solids", "cadgen.report",
                        "cadgen.export", "cadgen.studio", "cadgen.processes"},
    # the command line uses the public API only (and the two helpers it shares with the studio)
    "cadgen.cli": {"cadgen", "cadgen.crash", "cadgen.math_threads", "cadgen.processes"},
    "cadgen.__main__": {"cadgen.cli"},
    "cadgen": set(),                 # the API imports lazily, by name (see its _EXPORTS)
}
MAX_LINES = 600
MAX_TOP_LEVEL_MODULES = 6


def unit_of(module: str) -> str:
    if module.startswith("kinematics"):
        return "kinematics"
    if module.startswith("cadgen.params.feasibility"):
        return "cadgen.params.feasibility"
    parts = module.split(".")
    return ".".join(parts[:2]) if len(parts) > 1 else "cadgen"


def sources():
    for path in sorted((REPO / "cadgen").rglob("*.py")) + sorted((REPO / "kinematics").rglob("*.py")):
        module = ".".join(path.relative_to(REPO).with_suffix("").parts).removesuffix(".__init__")
        yield module, path


def imports_of(path: Path):
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and not node.level:
            yield node.module
        elif isinstance(node, ast.ImportFrom) and node.level:
            yield "kinematics" if "kinematics" in path.parts else "cadgen.?relative"
        elif isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)


def test_every_import_points_down_the_floors():
    wrong = []
    for module, path in sources():
        unit = unit_of(module)
        assert unit in ALLOWED, f"{module}: a new package; give it a floor in ALLOWED and the doc"
        for imported in imports_of(path):
            if imported.split(".")[0] not in ("cadgen", "kinematics"):
                continue
            other = unit_of(imported)
            if other != unit and other not in ALLOWED[unit]:
                wrong.append(f"{module} imports {imported} ({unit} -> {other})")
    assert not wrong, "\n".join(wrong)


def test_kinematics_never_imports_cadgen():
    for module, path in sources():
        if module.startswith("kinematics"):
            assert not [m for m in imports_of(path) if m.startswith("cadgen")], module


@pytest.mark.parametrize("module, path", list(sources()), ids=lambda v: str(v))
def test_no_module_is_over_the_style_guides_size(module, path):
    lines = len(path.read_text(encoding="utf-8").splitlines())
    assert lines <= MAX_LINES, f"{module}: {lines} lines; split it by concept"


def test_the_top_level_holds_the_cli_main_and_the_api_only():
    top = sorted(p.name for p in (REPO / "cadgen").glob("*.py"))
    assert len(top) <= MAX_TOP_LEVEL_MODULES, top
    assert {"__init__.py", "__main__.py", "cli.py"} <= set(top)


def test_every_public_name_resolves_and_the_cli_needs_nothing_else():
    for name in cadgen.__all__:
        assert getattr(cadgen, name) is not None, name
    # the names the command line takes from the API are all public
    tree = ast.parse((REPO / "cadgen" / "cli.py").read_text(encoding="utf-8"))
    taken = {alias.name for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
             and node.module == "cadgen" for alias in node.names}
    assert taken - {"__version__"} <= set(cadgen.__all__)
    assert {"load_params", "build", "evaluate", "ParameterError", "MechanismError"} <= set(
        cadgen.__all__)


def test_the_report_page_template_and_css_are_package_data():
    files = importlib.resources.files("cadgen.report")
    assert "<style>" not in (REPO / "cadgen" / "report" / "html.py").read_text(encoding="utf-8")
    assert files.joinpath("report.css").read_text(encoding="utf-8").strip()
    assert "${" in files.joinpath("page.html").read_text(encoding="utf-8")
