"""One math thread for the commands (cadgen.math_threads) and manifold3d's pool started on one
core (cadgen.solids.extrude._engine): what the command line sets, what a user set is kept,
and the process's CPU mask put back after the pool starts (a mask left at one core would halve
every later computation of the process). Each case in a fresh interpreter: the libraries read
their settings once, when they load."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from cadgen.math_threads import MATH_THREAD_VARIABLES


def _run(code: str, **environment) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES}
    env.update(environment)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


SET_THEN_REPORT = """
import json, os, sys
from cadgen.math_threads import one_thread_for_commands, MATH_THREAD_VARIABLES
one_thread_for_commands()
print(json.dumps({name: os.environ.get(name) for name in MATH_THREAD_VARIABLES}))
"""


def test_the_commands_ask_for_one_thread_of_each_library():
    assert _run(SET_THEN_REPORT) == {name: "1" for name in MATH_THREAD_VARIABLES}


def test_a_value_the_user_set_is_kept():
    seen = _run(SET_THEN_REPORT, OPENBLAS_NUM_THREADS="2")
    assert seen["OPENBLAS_NUM_THREADS"] == "2" and seen["OMP_NUM_THREADS"] == "1"


def test_nothing_is_set_once_numpy_is_loaded():
    seen = _run("import numpy\n" + SET_THEN_REPORT)
    assert seen == {name: None for name in MATH_THREAD_VARIABLES}


def test_the_command_line_runs_with_one_thread():
    # what a build's process sees: the variables set before numpy loads, in main()
    code = ("import json, os, sys\n"
            "import cadgen.cli\n"
            "def seen(argv):\n"
            "    print(json.dumps([os.environ.get('OMP_NUM_THREADS'), 'numpy' in sys.modules]))\n"
            "    raise SystemExit(0)\n"
            "cadgen.cli.build_parser = seen\n"
            "cadgen.cli.main(['--help'])\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={k: v for k, v in os.environ.items()
                               if k not in MATH_THREAD_VARIABLES}, timeout=120)
    assert json.loads(done.stdout) == ["1", False]


ENGINE = """
import json, os
before = sorted(os.sched_getaffinity(0))
from cadgen.solids.extrude import _engine, extrude
_engine()
after = sorted(os.sched_getaffinity(0))
box = extrude([[0, 0], [3, 0], [3, 2], [0, 2]], 1.5)
print(json.dumps({"before": before, "after": after, "volume": float(box.volume())}))
"""


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity") or len(os.sched_getaffinity(0)) < 2,
                    reason="needs Linux and two CPUs")
@pytest.mark.parametrize("threads", ["1", None])
def test_starting_manifold_puts_the_process_cpu_mask_back(threads):
    seen = _run(ENGINE, **({"OMP_NUM_THREADS": threads} if threads else {}))
    assert seen["after"] == seen["before"] and len(seen["before"]) >= 2
    assert seen["volume"] == pytest.approx(3 * 2 * 1.5, rel=1e-12)   # the solid is made
