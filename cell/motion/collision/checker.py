"""Collision checking with coal (through Pinocchio's GeometryModel): the arm against the cell's obstacles and
itself, at a configuration and along a motion by conservative advancement (docs/planning.md section 5). With
:mod:`cell.motion.collision.shapes`, the only coal importer. Everything in the robot base frame R [m]."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from cell.config.motion import CollisionOptions
from cell.geometry import FloatArray, readonly
from cell.motion.collision.contact import Contact, advance_along, advance_linear, deep_sample
from cell.motion.collision.relative import RelativeBounds
from cell.motion.collision.shapes import (
    Boxes,
    ToolShapes,
    add_obstacles,
    joint_radii,
    local_spheres,
    signed,
    torch_contacts,
    trim_near_tcp,
)
from cell.motion.robot import RobotModel
from cell.types import Part
from cell.types.track import LinearTrack
from cell.types.trajectory import Trajectory


@dataclass
class _Pairs:
    obstacle: list[int] = field(default_factory=list)
    self_: list[int] = field(default_factory=list)


class CollisionChecker:
    """Robot against obstacles and itself, for one arm and one set of obstacles (build one per plan).

    Holds Pinocchio/coal scratch data: not thread-safe.
    """

    def __init__(self, robot: RobotModel, obstacles: Sequence[Part], options: CollisionOptions | None = None) -> None:
        self.robot = robot
        self.options = opt = options or CollisionOptions()
        self._model = pin.buildModelFromUrdf(str(robot.source))
        if tuple(self._model.names[1:]) != robot.joint_names:
            raise ValueError("CollisionChecker: the URDF's joints differ from the RobotModel's")
        geom = pin.buildGeomFromUrdf(self._model, str(robot.source), pin.COLLISION)
        tcp = self._model.getFrameId(opt.tcp_frame)
        self._tcp_frame = tcp
        trim_near_tcp(self._model, geom, tcp, opt.tcp_clearance)
        self._n_robot = len(geom.geometryObjects)
        self.link_of: list[str] = [self._model.frames[o.parentFrame].name for o in geom.geometryObjects]
        # each obstacle's grown shape, its bound for the broad phase, the bodies whose shape is a surface only
        bounds, self._solids = add_obstacles(geom, obstacles, opt)
        self.link_of.extend(p.name for p in obstacles)
        self.obstacle_names = tuple(p.name for p in obstacles)
        self._pairs = _Pairs()
        parents = self._model.parents
        objs = geom.geometryObjects
        for i in range(self._n_robot):
            ji = objs[i].parentJoint
            for k in range(i + 1, len(objs)):
                jk = objs[k].parentJoint
                if k >= self._n_robot:  # robot shape vs obstacle (the fixed base never moves: skip it)
                    if ji != 0:
                        self._pairs.obstacle.append(len(geom.collisionPairs))
                        geom.addCollisionPair(pin.CollisionPair(i, k))
                    continue
                if ji == jk or parents[max(ji, jk)] == min(ji, jk):
                    continue
                self._pairs.self_.append(len(geom.collisionPairs))
                geom.addCollisionPair(pin.CollisionPair(i, k))
        self._geom = geom
        self._gdata = pin.GeometryData(geom)
        self._data = self._model.createData()
        self._radius, pairs = joint_radii(self._model, objs[: self._n_robot]), geom.collisionPairs
        ends = [(objs[pairs[k].first].parentJoint, objs[pairs[k].second].parentJoint) for k in self._pairs.self_]
        self._relative = RelativeBounds.build(list(parents), self._radius, ends)  # the path check's step bounds
        self._tool_shapes = [i for i in range(self._n_robot) if objs[i].parentJoint == self._model.njoints - 1]
        self._obstacle_ids = list(range(self._n_robot, len(objs)))
        self._tool = ToolShapes.build(self._model, self._data, self._geom, self._tcp_frame, self._tool_shapes)
        self._boxes = Boxes.build(geom, self._obstacle_ids, bounds)
        # The broad phase of a check: every robot shape's bounding sphere (centre in its own frame, radius), and
        # per pair its two shapes; a pair whose spheres (or sphere and box) are farther apart than what could
        # change the answer gets that lower bound instead of a distance query.
        self._centre_arr, self._radius_arr = local_spheres(objs[: self._n_robot])
        self._pair_first = np.array([p.first for p in pairs], dtype=int)
        self._pair_second = np.array([p.second for p in pairs], dtype=int)
        self._is_obstacle_pair = self._pair_second >= self._n_robot
        self._base_shapes = [i for i in range(self._n_robot) if objs[i].parentJoint == 0]
        self._base_offset = np.zeros(3)
        self._base_X = np.eye(4)  # the base's rigid placement (place_base)
        self.set_base(robot.base_offset_R)

    # -- the base on a linear track (docs/track.md) -------------------------------------------------------------

    @property
    def base_offset_R(self) -> FloatArray:
        """(3,) [m]: where the arm's base stands in R now (0: the base at R)."""
        return readonly(self._base_offset.copy())

    def set_base(self, offset_R: npt.ArrayLike) -> None:
        """Move the arm's base (its first joint and the shapes fixed to the base) to ``offset_R`` (3,) [m] in R, as
        a linear track carries it; the obstacles stay where they are (nothing is rebuilt). Self-collision is
        unchanged by a translation of the whole arm; the torch test (:meth:`torch_clear`) takes poses in R and
        needs no base at all."""
        d = np.asarray(offset_R, dtype=float).reshape(3)
        move = d - self._base_offset
        if not np.any(move):
            return
        M = self._model.jointPlacements[1]
        self._model.jointPlacements[1] = pin.SE3(np.array(M.rotation), np.array(M.translation) + move)
        for i in self._base_shapes:
            obj = self._geom.geometryObjects[i]
            P = obj.placement
            obj.placement = pin.SE3(np.array(P.rotation), np.array(P.translation) + move)
        self._base_offset = d.copy()

    def place_base(self, X_base: npt.ArrayLike) -> None:
        """Put the arm's base (its first joint and the shapes fixed to the base) at the rigid pose X_base (4, 4)
        in the obstacles' frame (identity: where R puts it), as when the obstacles turn on a positioner and the arm
        is seen from them; nothing is rebuilt. Undone by ``place_base(np.eye(4))``; not to be mixed with
        :meth:`set_base`."""
        X = np.asarray(X_base, dtype=float)
        step = pin.SE3(X @ np.linalg.inv(self._base_X))
        self._model.jointPlacements[1] = step * self._model.jointPlacements[1]
        for i in self._base_shapes:
            obj = self._geom.geometryObjects[i]
            obj.placement = step * obj.placement
        self._base_X = X.copy()

    def base_key(self) -> bytes:
        """Where the arm's base stands (:meth:`set_base`, :meth:`place_base`) as bytes: two equal keys, the same
        answers to every query."""
        return self._base_X.tobytes() + self._base_offset.tobytes()

    def step_bound(self, q: npt.ArrayLike) -> tuple[float, Contact | None]:
        """The motion [m] any arm point may make from q (dof,) before the next check, or the contact at q."""
        return self._step_bound(q)

    def check_trajectory(self, traj: Trajectory, track: LinearTrack | None = None) -> Contact | None:
        """:meth:`check_path` of a timed motion with the base where the track puts it at every sample
        (``traj.e1`` along ``track.axis_R``; without either, where the base stands now). A motion of the track
        itself is advanced conservatively in (q, E1): a step moves no arm point more than the joints' bound plus
        |delta E1|. The base is left where it was."""
        if traj.e1 is None or track is None:
            return self.check_path(traj.q, traj.times)
        keep = self._base_offset.copy()
        e1 = np.asarray(traj.e1, dtype=float)
        try:
            if np.ptp(e1) == 0.0:
                self.set_base(track.offset_R(float(e1[0])))
                return self.check_path(traj.q, traj.times)
            dof = traj.dof

            def step_bound(x: FloatArray) -> tuple[float, Contact | None]:
                self.set_base(track.offset_R(float(x[dof])))
                return self._step_bound(x[:dof])

            def motion(dx: FloatArray) -> float:
                return self.motion_bound(dx[:dof]) + abs(float(dx[dof]))

            hit = advance_along(step_bound, motion, np.column_stack([traj.q, e1]), traj.times)
            if hit is None:
                return None
            return Contact(hit.a, hit.b, hit.depth, hit.p_R, readonly(np.asarray(hit.q)[:dof]), hit.index, hit.t)
        finally:
            self.set_base(keep)

    # -- queries ---------------------------------------------------------------------------------------------

    def _distances(self, q: FloatArray) -> FloatArray:
        """Signed distance [m] of every checked pair at configuration q (negative: penetration)."""
        pin.computeDistances(self._model, self._data, self._geom, self._gdata, np.asarray(q, dtype=float))
        d = np.fromiter((r.min_distance for r in self._gdata.distanceResults), float, len(self._geom.collisionPairs))
        n = self._n_robot
        for k in np.flatnonzero(self._is_obstacle_pair & (d > 0.0)) if self._solids else ():
            body = self._solids.get(int(self._pair_second[k]) - n)
            if body is not None:  # a surface mesh: inside the body is a penetration
                i = int(self._pair_first[k])
                X = np.array(self._gdata.oMg[i].homogeneous)
                d[k] = signed(float(d[k]), body, X[:3, :3] @ self._centre_arr[i] + X[:3, 3])
        return d

    def _contact(self, k: int, d: float, q: FloatArray, index: int, t: float) -> Contact:
        pair = self._geom.collisionPairs[k]
        res = self._gdata.distanceResults[k]
        a, b = self.link_of[pair.first], self.link_of[pair.second]
        return Contact(a, b, float(d), readonly(np.array(res.getNearestPoint1())), readonly(q), index, t)

    def clearance(self, q: npt.ArrayLike) -> tuple[float, float]:
        """(clearance to obstacles, clearance between non-adjacent links) [m] at configuration q (dof,)."""
        d = self._distances(np.asarray(q, dtype=float))
        obs = d[self._pairs.obstacle] if self._pairs.obstacle else np.array([np.inf])
        slf = d[self._pairs.self_] if self._pairs.self_ else np.array([np.inf])
        return float(obs.min()), float(slf.min())

    def shape_spheres(self, q: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Each arm shape's bounding sphere at q (dof,) [rad]: centres (n, 3) in R [m] and radii (n,) [m]."""
        m, data, gdata = self._model, self._data, self._gdata
        pin.forwardKinematics(m, data, np.asarray(q, dtype=float))
        pin.updateGeometryPlacements(m, data, self._geom, gdata)
        X = np.array([g.homogeneous for g in gdata.oMg[: self._n_robot]])
        return np.einsum("nij,nj->ni", X[:, :3, :3], self._centre_arr) + X[:, :3, 3], self._radius_arr

    def _near_distances(self, q: FloatArray, cut_obstacle: float, cut_self: float) -> FloatArray:
        """Like :meth:`_distances`, but a pair whose bounding spheres (a robot shape's against another's, or
        against an obstacle box) are farther apart than ``cut_obstacle`` / ``cut_self`` [m] holds that lower
        bound instead of its distance (not queried): exact wherever the distance could be at most the cut."""
        geom, gdata, n = self._geom, self._gdata, self._n_robot
        c, _ = self.shape_spheres(q)
        a, b, obs = self._pair_first, self._pair_second, self._is_obstacle_pair
        lower = np.empty(len(a))
        to_box = self._boxes.sphere_distance(c, self._radius_arr)  # (robot shapes, boxes)
        lower[obs] = to_box[a[obs], b[obs] - n]
        slf = ~obs
        lower[slf] = np.linalg.norm(c[a[slf]] - c[b[slf]], axis=1) - self._radius_arr[a[slf]] - self._radius_arr[b[slf]]
        cut = np.where(obs, cut_obstacle, cut_self)
        for k in np.flatnonzero(lower <= cut):
            d = pin.computeDistance(geom, gdata, int(k)).min_distance
            if self._solids and obs[k]:  # a surface mesh: inside the body is a penetration
                d = signed(d, self._solids.get(int(b[k]) - n), c[a[k]])
            lower[k] = d
        return lower

    def check(self, q: npt.ArrayLike, index: int = 0, t: float = float("nan")) -> Contact | None:
        """The deepest contact at configuration q (dof,), or None when the arm is clear."""
        q = np.asarray(q, dtype=float)
        mc = self.options.min_clearance
        d = self._near_distances(q, mc, mc)  # a pair farther than the threshold is no contact
        k = int(np.argmin(d))
        if d[k] <= self.options.min_clearance:
            return self._contact(k, float(d[k]), q, index, t)
        return None

    def check_deep(self, q: npt.ArrayLike, depth: float) -> Contact | None:
        """:meth:`check`'s deepest contact at q (dof,) when it lies ``depth`` [m] or more deep, else None; only the
        pairs whose bounding spheres overlap by that much are queried (a probe for a deep contact)."""
        q = np.asarray(q, dtype=float)
        d = self._near_distances(q, -depth, -depth)
        k = int(np.argmin(d))
        return self._contact(k, float(d[k]), q, 0, float("nan")) if d[k] <= -depth else None

    def _step_bound(self, q: npt.ArrayLike) -> tuple[float, Contact | None]:
        """Allowed motion [m] from q before the next check, or the contact at q."""
        q = np.asarray(q, dtype=float)
        mc, step = self.options.min_clearance, self.options.max_step
        # a pair farther than what allows the largest step cannot shorten it (two links: twice as far)
        d = self._near_distances(q, mc + step + 1e-9, 2.0 * (mc + step) + 1e-9)
        k = int(np.argmin(d))
        if d[k] <= mc:
            return 0.0, self._contact(k, float(d[k]), q, 0, float("nan"))
        obs = float(d[self._pairs.obstacle].min()) if self._pairs.obstacle else np.inf  # (numpy: 580 pairs on
        slf = float(d[self._pairs.self_].min()) if self._pairs.self_ else np.inf  # the ladder, per check)
        # two links of the arm can approach each other at twice the single-link bound
        free = min(obs, slf / 2.0) - self.options.min_clearance
        return float(min(free, self.options.max_step)), None

    def _budgets(self, q: npt.ArrayLike) -> tuple[FloatArray, Contact | None]:
        """:meth:`_step_bound` per class of pairs (:class:`RelativeBounds`): each one's motion [m] allowed from q."""
        q = np.asarray(q, dtype=float)
        mc, step = self.options.min_clearance, self.options.max_step
        d = self._near_distances(q, mc + step + 1e-9, mc + step + 1e-9)  # a farther pair cannot shorten the step
        k = int(np.argmin(d))
        if d[k] <= mc:
            return np.zeros(len(self._relative.weights)), self._contact(k, float(d[k]), q, 0, float("nan"))
        obs = float(d[self._pairs.obstacle].min()) if self._pairs.obstacle else np.inf
        return self._relative.budgets(obs - mc, d[self._pairs.self_] - mc, step), None

    def motion_bound(self, dq: npt.ArrayLike) -> float:
        """Upper bound [m] on how far any arm point moves for a joint step dq (dof,) [rad]."""
        return float(np.abs(np.asarray(dq, dtype=float)) @ self._radius)

    def check_path(
        self, q_path: npt.ArrayLike, times: npt.ArrayLike | None = None, min_step: float = 0.001
    ) -> Contact | None:
        """First contact along a path of configurations (n, dof), linear in joint space between samples.

        times : (n,) [s] to report when the contact happens (optional). ``min_step`` [m]: smallest motion
        between two checks (near contact the check spacing shrinks to this, so a touch thinner than it can be
        missed). Returns None when the whole path is clear.
        """
        return advance_linear(self._budgets, self._relative.weights, q_path, times, min_step)

    def deep_contact(self, q_path: npt.ArrayLike, min_step: float = 0.001) -> Contact | None:
        """A contact :meth:`check_path` cannot miss, found quickly where the path (n, dof) runs deep into something:
        a sample of it, probed coarse to fine (at most 16), more than twice ``min_step`` inside a contact (between
        two of the advancement's checks no distance falls by more than that). None: none found, the path may
        still collide (only :meth:`check_path` says). Not the path's first contact."""
        depth = 2.0 * min_step + 0.001 - self.options.min_clearance
        return deep_sample(lambda q: self.check_deep(q, depth), q_path, depth, probes=16)

    def collides(self, q_path: npt.ArrayLike, min_step: float = 0.001) -> bool:
        """Whether :meth:`check_path` finds a contact along the path (n, dof): :meth:`deep_contact` first, for a
        search that needs only to know that a motion collides, not where it first does."""
        return self.deep_contact(q_path, min_step) is not None or self.check_path(q_path, None, min_step) is not None

    def torch_clear(self, X_RT: npt.ArrayLike, q_ref: npt.ArrayLike) -> Contact | None:
        """Contact of the tool-side shapes (everything rigid with the flange) against the obstacles when the TCP
        is at X_RT (4, 4), without IK (q_ref (dof,) is carried in the contact). The tool's shapes are placed
        from their fixed poses in the TCP frame; an obstacle box farther from a shape's bounding sphere than the
        clearance threshold is skipped without a distance query (the broad phase: only the few parts near the
        torch cost a query, however many parts the cell holds)."""
        return self.torch_clear_many(np.asarray(X_RT, dtype=float)[None], q_ref)[0]

    def torch_clear_many(self, X_RT: npt.ArrayLike, q_ref: npt.ArrayLike, first: bool = False) -> list[Contact | None]:
        """:meth:`torch_clear` of every TCP pose X_RT (m, 4, 4), the broad phase of all of them in one query.
        first : a pose's first contact found instead of its deepest (enough to know that it collides)."""
        return torch_contacts(
            self._tool,
            self._boxes,
            self._tool_shapes,
            self._obstacle_ids,
            self.link_of,
            self.options.min_clearance,
            X_RT,
            q_ref,
            first,
            self._solids,
        )
