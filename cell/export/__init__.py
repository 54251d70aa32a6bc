"""What the cell writes: the JSON report (:mod:`cell.export.reports.report`), the robot program through a post-processor
(:mod:`cell.export.program`, :mod:`cell.export.post`: KUKA KRL in :mod:`cell.export.krl`, ABB RAPID in
:mod:`cell.export.rapid`; a part turned over between sides in :mod:`cell.export.turnover_program`;
:mod:`cell.export.checks.program` re-reads a KRL program) and the joint trajectory as JSON and CSV
(:mod:`cell.export.trajectory`); every file is written whole (:mod:`cell.outputs`). Values in,
files out: these modules read the vocabulary and the run records, never a stage (an import-linter contract)."""

from cell.export.krl import write_krl
from cell.export.post import write_program
from cell.export.program import ProgramJob
from cell.export.reports.report import detection_report, rescan_report, weld_report, write_json
from cell.export.trajectory import write_csv
from cell.export.trajectory import write_json as write_trajectory_json
from cell.export.turnover_program import turnover_program, write_turnover_program
from cell.outputs import write_atomic

__all__ = [
    "ProgramJob",
    "detection_report",
    "rescan_report",
    "turnover_program",
    "weld_report",
    "write_atomic",
    "write_csv",
    "write_json",
    "write_krl",
    "write_program",
    "write_trajectory_json",
    "write_turnover_program",
]
