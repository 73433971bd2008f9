"""`run_analysis`: the library entry of earlier releases, now a build with chosen effects.

``cadgen analyze`` is ``cadgen build`` (see :mod:`cadgen.pipeline.build`); this function
keeps its switches for callers that turn whole parts of the pipeline on or off.
"""

from __future__ import annotations

from pathlib import Path

from cadgen.pipeline.build import BuildResult, build
from cadgen.report.content import input_hash, report_dict
from cadgen.report.summary import format_cam, format_gear_table, format_metrics_table, format_solids

__all__ = ["run_analysis", "AnalysisResult", "input_hash", "report_dict", "format_metrics_table",
           "format_gear_table", "format_cam", "format_solids"]

AnalysisResult = BuildResult


def run_analysis(params, output_root: Path | str | None = Path("outputs"),
                 steps_per_revolution: int | None = None, plots: bool = True,
                 gears: bool = True, cam: bool = True, solids: bool = True,
                 sweeps: bool = False) -> BuildResult:
    """Analyse one validated design; write ``<output_root>/<name>/`` atomically.

    ``gears`` cuts, checks and meshes every gear and writes their DXF files;
    ``cam`` designs the duckbill cam (planting) and writes cam.dxf; ``solids``
    builds every part and writes the STL files and the assembly; ``sweeps`` runs
    the FCL arm-interference and ground-clearance sweeps; ``plots`` draws the
    pictures and the HTML report. With ``output_root=None`` nothing is written.
    """
    effects = ["metrics", "curves"]
    if gears:
        effects += ["teeth", "meshing", "dxf"]
    if cam and params.mechanism == "planting":
        effects += ["cam", "dxf"]
    if solids:
        effects += ["solids", "stl"]
    if sweeps:
        effects += ["arm_interference", "ground_clearance"]
    if plots:
        effects += ["plots", "report"]
    return build(params, output_root, effects=list(dict.fromkeys(effects)),
                 steps=steps_per_revolution)
