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


def _run(code: str, *args, **environment) -> dict:
    """What ``code`` prints (JSON), run in a fresh interpreter with ``args``, without the
    math thread variables of this process but those given."""
    env = {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES}
    env.update(environment)
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          env=env, timeout=120)
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
import json, os, sys
import numpy
def threads():
    return len(os.listdir("/proc/self/task"))
base, before = threads(), sorted(os.sched_getaffinity(0))
if sys.argv[1] == "cadgen":
    from cadgen.solids.extrude import manifold3d_engine
    m3d = manifold3d_engine()
else:
    import manifold3d as m3d
solid = m3d.Manifold.sphere(10.0, 256)
for i in range(6):   # booleans large enough for manifold3d to run them in parallel
    solid = solid + m3d.Manifold.sphere(10.0, 256).translate((3.0 * (i + 1), 0.0, 0.0))
print(json.dumps({"base": base, "threads": threads(), "before": before,
                  "after": sorted(os.sched_getaffinity(0)), "volume": solid.volume()}))
"""


def _engine(way: str) -> dict:
    return _run(ENGINE, way, OPENBLAS_NUM_THREADS="1")   # numpy's pool out of the count


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity") or len(os.sched_getaffinity(0)) < 2
                    or not os.path.isdir("/proc/self/task"), reason="needs Linux and two CPUs")
def test_manifold_runs_without_worker_threads_and_the_cpu_mask_is_put_back():
    # a build forks: a oneTBB worker thread holding a lock at the fork would leave it held in
    # the child. Through cadgen, manifold3d makes no worker thread; on its own (the control,
    # which shows the count can tell) it makes one on two cores
    alone, through = _engine("plain"), _engine("cadgen")
    assert alone["threads"] > alone["base"]
    assert through["threads"] == through["base"]
    assert through["after"] == through["before"] and len(through["before"]) >= 2
    assert through["volume"] == alone["volume"]   # the same solid
