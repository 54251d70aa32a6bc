"""The coordinated motion gated as one: the arm's and the positioner's axes against their limits at every sample,
and the arm and torch against what stands still (the pedestal), what tilts (the cradle) and what tilts and turns
(the faceplate, the clamping table, the part and its fixtures) at every step, by conservative advancement over
the eight axes (docs/positioner.md, "Coordinated motion"). Frames: R the robot base; each group's obstacles where
they stand at the positioner's home; axes [rad]."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.config.motion import CollisionOptions
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker, Contact
from cell.motion.collision.contact import advance_along
from cell.motion.robot import RobotModel
from cell.positioner.bodies import CRADLE, FACEPLATE, PEDESTAL, positioner_parts
from cell.types import JointLimits, Part
from cell.types.positioner import TiltRotatePositioner


def joint_limits(arm: JointLimits, pos: TiltRotatePositioner) -> JointLimits:
    """The arm's joints and the positioner's two axes (tilt, rotate) as one set of limits (dof + 2)."""
    t, r = pos.tilt, pos.rotate
    cat = lambda a, x, y: np.concatenate([a, [x, y]])  # noqa: E731
    return JointLimits(
        (*arm.names, "tilt", "rotate"),
        cat(arm.q_min, t.q_min, r.q_min),
        cat(arm.q_max, t.q_max, r.q_max),
        cat(arm.v_max, t.v_max, r.v_max),
        cat(arm.a_max, t.a_max, r.a_max),
        cat(arm.j_max, t.j_max, r.j_max),
    )


@dataclass
class MovingScene:
    """Three collision checkers of one arm: the still obstacles, the tilting ones and the turning ones, each
    built where they stand at home; at a state (q, tilt, rotate) the arm's base is placed in each group's home
    frame (the inverse of the group's motion from home). ``lever_m``: a bound on any arm point's distance from
    the positioner's axes (an axis step of d rad moves it at most lever_m * d relative to the part)."""

    pos: TiltRotatePositioner
    still: CollisionChecker
    tilting: CollisionChecker
    turning: CollisionChecker
    lever_m: float

    @classmethod
    def build(
        cls, robot: RobotModel, pos: TiltRotatePositioner, carried: Sequence[Part], options: CollisionOptions
    ) -> MovingScene:
        """``carried``: what the faceplate carries (parts, fixtures, clamping table) in R at home."""
        bodies = {p.name: p for p in positioner_parts(pos, *pos.home)}
        still = CollisionChecker(robot, [bodies[PEDESTAL]], options)
        tilting = CollisionChecker(robot, [bodies[CRADLE]], options)
        turning = CollisionChecker(robot, [*carried, bodies[FACEPLATE]], options)
        centre, radius = robot.reach_bound("torch_tcp")
        lever = float(np.linalg.norm(centre - pos.X_R_F(*pos.home)[:3, 3])) + radius + 0.5
        return cls(pos, still, tilting, turning, lever)

    def _place(self, tilt: float, rotate: float) -> None:
        p, t0 = self.pos, self.pos.home[0]
        self.tilting.place_base(np.linalg.inv(p.X_R_tilt(tilt) @ np.linalg.inv(p.X_R_tilt(t0))))
        self.turning.place_base(np.linalg.inv(p.move(tilt, rotate)))

    def _step(self, x: FloatArray) -> tuple[float, Contact | None]:
        q = x[:-2]
        self._place(float(x[-2]), float(x[-1]))
        free = np.inf
        for checker in (self.still, self.tilting, self.turning):
            step, hit = checker.step_bound(q)
            if hit is not None:
                return 0.0, hit
            free = min(free, step)
        return float(free), None

    def _motion(self, dx: FloatArray) -> float:
        return self.still.motion_bound(dx[:-2]) + self.lever_m * float(np.abs(dx[-2:]).sum())

    def contact_at(self, x: npt.ArrayLike) -> Contact | None:
        """The arm and torch at one state x (dof + 2,) (arm joints, tilt, rotate) [rad] against every group, or
        None when clear (no motion: a knot's pose alone)."""
        try:
            return self._step(np.asarray(x, dtype=float))[1]
        finally:
            for checker in (self.tilting, self.turning):
                checker.place_base(np.eye(4))

    def check(self, times: npt.ArrayLike, x: npt.ArrayLike) -> Contact | None:
        """The first contact along the states x (n, dof + 2) (arm joints, tilt, rotate) [rad], linear between
        samples, or None: every check's distance at most ``max_step`` of arm motion relative to each group."""
        try:
            return advance_along(self._step, self._motion, np.asarray(x, dtype=float), np.asarray(times, float))
        finally:
            for checker in (self.tilting, self.turning):
                checker.place_base(np.eye(4))


def off_limits(limits: JointLimits, x: npt.ArrayLike) -> str | None:
    """The first axis outside its position limits along the states x (n, dof + 2), said in a line, or None."""
    X = np.asarray(x, dtype=float)
    below, above = limits.q_min - 1e-9 > X, limits.q_max + 1e-9 < X
    bad = np.flatnonzero((below | above).any(axis=0))
    if not len(bad):
        return None
    j = int(bad[0])
    worst = float(X[:, j].min() if below[:, j].any() else X[:, j].max())
    return (
        f"axis {limits.names[j]} at {np.degrees(worst):.2f} deg, outside "
        f"[{np.degrees(limits.q_min[j]):.1f}, {np.degrees(limits.q_max[j]):.1f}] deg"
    )
