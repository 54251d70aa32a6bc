"""What the cell writes: the JSON report (:mod:`cell.export.report`), the KUKA KRL program (:mod:`cell.export.krl`)
and the joint trajectory as JSON and CSV (:mod:`cell.export.trajectory`); reports and programs are written whole
(:mod:`cell.export.atomic`). Values in, files out: these modules read the vocabulary and the run records, never a
stage (an import-linter contract)."""

from cell.export.atomic import write_atomic
from cell.export.krl import write_krl
from cell.export.report import detection_report, rescan_report, weld_report, write_json
from cell.export.trajectory import write_csv
from cell.export.trajectory import write_json as write_trajectory_json

__all__ = [
    "detection_report",
    "rescan_report",
    "weld_report",
    "write_atomic",
    "write_csv",
    "write_json",
    "write_krl",
    "write_trajectory_json",
]
