"""Which found seams no torch can be placed on (:func:`unweldable`), so the arm spends no close-up re-scan on
them (:func:`rescan_weldable`): the planner would refuse them whatever the close-up found (out of reach, or the
torch against a part or the table at a weld end for every torch orientation the process allows; a few mm of seam
position change neither). The weld procedure of every task (:func:`seam_procedures`) and curved seam
(:func:`curve_procedures_for`); the parts of each weld's joint, which the safety gate's body test leaves out along
it (:func:`joint_parts`)."""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from cell.pipeline.detect import Progress, quiet
from cell.pipeline.geometry import MotionScene
from cell.pipeline.records import Detection
from cell.pipeline.rescan import RescanMode, rescan_chosen
from cell.scenario import Scenario
from cell.station import Arm, Station

if TYPE_CHECKING:
    from cell.planning.failures import SeamFailure
    from cell.types import Joint, WeldMap
    from cell.types.curve_estimate import CurveEstimate
    from cell.types.plan import NoProcedure, SeamProcedure, SeamTask
    from cell.types.rescan import Rescan


def unweldable(arm: Arm, det: Detection, seam_ids: Collection[str], motion: MotionScene) -> dict[str, SeamFailure]:
    """Seam id -> the planner's failure (its code, where), for those of ``seam_ids`` (found seams only) no torch
    can be placed on."""
    from cell.planning.plan import unplaceable
    from cell.planning.tasks import seam_tasks
    from cell.process.torch import WeldProcess

    if det.scene is None:
        return {}
    sc, ss = det.scenario, det.scene.seam_scene
    wanted = [e for e in det.estimates if e.id in seam_ids]
    tasks = seam_tasks(wanted, ss.weldmap, ss.joints, ss.table_z)
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    procs = seam_procedures(sc, det, tasks)
    return unplaceable(
        arm.model,
        tasks,
        arm.q_home,
        process,
        motion.checker,
        options=sc.motion.plan,
        procedures=procs,
        table_z=ss.table_z,  # a seam the table stand-off lets a torch reach is placeable, as the planner has it
    )


def seam_procedures(sc: Scenario, det: Detection, tasks: Sequence[SeamTask]) -> dict[str, SeamProcedure | NoProcedure]:
    """The weld procedure of every task (the scenario's WPS table, or its one row from ``process:``): by the
    joint type the aligned map gives, the position against gravity in R, the leg ``process.leg_mm`` (or
    ``process.seam_leg_mm`` of the seam)."""
    from cell.process.procedures import joint_type, select_procedures

    ss = det.scene.seam_scene if det.scene is not None else None
    kinds = {t.id: joint_type(ss.weldmap, ss.joints[t.id]) for t in tasks if ss and t.id in ss.joints}
    legs = {t.id: sc.process.seam_leg_mm.get(t.id, sc.process.leg_mm) for t in tasks}
    up_R = np.asarray(sc.X_WR[:3, :3]).T @ np.array([0.0, 0.0, 1.0])  # against gravity (W's z) in R
    return select_procedures(tasks, kinds, legs, sc.weld_procedures(), up_R)


def rescan_weldable(
    station: Station,
    det: Detection,
    mode: RescanMode,
    *,
    motion: MotionScene,
    progress: Progress = quiet,
) -> tuple[Rescan | None, Detection, dict[str, SeamFailure]]:
    """:func:`~cell.pipeline.rescan.rescan_chosen` leaving out the seams no torch can be placed on: neither the
    mode's choice nor an escalation re-scans them. Returns the re-scan (None when nothing was left to re-scan),
    the detection after it, and those seams (id -> the planner's failure)."""
    arm = station.arm
    if arm is None:  # rescan_seams says so
        return rescan_chosen(station, det, mode, motion=motion, progress=progress)

    def leave_out(d: Detection, ids: Sequence[str]) -> dict[str, SeamFailure]:
        return _hopeless(arm, d, ids, motion, progress)

    return rescan_chosen(station, det, mode, leave_out=leave_out, motion=motion, progress=progress)


def _hopeless(
    arm: Arm, det: Detection, ids: Sequence[str], motion: MotionScene, progress: Progress
) -> dict[str, SeamFailure]:
    """:func:`unweldable` of ``ids``, said on ``progress`` when there are any."""
    found = unweldable(arm, det, ids, motion)
    if found:
        progress(f"not re-scanning {len(found)} of {len(ids)} seams no torch can be placed on (planned to say why)")
    return found


def curve_procedures_for(
    sc: Scenario, weldmap_R: WeldMap, curves: Sequence[CurveEstimate]
) -> dict[str, SeamProcedure | NoProcedure]:
    """The weld procedure of every found curved seam (:func:`cell.planning.curves.curve_procedures`): its joint
    type from the map's curved joint, its leg ``process.leg_mm`` (or ``process.seam_leg_mm`` of the seam)."""
    from cell.planning.curves import curve_procedures

    if not curves:
        return {}
    kinds = {c.id: c.joint.kind for c in weldmap_R.curved if c.joint is not None}
    legs = {c.id: sc.process.seam_leg_mm.get(c.id, sc.process.leg_mm) for c in curves}
    up_R = np.asarray(sc.X_WR[:3, :3]).T @ np.array([0.0, 0.0, 1.0])
    return curve_procedures(curves, kinds, legs, sc.weld_procedures(), up_R)


def joint_parts(
    joints: Mapping[str, Joint], task_ids: Sequence[str], weldmap_R: WeldMap, curves: Sequence[CurveEstimate] = ()
) -> dict[str, tuple[str, ...]]:
    """Per task id (a seam's, or a tack's: its seam's) and per curved seam, the two parts of its joint: the safety
    gate leaves them out of its body test along that task's own weld."""
    from cell.pipeline.tacks import TACK_MARK

    out: dict[str, tuple[str, ...]] = {}
    for tid in task_ids:
        j = joints.get(tid.split(TACK_MARK)[0])
        if j is not None:
            out[tid] = (j.abutting, j.receiving)
    wanted = {c.id for c in curves}
    for c in weldmap_R.curved:
        if c.id in wanted and c.joint is not None:
            out[c.id] = (c.joint.abutting, c.joint.receiving)
    return out
