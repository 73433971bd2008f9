"""cadgen.pipeline.warm: the imports a build makes, made ahead by a process that forks builds
(a batch's local worker). A build forked after :func:`warm` loads no further third-party
package, so its lists of modules cannot fall behind the stages' code unnoticed.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from helpers import REFERENCE

import cadgen.pipeline.figures

pytestmark = pytest.mark.skipif(not cadgen.pipeline.figures._can_fork(),
                                reason="forks a build, as a batch's worker does")

KERNEL_B = REFERENCE.parent / "kernel-b.toml"

#: In a fresh interpreter: the third-party packages :func:`warm` imports, then those a build
#: forked after it imports (none, if the lists are whole).
SCRIPT = r"""
import json, os, sys
import cadgen
from cadgen.params import load_params
from cadgen.pipeline.warm import warm

def third_party():
    return {name.split(".")[0] for name, module in list(sys.modules.items())
            if "site-packages" in (getattr(module, "__file__", None) or "")}

params = load_params(sys.argv[2])
before = third_party()
warm(params)
warmed = sorted(third_party() - before)
read, write = os.pipe()
pid = os.fork()
if pid == 0:
    os.close(read)
    before = third_party()
    cadgen.build(params, sys.argv[1], cache=False)   # every gear cut, every file written
    os.write(write, json.dumps(sorted(third_party() - before)).encode())
    os._exit(0)
os.close(write)
data = b""
while chunk := os.read(read, 1 << 16):
    data += chunk
os.waitpid(pid, 0)
print(json.dumps({"warm": warmed, "build": json.loads(data)}))
"""


def test_a_build_forked_after_warming_imports_no_further_package(tmp_path):
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(tmp_path), str(REFERENCE)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    imported = json.loads(run.stdout.strip().splitlines()[-1])
    # what a full build needs, loaded ahead (a build in a fresh interpreter loads them all:
    # had the lists missed one, the build would load it and the check below fail)
    assert {"scipy", "shapely", "trimesh", "manifold3d", "fcl", "matplotlib",
            "ezdxf"} <= set(imported["warm"]), imported["warm"]
    assert imported["build"] == []
    assert (tmp_path / "xin2024-planter" / "report.html").is_file()


def test_warming_takes_the_designs_mechanism_and_scene():
    from cadgen.params import load_params
    from cadgen.pipeline.warm import warm

    pricking = warm(load_params(KERNEL_B))
    assert {"cadgen.solids.pricking", "cadgen.report.plots.pricking", "trimesh",
            "fcl"} <= set(pricking)
    assert not any(name.endswith(".planting") for name in pricking)
    # a metrics-only scene imports no third-party library at all (as its build: README,
    # "A metrics-only scene never ... imports fcl, manifold3d, trimesh or matplotlib")
    metrics = warm(load_params(REFERENCE), effects=["metrics"])
    assert metrics and {name.split(".")[0] for name in metrics} == {"cadgen"}
