"""Inverse kinematics: damped least squares on the 6D pose error (log6), joint limits kept by clamping; a solution only
within the tolerance and the limits, else :class:`IKSolveError` with its fields (docs/planning.md section 1).
Frames: targets ``X_RT`` in the robot base frame R [m]; the solved frame (default ``torch_tcp``) is brought onto T."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.linalg import _umath_linalg

from cell.config.motion import IKOptions
from cell.errors import IKError
from cell.geometry import FloatArray, axis_angle_to_matrix, cross3, readonly
from cell.motion.robot import RobotModel


class IKSolveError(IKError):
    """An :class:`~cell.errors.IKError` with its data: ``frame`` solved for, ``target`` X_RT (4, 4) in R,
    ``residual_m`` [m] and ``residual_rad`` [rad] of the best attempt, ``beyond_reach``: the target lies beyond
    the arm's reach bound, so no attempt was made (``residual_m`` is then how far beyond the bound it lies, a lower
    bound on any attempt's error, and ``residual_rad`` is nan)."""

    def __init__(
        self,
        message: str,
        *,
        frame: str,
        target: FloatArray,
        residual_m: float,
        residual_rad: float,
        beyond_reach: bool = False,
    ) -> None:
        super().__init__(message)
        self.frame = frame
        self.target = readonly(target)
        self.residual_m = residual_m
        self.residual_rad = residual_rad
        self.beyond_reach = beyond_reach

    def reworded(self, message: str) -> IKSolveError:
        """The same failure with another message (e.g. prefixed with where on a path it happened)."""
        return IKSolveError(
            message,
            frame=self.frame,
            target=self.target,
            residual_m=self.residual_m,
            residual_rad=self.residual_rad,
            beyond_reach=self.beyond_reach,
        )


@dataclass
class _Attempt:
    q: FloatArray
    pos_err: float
    rot_err: float
    converged: bool


def _align_z(R_RF: FloatArray, z_RT: FloatArray) -> FloatArray:
    """R_RF turned by the smallest rotation that carries its z axis onto z_RT (unit, in R)."""
    z_RF = R_RF[:, 2]
    axis = cross3(z_RF, z_RT)
    s, c = math.sqrt(float(axis @ axis)), float(z_RF @ z_RT)
    if s < 1e-12:
        if c > 0.0:
            return R_RF
        axis = R_RF[:, 0]  # opposite axes: any axis normal to z_RF does
    return axis_angle_to_matrix(axis, float(np.arctan2(s, c))) @ R_RF


def _errors(X_RF: FloatArray, X_RT: FloatArray, free_axis: bool) -> tuple[float, float]:
    """Position error [m] and orientation error [rad] (angle between z axes when free_axis). The norms are
    ``np.linalg.norm``'s own arithmetic (the square root of the dot product), without its dispatch."""
    d = X_RT[:3, 3] - X_RF[:3, 3]
    pos = math.sqrt(float(d @ d))
    if free_axis:
        zf, zt = X_RF[:3, 2], X_RT[:3, 2]
        c = cross3(zf, zt)
        return pos, math.atan2(math.sqrt(float(c @ c)), float(zf @ zt))
    R = X_RF[:3, :3].T @ X_RT[:3, :3]
    cos = (float(R.trace()) - 1.0) / 2.0
    v = _vee(R)
    return pos, math.atan2(math.sqrt(float(v @ v)), cos)


def _vee(R: FloatArray) -> FloatArray:
    """sin(angle) * axis of a rotation matrix (half the skew part)."""
    r = R.tolist()  # the differences of the same doubles, without indexing the array nine times
    return 0.5 * np.array([r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]])


def _descend(
    model: RobotModel, fid: int, X_RT: FloatArray, q0: FloatArray, free_axis: bool, opt: IKOptions
) -> _Attempt:
    """One damped least-squares run from q0; returns the best iterate."""
    lim = model.limits
    q_min, q_max, multi = lim.q_min, lim.q_max, model.multi_turn
    single = ~multi
    q = np.minimum(np.maximum(q0, q_min), q_max)  # np.clip's arithmetic (the limits)
    best = _Attempt(q, np.inf, np.inf, False)
    best_score = np.inf
    eye = np.eye(5 if free_axis else 6)
    for _ in range(opt.max_iters + 1):
        if free_axis:  # the target turned about its z axis to the orientation nearest to F's
            X_RF, J_F = model.pose_and_jacobian(q, fid)
            X_goal = X_RT.copy()
            X_goal[:3, :3] = _align_z(X_RF[:3, :3], X_RT[:3, 2])
            e, J = model.pose_residual(X_RF, X_goal, J_F)
        else:
            X_RF, e, J = model.pose_residual_at(q, fid, X_RT)
        pos_err, rot_err = _errors(X_RF, X_RT, free_axis)
        if pos_err + rot_err * 0.1 < best_score:
            best, best_score = _Attempt(q, pos_err, rot_err, False), pos_err + rot_err * 0.1
        if pos_err <= opt.pos_tol and rot_err <= opt.rot_tol:
            return _Attempt(q, pos_err, rot_err, True)
        if free_axis:  # e[5] (turn about F's z) is zero by construction of X_goal: drop that row
            e, J = e[:5], J[:5]
        dq = _dls_step(J, e, eye, opt.damping)
        # Joints at a limit that the step pushes further out are frozen and the step is solved again
        # (multi-turn joints are not: they wrap by a full turn below).
        out = (((q <= q_min) & (dq < 0)) | ((q >= q_max) & (dq > 0))) & single
        if out.any():
            dq = _dls_step(J * ~out, e, eye, opt.damping)
        big = float(np.abs(dq).max())
        if big > opt.max_step:
            dq *= opt.max_step / big
        q = model.integrate(q, dq)
        q -= 2.0 * np.pi * (multi & (q > q_max))
        q += 2.0 * np.pi * (multi & (q < q_min))
        q = np.minimum(np.maximum(q, q_min), q_max)
    return best


def _dls_step(J: FloatArray, e: FloatArray, eye: FloatArray, damping: float) -> FloatArray:
    """dq = J^T (J J^T + lambda^2 I)^-1 e: ``np.linalg.solve``'s own LAPACK kernel (the damping keeps the matrix
    positive definite, so its singular-matrix check has nothing to catch), without its dispatch."""
    return np.asarray(J.T @ _umath_linalg.solve1(J @ J.T + damping * eye, e, signature="dd->d"))


def solve_ik(
    model: RobotModel,
    X_RT_target: npt.ArrayLike,
    q_seed: npt.ArrayLike,
    *,
    frame: str = "torch_tcp",
    rng: np.random.Generator | None = None,
    free_axis: bool = False,
    options: IKOptions | None = None,
) -> FloatArray:
    """Joint values (dof,) [rad], read-only, that put ``frame`` on the target pose X_RT_target (4, 4) in R.

    q_seed : (dof,) start (warm start: the previous pose's solution). When the seeded run fails and ``rng``
        is given, ``options.restarts`` more runs start from random configurations drawn from it
        (deterministic for a seeded generator); without ``rng`` there are no restarts.
    free_axis : leave the rotation about the target's z axis free (position and z direction only).
    Raises IKSolveError (an IKError: target, best error, reason, and those as fields) when no run reaches the
    tolerance within the joint limits.
    """
    opt = options or IKOptions()
    X_RT = np.asarray(X_RT_target, dtype=float)
    if X_RT.shape != (4, 4) or not np.all(np.isfinite(X_RT)):
        raise ValueError(f"solve_ik: target must be a finite (4, 4) pose, got shape {X_RT.shape}")
    q_start = np.asarray(q_seed, dtype=float)
    if q_start.shape != (model.dof,) or not np.all(np.isfinite(q_start)):
        raise ValueError(f"solve_ik: q_seed must be {model.dof} finite joint values, got shape {q_start.shape}")
    fid = model.frame_id(frame)
    p_RJ, reach = model.reach_bound(frame)
    dist = float(np.linalg.norm(X_RT[:3, 3] - p_RJ))
    if dist > reach:
        raise IKSolveError(
            f"IK for {frame}: the target at p_RT = {np.round(X_RT[:3, 3] * 1000.0, 2).tolist()} mm is "
            f"{dist:.3f} m from {model.joint_names[0]}'s origin, beyond the arm's reach bound of "
            f"{reach:.3f} m",
            frame=frame,
            target=X_RT,
            residual_m=dist - reach,
            residual_rad=float("nan"),
            beyond_reach=True,
        )
    n_attempts = 1 + (opt.restarts if rng is not None else 0)
    att = _descend(model, fid, X_RT, q_start, free_axis, opt)
    best, k = att, 1
    while not att.converged:
        if rng is None or k >= n_attempts:
            raise IKSolveError(
                _failure_message(model, frame, X_RT, best, n_attempts, free_axis, opt),
                frame=frame,
                target=X_RT,
                residual_m=best.pos_err,
                residual_rad=best.rot_err,
            )
        att = _descend(model, fid, X_RT, model.limits.sample(rng, opt.restart_margin), free_axis, opt)
        if att.pos_err + 0.1 * att.rot_err < best.pos_err + 0.1 * best.rot_err:
            best = att
        k += 1
    if not model.limits.contains(att.q):  # _descend clamps: this would be a bug; never return it
        raise IKSolveError(
            f"IK for {frame} left the joint limits at q = {np.degrees(att.q).round(3)} deg",
            frame=frame,
            target=X_RT,
            residual_m=att.pos_err,
            residual_rad=att.rot_err,
        )
    return readonly(att.q)


def _failure_message(
    model: RobotModel,
    frame: str,
    X_RT: FloatArray,
    best: _Attempt,
    n_attempts: int,
    free_axis: bool,
    opt: IKOptions,
) -> str:
    lim = model.limits
    at_limit = [
        n
        for n, q, lo, hi in zip(lim.names, best.q, lim.q_min, lim.q_max, strict=True)
        if min(q - lo, hi - q) < np.radians(0.5)
    ]
    why = f"joints at their limits: {', '.join(at_limit)}" if at_limit else "no joint at a limit"
    # A small manipulability means the best pose is singular: typically the arm stretched towards a target
    # out of its workspace, or the wrist aligned.
    why += f"; manipulability there {model.manipulability(best.q):.2g} (0 = singular)"
    task = "position and torch axis" if free_axis else "pose"
    p = np.round(X_RT[:3, 3] * 1000.0, 2)
    return (
        f"IK for {frame} did not reach the target {task} at p_RT = {p.tolist()} mm within "
        f"{opt.pos_tol * 1000:g} mm / {np.degrees(opt.rot_tol):g} deg after {n_attempts} attempt(s); "
        f"best error {best.pos_err * 1000:.3f} mm / {np.degrees(best.rot_err):.3f} deg ({why})"
    )


def solve_path(
    model: RobotModel,
    targets: Sequence[FloatArray] | FloatArray,
    q_seed: npt.ArrayLike,
    *,
    frame: str = "torch_tcp",
    rng: np.random.Generator | None = None,
    free_axis: bool = False,
    max_joint_step: float = np.radians(20.0),
    options: IKOptions | None = None,
) -> FloatArray:
    """Joint values (n, dof) [rad], read-only, for a sequence of target poses (n, 4, 4) in R, warm-started.

    The first pose starts from q_seed (with restarts when ``rng`` is given); each later pose starts from the
    previous solution, without restarts. Raises IKError naming the index of the first pose that does not
    converge, or at which some joint moves more than ``max_joint_step`` [rad] from the previous pose (a
    configuration flip, e.g. through the wrist singularity).
    """
    X = np.asarray(targets, dtype=float)
    if X.ndim != 3 or X.shape[1:] != (4, 4) or len(X) == 0:
        raise ValueError(f"solve_path: targets must be (n, 4, 4) with n >= 1, got {X.shape}")
    out = np.empty((len(X), model.dof))
    q = np.asarray(q_seed, dtype=float)
    for i, X_RT in enumerate(X):
        try:
            q_new = solve_ik(
                model, X_RT, q, frame=frame, rng=rng if i == 0 else None, free_axis=free_axis, options=options
            )
        except IKSolveError as exc:
            raise exc.reworded(f"path pose {i} of {len(X)}: {exc.message}") from exc
        except IKError as exc:
            raise IKError(f"path pose {i} of {len(X)}: {exc.message}") from exc
        if i > 0:
            jump = np.abs(q_new - out[i - 1])
            j = int(np.argmax(jump))
            if jump[j] > max_joint_step:
                raise IKError(
                    f"path pose {i} of {len(X)}: joint {model.joint_names[j]} jumps "
                    f"{np.degrees(jump[j]):.1f} deg from the previous pose (limit "
                    f"{np.degrees(max_joint_step):.1f} deg): a configuration flip or a singularity "
                    "on the path"
                )
        out[i] = q_new
        q = q_new
    return readonly(out)
