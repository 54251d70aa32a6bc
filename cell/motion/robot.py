"""The arm's kinematic model, the only module that imports Pinocchio. Frames: ``R`` the robot base (URDF root
``base_link`` = KUKA $ROBROOT); every pose returned is ``X_RF`` [m]; joints are the controller's A1..A6 [rad]. A
:class:`RobotModel` keeps one scratch ``Data``: cheap to call, not thread-safe (one model per thread)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from cell.errors import MotionError, ScenarioError
from cell.geometry import FloatArray, readonly
from cell.motion.limits import JointLimits, load_limits

_REFERENCES = {"local": pin.LOCAL, "aligned": pin.LOCAL_WORLD_ALIGNED}


class RobotModel:
    """Kinematics of a fixed-base serial arm loaded from a URDF (bounded single-axis joints only)."""

    def __init__(self, model: pin.Model, limits: JointLimits, source: Path) -> None:
        self._model = model
        self.base_offset_R: FloatArray = readonly(np.zeros(3))  # where the base stands in R (a linear track)
        self._data = model.createData()
        self.limits = limits
        self.source = source
        self.name: str = model.name
        self.joint_names: tuple[str, ...] = limits.names
        # Revolute joints whose range exceeds a full turn (KUKA A4, A6): q and q -+ 2 pi are the same pose.
        revolute = np.array([j.shortname().startswith("JointModelR") for j in model.joints[1:]])
        self.multi_turn = readonly(revolute & (limits.q_max - limits.q_min > 2.0 * np.pi), np.bool_)
        self._frames: dict[str, int] = {}
        self._reach: dict[str, tuple[FloatArray, float]] = {}
        for i, frame in enumerate(model.frames):
            if frame.type == pin.FrameType.BODY and frame.name not in self._frames:
                self._frames[frame.name] = i

    @classmethod
    def from_urdf(cls, path: str | Path, limits_path: str | Path | None = None) -> RobotModel:
        """Load a URDF and its motion limits (default: ``<stem>.limits.yaml`` beside the URDF).

        Raises ScenarioError when a file is missing or invalid, or the arm has a joint that is not a single
        bounded revolute/prismatic axis.
        """
        path = Path(path)
        if not path.is_file():
            raise ScenarioError(f"robot URDF {path} not found")
        try:
            model = pin.buildModelFromUrdf(str(path))
        except (RuntimeError, ValueError) as exc:
            raise ScenarioError(f"robot URDF {path} cannot be loaded: {exc}") from exc
        if model.nq != model.nv or model.nq != model.njoints - 1:
            raise ScenarioError(f"robot URDF {path}: only single-axis joints are supported (no continuous/floating)")
        names = tuple(model.names[1:])
        q_min = np.array(model.lowerPositionLimit, dtype=float)
        q_max = np.array(model.upperPositionLimit, dtype=float)
        v_urdf = np.array(model.velocityLimit, dtype=float)
        if not (np.all(np.isfinite(q_min)) and np.all(np.isfinite(q_max)) and np.all(q_min < q_max)):
            raise ScenarioError(f"robot URDF {path}: every joint needs finite lower < upper position limits")
        lim_path = Path(limits_path) if limits_path is not None else path.with_suffix(".limits.yaml")
        return cls(model, load_limits(lim_path, names, q_min, q_max, v_urdf), path)

    def shifted(self, offset_R: npt.ArrayLike) -> RobotModel:
        """The same arm with its base moved by ``offset_R`` (3,) [m] in R, as a linear track carries it
        (docs/track.md): every pose it returns (:meth:`fk`, :meth:`pose_and_jacobian`, :meth:`reach_bound`) is
        still in R, X_RF = translation(offset) @ X_Re_F. The joint axes keep their directions, so Jacobians and
        manipulability are those of the unshifted arm. A new model (this one is unchanged)."""
        d = np.asarray(offset_R, dtype=float)
        if d.shape != (3,) or not np.all(np.isfinite(d)):
            raise ValueError(f"robot {self.name}: a base offset is 3 finite values [m], got {d.shape}")
        model = pin.Model(self._model)
        move = d - self.base_offset_R
        model.jointPlacements[1] = _translated(model.jointPlacements[1], move)
        for fr in model.frames:
            if fr.parentJoint == 0:  # frames fixed to the base (base_link, its children)
                fr.placement = _translated(fr.placement, move)
        out = RobotModel(model, self.limits, self.source)
        out.base_offset_R = readonly(d.copy())
        return out

    @property
    def dof(self) -> int:
        return int(self._model.nq)

    @property
    def frame_names(self) -> tuple[str, ...]:
        """Names of the link frames (URDF links), in model order."""
        return tuple(self._frames)

    def frame_id(self, frame: str) -> int:
        """Index of a link frame; MotionError naming the valid frames when there is none of that name."""
        try:
            return self._frames[frame]
        except KeyError:
            raise MotionError(f"robot {self.name} has no frame {frame!r}; frames: {', '.join(self._frames)}") from None

    def _q(self, q: npt.ArrayLike) -> FloatArray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.dof,):
            raise ValueError(f"robot {self.name}: q must have shape ({self.dof},), got {q.shape}")
        return q

    def fk(self, q: npt.ArrayLike, frame: str = "torch_tcp") -> FloatArray:
        """X_RF (4, 4): pose of ``frame`` in the robot base frame R at joint values q (dof,) [rad]."""
        fid = self.frame_id(frame)
        pin.forwardKinematics(self._model, self._data, self._q(q))
        return np.array(pin.updateFramePlacement(self._model, self._data, fid).homogeneous)

    def fk_frames(self, q: npt.ArrayLike, frames: tuple[str, ...]) -> dict[str, FloatArray]:
        """Poses X_RF (4, 4) of several frames at once."""
        ids = [self.frame_id(f) for f in frames]
        pin.forwardKinematics(self._model, self._data, self._q(q))
        return {
            f: np.array(pin.updateFramePlacement(self._model, self._data, i).homogeneous)
            for f, i in zip(frames, ids, strict=True)
        }

    def jacobian(self, q: npt.ArrayLike, frame: str = "torch_tcp", reference: str = "aligned") -> FloatArray:
        """Frame Jacobian (6, dof): joint rates [rad/s] -> twist [v; w] of ``frame`` ([m/s], [rad/s]).

        reference : ``"aligned"`` - velocity of the frame origin and angular velocity in R's axes;
            ``"local"`` - both in the frame's own axes.
        """
        if reference not in _REFERENCES:
            raise ValueError(f"jacobian reference {reference!r} unknown; valid: {', '.join(_REFERENCES)}")
        fid = self.frame_id(frame)
        q = self._q(q)
        pin.computeJointJacobians(self._model, self._data, q)
        pin.updateFramePlacement(self._model, self._data, fid)
        return np.array(pin.getFrameJacobian(self._model, self._data, fid, _REFERENCES[reference]))

    def manipulability(self, q: npt.ArrayLike) -> float:
        """Yoshikawa's measure sqrt(det(J J^T)) of the flange Jacobian; 0 at a singularity.

        For a 6-axis arm this is |det J|, which is the same for every frame fixed to the last link (moving the
        reference point or the axes multiplies J by a matrix of determinant +-1), so the tool does not matter.
        Units m^3 (three translational rows); compare values of one arm only.
        """
        J = self.jacobian(q, "tool0" if "tool0" in self._frames else self.frame_names[-1], "aligned")
        return float(np.sqrt(max(np.linalg.det(J @ J.T), 0.0)))

    def reach_bound(self, frame: str = "torch_tcp") -> tuple[FloatArray, float]:
        """A sphere the frame's origin never leaves: centre p_RJ (3,) = the first joint's origin, radius [m].

        The radius sums the distances between consecutive joint origins and the frame's offset from its joint;
        a target farther than that from the centre is out of reach whatever the joint values.
        """
        if frame not in self._reach:
            fr = self._model.frames[self.frame_id(frame)]
            j = int(fr.parentJoint)
            if j == 0:  # fixed to the base
                self._reach[frame] = (np.array(fr.placement.translation), 0.0)
            else:
                radius = float(np.linalg.norm(fr.placement.translation))
                while j > 1:
                    radius += float(np.linalg.norm(self._model.jointPlacements[j].translation))
                    j = int(self._model.parents[j])
                self._reach[frame] = (np.array(self._model.jointPlacements[1].translation), radius)
        centre, radius = self._reach[frame]
        return centre.copy(), radius

    def pose_and_jacobian(self, q: npt.ArrayLike, frame_id: int) -> tuple[FloatArray, FloatArray]:
        """X_RF (4, 4) of the frame with index ``frame_id`` and its Jacobian (6, dof) in F's own axes."""
        q = self._q(q)
        pin.computeJointJacobians(self._model, self._data, q)
        M_RF = pin.updateFramePlacement(self._model, self._data, frame_id)
        J_F = pin.getFrameJacobian(self._model, self._data, frame_id, pin.LOCAL)
        return np.array(M_RF.homogeneous), np.array(J_F)

    @staticmethod
    def pose_residual(X_RF: FloatArray, X_RT: FloatArray, J_F: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The 6D error of frame F against a target T, for Gauss-Newton / damped least-squares IK.

        X_RF, X_RT : (4, 4) poses in R.
        J_F : (6, dof) Jacobian of F in F's own axes (from :meth:`pose_and_jacobian`).
        Returns ``e`` (6,) = log6(X_FT) = [v; w], the twist in F's axes that carries F onto T in unit
        time, and ``J`` (6, dof) with e(q + dq) ~ e(q) - J dq, so that the Newton step is dq = J^+ e.
        """
        M_FT = pin.SE3(X_RF).actInv(pin.SE3(X_RT))
        return np.array(pin.log6(M_FT).vector), pin.Jlog6(M_FT.inverse()) @ J_F

    def pose_residual_at(
        self, q: FloatArray, frame_id: int, X_RT: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:meth:`pose_and_jacobian` and :meth:`pose_residual` in one: (X_RF (4, 4), e (6,), J (6, dof)) at q (dof,),
        the same numbers without the placement's round trip through an array (an IK iteration's kinematics)."""
        pin.computeJointJacobians(self._model, self._data, q)
        M_RF = pin.updateFramePlacement(self._model, self._data, frame_id)
        J_F = pin.getFrameJacobian(self._model, self._data, frame_id, pin.LOCAL)
        M_FT = M_RF.actInv(pin.SE3(X_RT))
        return np.array(M_RF.homogeneous), np.array(pin.log6(M_FT).vector), pin.Jlog6(M_FT.inverse()) @ J_F

    def integrate(self, q: npt.ArrayLike, dq: npt.ArrayLike) -> FloatArray:
        """q (+) dq on the configuration space (plain addition for revolute joints), as a new array."""
        return np.array(pin.integrate(self._model, self._q(q), np.asarray(dq, dtype=float)))


def _translated(M: pin.SE3, d: FloatArray) -> pin.SE3:
    """translation(d) * M: the placement M moved by d [m] in its parent's axes."""
    return pin.SE3(np.array(M.rotation), np.array(M.translation) + d)
