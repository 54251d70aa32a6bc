"""The arm inside the simulated cell: a URDF posed by joint name, timed joint trajectories played back kinematically
(deterministic, no dynamics), poses from PyBullet's own forward kinematics (an independent check of the Pinocchio
model), and the weld bead drawn where the arc is on. Frames: W world, R robot base. Units: metres, radians, seconds."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pybullet
from pybullet_utils.bullet_client import BulletClient
from scipy.spatial.transform import Rotation

from cell.config.sim import BeadStyle
from cell.errors import PlanError, ScenarioError
from cell.geometry import FloatArray, make_pose, readonly
from cell.sim.execution import _check_trajectory, _events, _interp_rows, _record_times
from cell.types.execution import Event, Execution

__all__ = ["BeadStyle", "Event", "Execution", "SimRobot", "add_bead", "bead_chords", "bead_segment"]

_MOVABLE = (pybullet.JOINT_REVOLUTE, pybullet.JOINT_PRISMATIC)
_LIMIT_TOL = 1e-6  # [rad] how far a played configuration may lie outside the URDF limits (rounding)


# PyBullet orders quaternions (x, y, z, w), as scipy's Rotation.as_quat/from_quat do; Pinocchio and Eigen
# print (w, x, y, z). Every PyBullet quaternion of the robot and the bead passes through these two functions.
def _quat_from_matrix(R: FloatArray) -> list[float]:
    """PyBullet quaternion (x, y, z, w) of a rotation matrix (3, 3)."""
    return [float(v) for v in Rotation.from_matrix(R).as_quat()]


def _matrices_from_quats(quats: npt.ArrayLike) -> FloatArray:
    """Rotation matrices (n, 3, 3) from PyBullet quaternions (n, 4) ordered (x, y, z, w)."""
    return np.asarray(Rotation.from_quat(np.asarray(quats, dtype=float).reshape(-1, 4)).as_matrix())


def _pose(position: Sequence[float], quat_xyzw: Sequence[float]) -> FloatArray:
    return make_pose(_matrices_from_quats(quat_xyzw)[0], position)


def _chord_points(path: FloatArray, step: float) -> FloatArray:
    """Points (k, 3) along a polyline at arc lengths 0, step, 2 step, ..., and its end."""
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] < 1e-9:
        return path[:1]
    n = max(int(np.ceil(s[-1] / step - 1e-9)), 1)
    targets = np.linspace(0.0, s[-1], n + 1)
    return _interp_rows(targets, s, path)


class SimRobot:
    """A fixed-base arm in a PyBullet client, posed and read by joint and link name.

    client : the owning cell's client. urdf_path : the arm's URDF. X_WR : (4, 4) pose of the URDF root link
    (``base_link``) in W. q : (dof,) initial joint values [rad] in ``joint_names`` order.
    joint_names : order of q; default the movable joints in URDF tree order (give ``RobotModel.joint_names`` to
    be sure both models agree).
    """

    def __init__(
        self,
        client: BulletClient,
        urdf_path: str | Path,
        X_WR: npt.ArrayLike,
        q: npt.ArrayLike,
        joint_names: Sequence[str] | None = None,
    ) -> None:
        path = Path(urdf_path)
        if not path.is_file():
            raise ScenarioError(f"robot URDF {path} not found")
        X = np.asarray(X_WR, dtype=float)
        if X.shape != (4, 4):
            raise ValueError(f"X_WR must be (4, 4), got {X.shape}")
        self._c = client
        try:
            # loadURDF places the root link's own frame (not its inertial frame) at basePosition/Orientation.
            self.body = int(
                client.loadURDF(
                    str(path),
                    basePosition=[float(v) for v in X[:3, 3]],
                    baseOrientation=_quat_from_matrix(X[:3, :3]),
                    useFixedBase=True,
                )
            )
        except pybullet.error as exc:
            raise ScenarioError(f"robot URDF {path} cannot be loaded by PyBullet: {exc}") from exc
        self.name = client.getBodyInfo(self.body)[1].decode()
        self.base_link = client.getBodyInfo(self.body)[0].decode()
        self._links: dict[str, int] = {self.base_link: -1}
        movable: dict[str, int] = {}
        lower: dict[str, float] = {}
        upper: dict[str, float] = {}
        for j in range(client.getNumJoints(self.body)):
            info = client.getJointInfo(self.body, j)
            self._links[info[12].decode()] = j  # a link's index is the index of its parent joint
            if info[2] in _MOVABLE:
                jname = info[1].decode()
                movable[jname] = j
                lower[jname], upper[jname] = float(info[8]), float(info[9])
        names = tuple(movable) if joint_names is None else tuple(joint_names)
        unknown = [n for n in names if n not in movable]
        if unknown or len(set(names)) != len(movable):
            raise ScenarioError(
                f"robot {self.name}: joint_names {', '.join(names)} must name each movable joint once; "
                f"movable joints: {', '.join(movable)}"
            )
        self.joint_names: tuple[str, ...] = names
        self._joint_ids = [movable[n] for n in names]
        self.q_min = readonly([lower[n] for n in names])
        self.q_max = readonly([upper[n] for n in names])
        # pose of the root link frame in its inertial frame (getBasePositionAndOrientation gives the latter)
        dyn = client.getDynamicsInfo(self.body, -1)
        self._X_inertial_base = np.linalg.inv(_pose(dyn[3], dyn[4]))
        base = client.getBasePositionAndOrientation(self.body)
        self._base0 = (np.array(base[0], dtype=float), [float(v) for v in base[1]])
        self._track_W: FloatArray | None = None  # unit axis in W of a linear track under the base
        self._e1_next: FloatArray | None = None
        self.set_q(q)

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    def on_track(self, axis_W: npt.ArrayLike) -> None:
        """The base rides a linear track along ``axis_W`` (3,) in W: E1 = 0 is where it was loaded (X_WR)."""
        a = np.asarray(axis_W, dtype=float)
        self._track_W = a / np.linalg.norm(a)

    def set_e1(self, e1: float) -> None:
        """Put the base at E1 = e1 [m] on its track (a translation of the whole arm along the axis)."""
        if self._track_W is None:
            raise ScenarioError(f"robot {self.name} has no linear track: E1 = {e1 * 1000:.1f} mm cannot be set")
        p0, orn = self._base0
        self._c.resetBasePositionAndOrientation(self.body, [float(v) for v in p0 + e1 * self._track_W], orn)

    def stage_e1(self, e1: npt.ArrayLike | None) -> None:
        """E1 [m] per sample (n,) of the next :meth:`play` (the track moves the base as it plays); None: the
        base stays where it is."""
        self._e1_next = None if e1 is None else np.asarray(e1, dtype=float)

    @property
    def link_names(self) -> tuple[str, ...]:
        return tuple(self._links)

    def link_index(self, link: str) -> int:
        """PyBullet link index of ``link`` (-1 for the root); KeyError naming the links if there is none."""
        try:
            return self._links[link]
        except KeyError:
            raise KeyError(f"robot {self.name} has no link {link!r}; links: {', '.join(self._links)}") from None

    def _q(self, q: npt.ArrayLike) -> FloatArray:
        qa = np.asarray(q, dtype=float)
        if qa.shape != (self.dof,) or not np.all(np.isfinite(qa)):
            raise ValueError(f"robot {self.name}: q must be {self.dof} finite values [rad], got {qa.shape}")
        return qa

    def set_q(self, q: npt.ArrayLike) -> None:
        """Put the arm at joint values q (dof,) [rad] (kinematic: no dynamics, zero velocity)."""
        qa = self._q(q)
        self._c.resetJointStatesMultiDof(self.body, self._joint_ids, [[float(v)] for v in qa])

    @property
    def q(self) -> FloatArray:
        """Current joint values (dof,) [rad], read back from PyBullet."""
        return np.array([s[0] for s in self._c.getJointStates(self.body, self._joint_ids)])

    def link_pose(self, link: str) -> FloatArray:
        """X_W_link (4, 4): pose of the URDF frame of ``link`` in W at the current joint values."""
        i = self.link_index(link)
        if i < 0:
            pos, orn = self._c.getBasePositionAndOrientation(self.body)
            return _pose(pos, orn) @ self._X_inertial_base
        state = self._c.getLinkState(self.body, i, computeForwardKinematics=True)
        return _pose(state[4], state[5])  # worldLinkFramePosition/Orientation: the URDF link frame

    def limit_violation(self, q: FloatArray) -> str:
        """'' when every row of q (n, dof) is within the URDF limits, else which joint leaves them first."""
        out = (q < self.q_min - _LIMIT_TOL) | (q > self.q_max + _LIMIT_TOL)
        if not out.any():
            return ""
        row, col = np.argwhere(out)[0]
        return (
            f"{self.joint_names[col]} = {np.degrees(q[row, col]):.2f} deg at sample {row}, "
            f"limits [{np.degrees(self.q_min[col]):.2f}, {np.degrees(self.q_max[col]):.2f}] deg"
        )

    def play(
        self,
        times: npt.ArrayLike,
        q: npt.ArrayLike,
        arc_on: npt.ArrayLike,
        *,
        tcp_link: str,
        record_dt: float,
        record_poses: bool = True,
        marks: Sequence[tuple[float, str]] = (),
    ) -> Execution:
        """Play a timed joint trajectory kinematically and record the tool path (see ``SimCell.execute``)."""
        t_in, q_in, arc_in = _check_trajectory(times, q, arc_on, self.dof)
        e1_in, self._e1_next = self._e1_next, None
        if e1_in is not None and (e1_in.shape != t_in.shape or not np.all(np.isfinite(e1_in))):
            raise ValueError(f"execute: e1 must be ({len(t_in)},) finite values [m], got {e1_in.shape}")
        tcp = self.link_index(tcp_link)
        bad = self.limit_violation(q_in)
        if bad:
            raise PlanError(f"trajectory leaves the joint limits of robot {self.name}: {bad}")
        t_rec = _record_times(t_in, arc_in, record_dt)
        q_rec = _interp_rows(t_rec, t_in, q_in)
        e1_rec = None if e1_in is None else np.interp(t_rec, t_in, e1_in)
        arc_rec = arc_in[np.searchsorted(t_in, t_rec, side="right") - 1]
        pos = np.empty((len(t_rec), 3))
        quat = np.empty((len(t_rec), 4))
        for k, qk in enumerate(q_rec):
            if e1_rec is not None and (k == 0 or e1_rec[k] != e1_rec[k - 1]):
                self.set_e1(float(e1_rec[k]))  # the track carries the base
            self._c.resetJointStatesMultiDof(self.body, self._joint_ids, [[float(v)] for v in qk])
            if tcp < 0:
                p, o = self._c.getBasePositionAndOrientation(self.body)
                X = _pose(p, o) @ self._X_inertial_base
                pos[k], quat[k] = X[:3, 3], _quat_from_matrix(X[:3, :3])
            else:
                state = self._c.getLinkState(self.body, tcp, computeForwardKinematics=True)
                pos[k], quat[k] = state[4], state[5]
        X_W_tcp = None
        if record_poses:
            X_W_tcp = np.tile(np.eye(4), (len(t_rec), 1, 1))
            X_W_tcp[:, :3, :3] = _matrices_from_quats(quat)
            X_W_tcp[:, :3, 3] = pos
        events = _events(t_rec, q_rec, pos, arc_rec, marks)
        return Execution(times=t_rec, q=q_rec, tcp_W=pos, arc_on=arc_rec, events=events, X_W_tcp=X_W_tcp)


def bead_chords(tcp_W: FloatArray, arc_on: npt.NDArray[np.bool_], step_m: float) -> list[tuple[FloatArray, FloatArray]]:
    """Straight pieces (a, b) [m] of about ``step_m`` along the tool path where the arc is on.

    The arc state ``arc_on[k]`` holds from record k to record k + 1, so a run of on-samples k0..k1 welds the
    path from point k0 to point k1 + 1 (or to the last point).
    """
    out: list[tuple[FloatArray, FloatArray]] = []
    on = np.asarray(arc_on, bool)
    k = 0
    n = len(on)
    while k < n:
        if not on[k]:
            k += 1
            continue
        k1 = k
        while k1 + 1 < n and on[k1 + 1]:
            k1 += 1
        pts = _chord_points(tcp_W[k : min(k1 + 2, n)], step_m)
        out.extend((pts[i], pts[i + 1]) for i in range(len(pts) - 1))
        k = k1 + 1
    return out


def add_bead(client: BulletClient, a_W: FloatArray, b_W: FloatArray, style: BeadStyle) -> int:
    """A visual-only capsule (no collision shape) from a to b [m] in W; returns its body id."""
    d = np.asarray(b_W, float) - np.asarray(a_W, float)
    length = float(np.linalg.norm(d))
    z = d / length
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    R = np.column_stack([x, np.cross(z, x), z])  # PyBullet capsules lie along their local z axis
    visual = client.createVisualShape(
        pybullet.GEOM_CAPSULE, radius=style.radius_m, length=length, rgbaColor=list(style.rgba)
    )
    body = client.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=-1,
        baseVisualShapeIndex=visual,
        basePosition=[float(v) for v in (np.asarray(a_W, float) + d / 2.0)],
        baseOrientation=_quat_from_matrix(R),
    )
    return int(body)


def bead_segment(client: BulletClient, body: int) -> tuple[FloatArray, FloatArray]:
    """End points (a, b) in W [m] of a bead capsule's axis, read back from PyBullet."""
    pos, orn = client.getBasePositionAndOrientation(body)
    shape = client.getVisualShapeData(body)[0]
    half = float(shape[3][0]) / 2.0  # visual dimensions of a capsule: (length, radius, 0)
    axis = _matrices_from_quats(orn)[0][:, 2]
    p = np.asarray(pos, dtype=float)
    return p - half * axis, p + half * axis
