"""The only place that knows the order of the stages: capture -> perceive -> align map -> locate -> re-scan -> plan ->
gate -> execute. Each stage takes and returns values; this package wires them, times them, and is the only code
that talks to the station's ports. The CLI is a thin layer over it."""

from cell.pipeline.cloud import locate_cloud
from cell.pipeline.detect import (
    AlignStart,
    build_scene,
    capture,
    detect,
    evaluate,
    locate,
    read_weldmap,
    table_z_R,
)
from cell.pipeline.evaluation import truths
from cell.pipeline.gated import plan_for
from cell.pipeline.geometry import open_cell, robot_arm
from cell.pipeline.job import WeldJob
from cell.pipeline.records import Capture, Detection, Scene, SeamWeld, WeldRun
from cell.pipeline.rescan import RescanMode, rescan_detection, rescan_seams, rescanned
from cell.pipeline.weld import execute, torch_paths, weld

__all__ = [
    "AlignStart",
    "Capture",
    "Detection",
    "RescanMode",
    "Scene",
    "SeamWeld",
    "WeldJob",
    "WeldRun",
    "build_scene",
    "capture",
    "detect",
    "evaluate",
    "execute",
    "locate",
    "locate_cloud",
    "open_cell",
    "plan_for",
    "read_weldmap",
    "rescan_detection",
    "rescan_seams",
    "rescanned",
    "robot_arm",
    "table_z_R",
    "torch_paths",
    "truths",
    "weld",
]
