"""Motion: the arm's model and IK (Pinocchio), torch poses, timing (Ruckig), collisions (coal), the welding plan, the
safety gate and the eye-in-hand camera's close-up views (docs/planning.md). ``from cell.motion import X`` imports
X's module when X is first asked for, so a light name does not pull in Pinocchio, coal and Ruckig."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cell.motion.collision import CollisionChecker, CollisionOptions, Contact
    from cell.motion.collision.scene import cell_obstacles
    from cell.motion.gate import GateOptions, GateRefusedError, Violation, ViolationKind, check_plan, find_violations
    from cell.motion.ik import IKOptions, IKSolveError, solve_ik, solve_path
    from cell.motion.limits import JointLimits, load_limits
    from cell.motion.lines import line_trajectory
    from cell.motion.plan import plan_welds
    from cell.motion.plan_options import PlanOptions
    from cell.motion.process.quality import WeldQuality, weld_quality
    from cell.motion.process.torch import (
        WeldProcess,
        back_off,
        fillet_axes,
        line_poses,
        measured_angles,
        torch_poses,
        torch_rotation,
    )
    from cell.motion.robot import RobotModel
    from cell.motion.tasks import seam_tasks
    from cell.motion.timing import DEFAULT_DT, path_profile, ptp, ptp_duration
    from cell.motion.views.scan import scan_configuration
    from cell.motion.views.viewpoint import (
        ViewOptions,
        Viewpoint,
        ViewTarget,
        plan_view,
        torch_axis_in_camera,
        view_candidates,
    )
    from cell.types.plan import PlanReason, SeamOutcome, SeamTask, Segment, SegmentKind, WeldPlan
    from cell.types.trajectory import PathProfile, Trajectory

_WHERE = {
    "CollisionChecker": "cell.motion.collision",
    "CollisionOptions": "cell.motion.collision",
    "Contact": "cell.motion.collision",
    "GateOptions": "cell.motion.gate",
    "GateRefusedError": "cell.motion.gate",
    "Violation": "cell.motion.gate",
    "ViolationKind": "cell.motion.gate",
    "check_plan": "cell.motion.gate",
    "find_violations": "cell.motion.gate",
    "IKOptions": "cell.motion.ik",
    "IKSolveError": "cell.motion.ik",
    "solve_ik": "cell.motion.ik",
    "solve_path": "cell.motion.ik",
    "JointLimits": "cell.motion.limits",
    "load_limits": "cell.motion.limits",
    "line_trajectory": "cell.motion.lines",
    "plan_welds": "cell.motion.plan",
    "PlanOptions": "cell.motion.plan_options",
    "PlanReason": "cell.types.plan",
    "SeamOutcome": "cell.types.plan",
    "SeamTask": "cell.types.plan",
    "Segment": "cell.types.plan",
    "SegmentKind": "cell.types.plan",
    "WeldPlan": "cell.types.plan",
    "seam_tasks": "cell.motion.tasks",
    "WeldQuality": "cell.types.execution",
    "weld_quality": "cell.motion.process.quality",
    "RobotModel": "cell.motion.robot",
    "scan_configuration": "cell.motion.views.scan",
    "cell_obstacles": "cell.motion.collision.scene",
    "DEFAULT_DT": "cell.motion.timing",
    "PathProfile": "cell.types.trajectory",
    "Trajectory": "cell.types.trajectory",
    "path_profile": "cell.motion.timing",
    "ptp": "cell.motion.timing",
    "ptp_duration": "cell.motion.timing",
    "WeldProcess": "cell.motion.process.torch",
    "back_off": "cell.motion.process.torch",
    "fillet_axes": "cell.motion.process.torch",
    "line_poses": "cell.motion.process.torch",
    "measured_angles": "cell.motion.process.torch",
    "torch_poses": "cell.motion.process.torch",
    "torch_rotation": "cell.motion.process.torch",
    "NoViewError": "cell.motion.views.viewpoint",
    "ViewOptions": "cell.motion.views.viewpoint",
    "ViewRejection": "cell.motion.views.viewpoint",
    "ViewTarget": "cell.motion.views.viewpoint",
    "Viewpoint": "cell.motion.views.viewpoint",
    "plan_view": "cell.motion.views.viewpoint",
    "torch_axis_in_camera": "cell.motion.views.viewpoint",
    "view_candidates": "cell.motion.views.viewpoint",
}

__all__ = [
    "DEFAULT_DT",
    "CollisionChecker",
    "CollisionOptions",
    "Contact",
    "GateOptions",
    "GateRefusedError",
    "IKOptions",
    "IKSolveError",
    "JointLimits",
    "NoViewError",
    "PathProfile",
    "PlanOptions",
    "PlanReason",
    "RobotModel",
    "SeamOutcome",
    "SeamTask",
    "Segment",
    "SegmentKind",
    "Trajectory",
    "ViewOptions",
    "ViewRejection",
    "ViewTarget",
    "Viewpoint",
    "Violation",
    "ViolationKind",
    "WeldPlan",
    "WeldProcess",
    "WeldQuality",
    "back_off",
    "cell_obstacles",
    "check_plan",
    "fillet_axes",
    "find_violations",
    "line_poses",
    "line_trajectory",
    "load_limits",
    "measured_angles",
    "path_profile",
    "plan_view",
    "plan_welds",
    "ptp",
    "ptp_duration",
    "scan_configuration",
    "seam_tasks",
    "solve_ik",
    "solve_path",
    "torch_axis_in_camera",
    "torch_poses",
    "torch_rotation",
    "view_candidates",
    "weld_quality",
]


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'cell.motion' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)
