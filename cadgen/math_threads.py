"""The math libraries' thread pools: one thread each in cadgen's processes.

numpy's and scipy's OpenBLAS (and MKL, OpenMP where a build of them uses it) start a pool of
threads when they load, sized to the machine. cadgen's arrays are small (thousands of
samples) and its parallel work is done by processes (the worker beside the teeth, a batch's
workers, the optimiser's pool): the pool's threads only spin waiting on each other and on
those processes. Measured on the 2-core machine (docs/performance.md): a full build of the
paper's design 3.72 -> 3.48 s of CPU, a metrics-only build 0.225 -> 0.212 s; the studio's
kernel-b evaluation 373 -> 115 ms at the median on a shared machine.

manifold3d's oneTBB pool has no such variable; it takes the CPUs the process may use when it
starts, so :func:`cadgen.solids.extrude.manifold3d_engine` starts it on one core in every
process (a build forks, and a oneTBB worker holding a lock at the fork would leave it held in
the child; and the booleans of the paper design's parts take 0.28 s of CPU on two threads,
0.19 s on one).

The pool is sized when the library loads, so this is set before anything imports numpy:
by the command line for every command (:func:`one_thread_for_commands`; its child
processes inherit it) and by the studio (:func:`single_threaded_math`). A variable the
user has set is left as it is.
"""

from __future__ import annotations

import os
import sys

__all__ = ["MATH_THREAD_VARIABLES", "one_thread_for_commands", "single_threaded_math"]

#: Environment variables that set the math libraries' thread pools (OpenBLAS, MKL, OpenMP).
MATH_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def one_thread_for_commands() -> None:
    """One math thread for this process and the processes it starts (the command line's
    choice; a library caller's process is left alone). Does nothing once numpy is loaded."""
    if "numpy" in sys.modules:
        return
    for name in MATH_THREAD_VARIABLES:
        os.environ.setdefault(name, "1")


def single_threaded_math() -> None:
    """Load numpy and scipy with their BLAS on one thread, in this process only (call first);
    the variables are put back once the libraries have loaded, so that processes started
    later get what this one was started with."""
    if "numpy" in sys.modules:
        return   # too late: the pool is made when the library loads
    saved = {name: os.environ.get(name) for name in MATH_THREAD_VARIABLES}
    one_thread_for_commands()
    try:
        import importlib

        importlib.import_module("numpy")          # loads its OpenBLAS with the variables set
        importlib.import_module("scipy.linalg")   # scipy's wheels bring their own OpenBLAS
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
