"""Which weld procedure welds each seam, and in which direction (values in, values out): the first row whose joint
type, welding position (ISO 6947) and leg fit; a seam near vertical in the row's direction (docs/planning.md
section 1). Frames: R the robot base [m]; ``up_R`` the unit vector against gravity in R."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types import Joint, WeldMap
from cell.types.plan import SeamTask
from cell.types.procedure import WeldProcedure

VERTICAL_DEG = 30.0  # [deg] a seam this close to vertical is welded in its procedure's direction
UP_R = np.array([0.0, 0.0, 1.0])  # against gravity in R when the base stands upright


@dataclass(frozen=True)
class SeamProcedure:
    """The procedure a seam got: the row, the seam's joint type and position, whether its ends are swapped
    (``reverse``: welded from p_end to p_start, to weld a vertical seam upwards) and whether the direction is
    fixed (a vertical seam: the planner tries only that one)."""

    seam_id: str
    procedure: WeldProcedure
    joint: str
    position: str
    leg_mm: float
    reverse: bool = False
    fixed_direction: bool = False

    def oriented(self, task: SeamTask) -> SeamTask:
        """The task with its ends swapped when the procedure welds it the other way."""
        if not self.reverse:
            return task
        return SeamTask(task.id, task.p_end, task.p_start, task.n_a, task.n_b)


@dataclass(frozen=True)
class NoProcedure:
    """No row of the WPS table fits the seam: why (joint, position, leg it asked for)."""

    seam_id: str
    reason: str


def joint_type(weldmap_R: WeldMap, joint: Joint) -> str:
    """``T``, ``corner`` or ``lap`` for one seam's joint (parts and faces in the same frame): the joint's kind as the
    map reads it (:func:`cell.seams.joint.joint_kind`), the key a procedure row is chosen by."""
    from cell.seams.joint import joint_kind  # the seams package stays out of the motion import chain

    return joint_kind(weldmap_R, joint)


def is_vertical(d_R: npt.ArrayLike, up_R: npt.ArrayLike = UP_R) -> bool:
    """Whether a seam direction (3,) lies within ``VERTICAL_DEG`` of vertical."""
    d = np.asarray(d_R, dtype=float)
    return abs(float(d @ np.asarray(up_R))) / float(np.linalg.norm(d)) >= math.cos(math.radians(VERTICAL_DEG))


def position(d_R: npt.ArrayLike, n_a_R: npt.ArrayLike, n_b_R: npt.ArrayLike, up_R: npt.ArrayLike = UP_R) -> str:
    """ISO 6947 position of a fillet welded along d (3,) (from start to end) with faces of outward normals n_a,
    n_b: PF / PG for a vertical seam welded up / down, else by the elevation of the fillet's bisector (the way
    the bead faces): PA above 67.5 deg, PB down to -22.5 deg, PD down to -67.5 deg, PE below."""
    up = np.asarray(up_R, dtype=float)
    d = np.asarray(d_R, dtype=float)
    if is_vertical(d, up):
        return "PF" if float(d @ up) > 0.0 else "PG"
    b = np.asarray(n_a_R, dtype=float) + np.asarray(n_b_R, dtype=float)
    elev = math.degrees(math.asin(float(np.clip(b @ up / np.linalg.norm(b), -1.0, 1.0))))
    if elev > 67.5:
        return "PA"
    if elev >= -22.5:
        return "PB"
    return "PD" if elev >= -67.5 else "PE"


def _direction(task: SeamTask, proc: WeldProcedure, up: FloatArray) -> tuple[bool, bool]:
    """(reverse, fixed) for a task under one procedure."""
    d = task.p_end - task.p_start
    if not is_vertical(d, up):
        return False, False
    goes_up = float(d @ up) > 0.0
    if proc.direction == "up":
        return not goes_up, True
    if proc.direction == "down":
        return goes_up, True
    return False, True


def select_procedure(
    task: SeamTask,
    joint: str,
    leg_mm: float,
    rows: Sequence[WeldProcedure],
    up_R: npt.ArrayLike = UP_R,
) -> SeamProcedure | NoProcedure:
    """The first row of ``rows`` that fits the seam (joint type, position in the row's direction, leg [mm])."""
    up = np.asarray(up_R, dtype=float)
    tried = []
    for proc in rows:
        reverse, fixed = _direction(task, proc, up)
        a, b = (task.p_end, task.p_start) if reverse else (task.p_start, task.p_end)
        pos = position(b - a, task.n_a, task.n_b, up)
        tried.append(pos)
        if proc.joint not in ("any", joint) or proc.position not in ("any", pos):
            continue
        if not proc.leg_min_mm <= leg_mm <= proc.leg_max_mm:
            continue
        return SeamProcedure(task.id, proc, joint, pos, leg_mm, reverse, fixed)
    where = "/".join(sorted(set(tried))) or "?"
    names = ", ".join(p.name for p in rows) or "none"
    return NoProcedure(
        task.id, f"no weld procedure for a {joint} joint in position {where} with a {leg_mm:g} mm leg (rows: {names})"
    )


def select_procedures(
    tasks: Sequence[SeamTask],
    joint_types: dict[str, str],
    legs_mm: dict[str, float],
    rows: Sequence[WeldProcedure],
    up_R: npt.ArrayLike = UP_R,
) -> dict[str, SeamProcedure | NoProcedure]:
    """:func:`select_procedure` for every task, keyed by seam id (joint type ``any`` where the map says none)."""
    return {t.id: select_procedure(t, joint_types.get(t.id, "any"), legs_mm[t.id], rows, up_R) for t in tasks}
