"""Shared fixtures: the paper's planting design as a kinematic model; the headless browser."""

import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest

from cadgen.solids.extrude import manifold3d_engine
from kinematics.pitch_curves import LimaconPitchCurve
from kinematics.planting import PlantingMechanism

# manifold3d's pool started as cadgen starts it (one core, no worker thread) before any test
# module is collected: some build solids at import, and the suite's process forks builds'
# workers; a oneTBB worker holding a lock at a fork leaves the child waiting on it for ever
# (see cadgen.solids.extrude.manifold3d_engine)
manifold3d_engine()

REPO = Path(__file__).resolve().parents[1]
PAPER_LIMACON = dict(a1=1.2, b1=27.5, c1=-5.5, d1=30.5, e1=2.66, e2=1.0,
                     f1=8.55, f2=4.24, g1=-6.95, g2=-4.0)


@pytest.fixture(scope="session")
def paper_curve():
    return LimaconPitchCurve(**PAPER_LIMACON)


@pytest.fixture(scope="session")
def paper_mechanism(paper_curve):
    return PlantingMechanism(paper_curve, i12=1.2, i13=1.1, R=36.0, r=27.0, L1=130.0, L2=190.0,
                             phi0=np.pi / 2, phic=np.pi / 2, n=3.0)


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)


@pytest.fixture(scope="session")
def planting_solids():
    """The paper's design with every solid: (params, mechanism, evaluation, cam, train,
    assembly, housings, layout). Built once for the solids and mesh-export tests."""
    from cadgen.cam.design import design_cam
    from cadgen.design import build_mechanism, evaluate
    from cadgen.gears.trains import planting_train
    from cadgen.machine.drivetrain import drivetrain
    from cadgen.params import load_params
    from cadgen.solids.planting import planting_assembly

    params = load_params(REPO / "params" / "xin2024-planter.toml")
    mechanism = build_mechanism(params)
    evaluation = evaluate(params, mechanism, steps=720)
    cam = design_cam(params, mechanism, evaluation.events)
    machine = drivetrain(params, mechanism)
    train = planting_train(params, mechanism, drive=machine.drive)   # as a build cuts it
    assembly, housings, layout = planting_assembly(params, mechanism, train, cam,
                                                   evaluation.events.soil_level,
                                                   drivetrain=machine)
    return params, mechanism, evaluation, cam, train, assembly, housings, layout


@pytest.fixture(scope="session", autouse=True)
def _session_gear_cache(tmp_path_factory):
    """The session's builds use a gear cache of their own, never the user's: ``CADGEN_CACHE_DIR``
    (read by ``cadgen.cache_directory``, inherited by worker processes) names a temporary
    directory. Builds in the suite then run as a designer's do, cold first and warm after;
    the tests that need every gear cut pass ``cache=False``."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("CADGEN_CACHE_DIR", str(tmp_path_factory.mktemp("gear-cache")))
        yield


def load_script(name: str):
    """``scripts/<name>.py`` as a module (the screenshot scripts hold the page checks)."""
    spec = importlib.util.spec_from_file_location(name, REPO / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _browser_unavailable(reason: str):
    if os.environ.get("CI") == "true":
        pytest.fail(f"{reason}: CI must run the browser tests (.ci/run installs chromium)")
    pytest.skip(reason)


@pytest.fixture(scope="session")
def chromium():
    """Debian's Chromium for Playwright: skipped without it locally, failed under CI=true."""
    executable = load_script("report_screenshots").find_chromium()
    if executable is None:
        _browser_unavailable("Chromium is not installed (apt-get install -y chromium)")
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        _browser_unavailable("Playwright for Python is not installed (pip install -e '.[test]')")
    return executable


@pytest.fixture(scope="module")
def browser(chromium):
    """One headless Chromium per test module (its pages are the tests' own)."""
    from playwright.sync_api import sync_playwright

    launch = load_script("report_screenshots").launch
    with sync_playwright() as playwright:
        browser = launch(playwright, chromium)
        yield browser
        browser.close()
