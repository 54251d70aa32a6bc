"""The vocabulary of the cell: frozen dataclasses with read-only arrays, numpy only; every stage imports its values
from here and nothing here imports a stage. Frames: ``W`` world, ``R`` robot base, ``M`` welding map, ``C`` camera
optical frame, ``B`` a box part's own frame. Metres and radians inside; millimetres and degrees only at the edges."""

from cell.types.curve_estimate import CurveEstimate
from cell.types.curves import ArcCurve, CurvedJoint, CurvedSeam, Cylinder, EllipseCurve, SampledCurve, Surface
from cell.types.execution import Event, Execution, WeldQuality
from cell.types.gate import Violation, ViolationKind
from cell.types.map import BOX_FACES, Box, MapSeam, Part, Polyhedron, Unsupported, UnsupportedSeam, WeldMap
from cell.types.plan import PlanReason, SeamOutcome, SeamTask, Segment, SegmentKind, WeldPlan
from cell.types.procedure import Weave, WeldPass, WeldProcedure
from cell.types.rescan import Rescan, SeamRescan, Viewpoint
from cell.types.robot import JointLimits, Kinematics
from cell.types.run import CheckFail, LastCheck, SeamRecord, SeamWeld, WeldReason
from cell.types.seams import (
    EndSource,
    Joint,
    MetricsSummary,
    Reason,
    SeamEstimate,
    SeamMetrics,
    SeamScene,
    SeamStatus,
)
from cell.types.sensing import CameraIntrinsics, Cloud, DepthImage, VoxelTable
from cell.types.solid import pair_distance
from cell.types.trajectory import PathProfile, Trajectory
from cell.types.view import ArmMotion, CameraView, CellView, RobotPose, Shape, ShapeKind

__all__ = [
    "BOX_FACES",
    "ArcCurve",
    "ArmMotion",
    "Box",
    "CameraIntrinsics",
    "CameraView",
    "CellView",
    "CheckFail",
    "Cloud",
    "CurveEstimate",
    "CurvedJoint",
    "CurvedSeam",
    "Cylinder",
    "DepthImage",
    "EllipseCurve",
    "EndSource",
    "Event",
    "Execution",
    "Joint",
    "JointLimits",
    "Kinematics",
    "LastCheck",
    "MapSeam",
    "MetricsSummary",
    "Part",
    "PathProfile",
    "PlanReason",
    "Polyhedron",
    "Reason",
    "Rescan",
    "RobotPose",
    "SampledCurve",
    "SeamEstimate",
    "SeamMetrics",
    "SeamOutcome",
    "SeamRecord",
    "SeamRescan",
    "SeamScene",
    "SeamStatus",
    "SeamTask",
    "SeamWeld",
    "Segment",
    "SegmentKind",
    "Shape",
    "ShapeKind",
    "Surface",
    "Trajectory",
    "Unsupported",
    "UnsupportedSeam",
    "Viewpoint",
    "Violation",
    "ViolationKind",
    "VoxelTable",
    "Weave",
    "WeldMap",
    "WeldPass",
    "WeldPlan",
    "WeldProcedure",
    "WeldQuality",
    "WeldReason",
    "pair_distance",
]
