"""The simulated cell: one object owns its PyBullet client, builds the as-built cell (bodies found by name, never by
index) and renders depth cameras with the TinyRenderer (headless, the sampling :mod:`cell.sim.camera` models); an
arm added to it plays back trajectories, draws the bead and carries the eye-in-hand camera. World frame W, z up."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType, TracebackType

import numpy as np
import numpy.typing as npt

from cell.errors import ScenarioError, SensorError
from cell.geometry import FloatArray, make_pose
from cell.scenario import CameraSpec, Scenario
from cell.sim.board import Size2, add_board, colour_noise, place_body
from cell.sim.bodies import add_box, add_floor, add_part, move_bodies
from cell.sim.camera import intrinsics_for
from cell.sim.faults import built_parts, corrupt_depth, occluder_boxes
from cell.sim.floor import Floor, floor_colour
from cell.sim.lens import Sensor, sensor_for
from cell.sim.noise import apply_noise, believed_pose, specular_dropout
from cell.sim.quiet import BulletClient, pybullet, silenced_fds
from cell.sim.render_cache import draw, mesh_digest
from cell.sim.robot import BeadStyle, SimRobot, add_bead, bead_chords, bead_segment
from cell.types import Box, CameraIntrinsics, DepthImage, Part
from cell.types.execution import Execution

GROUND = "ground"
TABLE = "table"
_GROUND_SIZE = (20.0, 20.0, 0.02)  # [m] a thin box whose top face is the plane z = 0
_RGBA = {GROUND: (0.35, 0.35, 0.35, 1.0), TABLE: (0.55, 0.45, 0.35, 1.0)}
_PART_RGBA = (0.7, 0.72, 0.75, 1.0)
_OCCLUDER_RGBA = (0.2, 0.3, 0.8, 1.0)
_FIXTURE_RGBA = (0.45, 0.45, 0.47, 1.0)  # grey: clamps, stops and jigs
FIXTURE_PREFIX = "fixture:"  # body names of the map's fixtures: ``fixture:<name>``
TACK_PREFIX = "tack:"  # tack welds laid before the cell sees the part (``simulation.tacks_present``), not fixtures
_TACK_RGBA = (0.3, 0.3, 0.32, 1.0)
DEFAULT_BEAD = BeadStyle()
EYE_IN_HAND_LINK = "camera_optical"  # the arm's optical frame of the eye-in-hand camera (z forward, y down)
FLANGE_LINK = "tool0"  # the arm's flange frame (a hand-eye calibration's X_FC is measured from it)


class SimCell:
    """The as-built cell in PyBullet.

    scenario : the cell (table, cameras, noise, seed).
    parts_W : the as-built parts in W (``asbuilt.parts.as_built_parts``), boxes or polyhedra; names must be unique.
    gui : show PyBullet's GUI (needs a display); headless ``DIRECT`` by default.
    fixtures_W : the map's fixtures in W (``asbuilt.parts.as_built_fixtures``): clamps, stops, jigs, rendered grey as
        bodies ``fixture:<name>`` so the cameras see them as in the real cell; they stay put when the part is turned.
        Entries named ``tack:...`` (``asbuilt.parts.as_built_fixtures`` with ``simulation.tacks_present``) are tack
        welds' beads instead: bodies of that name, dark, on the part (they turn with it).
    The scenario's ``faults:`` (:mod:`cell.sim.faults`) are applied here: parts in ``missing_parts`` are not
    built (``parts_W`` still lists them: it is the design as built), occluders are added as bodies
    ``occluder:<name>``, and a faulty camera's images are corrupted after the noise model.

    Use as a context manager (``with SimCell(scenario, parts) as sim:``) or call :meth:`close`.
    """

    def __init__(
        self, scenario: Scenario, parts_W: Sequence[Part], *, gui: bool = False, fixtures_W: Sequence[Part] = ()
    ) -> None:
        names = [p.name for p in parts_W]
        reserved = {GROUND, TABLE}
        clash = sorted({n for n in names if names.count(n) > 1 or n in reserved})
        if clash:
            raise ScenarioError(
                f"part names must be unique and not {GROUND!r}/{TABLE!r}; offending: {', '.join(clash)}"
            )
        self.scenario = scenario
        self.parts_W: tuple[Part, ...] = tuple(parts_W)
        with silenced_fds():  # pybullet's banners: not on stdout (it carries our results), not on stderr
            self._client: BulletClient | None = BulletClient(connection_mode=pybullet.GUI if gui else pybullet.DIRECT)
        self._bodies: dict[str, int] = {}
        self._noise_rngs: dict[str, np.random.Generator] = {}
        self._sensors: dict[str, Sensor] = {}
        self._robot: SimRobot | None = None
        self._beads: list[int] = []
        ground = Box(make_pose(p=(0.0, 0.0, -_GROUND_SIZE[2] / 2.0)), np.array(_GROUND_SIZE))
        self._drawn: dict[int, bytes] = {}  # what a vertex mesh's shape data does not say (render_cache.scene_key)
        self._bodies[GROUND] = add_floor(self.client, ground, _RGBA[GROUND], drawn=gui)
        self._floor = Floor(0.0, (ground.size[0] / 2.0, ground.size[1] / 2.0), floor_colour(_RGBA[GROUND]))
        # The floor's key: its size and colour (drawn by Floor, not by TinyRenderer: its body has no face to digest).
        self._drawn[self._bodies[GROUND]] = mesh_digest(ground.size[None, :], np.array([self._floor.rgb]))
        table = scenario.table
        self._add_box(TABLE, Box(make_pose(p=table.center_m), np.array(table.size_m)), _RGBA[TABLE])
        # Faults (scenario ``faults:``): parts not built are left out, objects the map does not know are added.
        for part in built_parts(self.parts_W, scenario.faults):
            self._bodies[part.name] = self._add_part(part, _PART_RGBA)
        self._tacks: list[str] = []  # tack welds' beads (``tack:...``): on the part, they turn with it
        for fixture in fixtures_W:
            if fixture.name.startswith(TACK_PREFIX):
                self._bodies[fixture.name] = self._add_part(fixture, _TACK_RGBA)
                self._tacks.append(fixture.name)
                continue
            self._bodies[FIXTURE_PREFIX + fixture.name] = self._add_part(fixture, _FIXTURE_RGBA)
        for name, box in occluder_boxes(scenario.faults):
            self._add_box(name, box, _OCCLUDER_RGBA)

    # -- scene -----------------------------------------------------------------------------------------------

    @property
    def client(self) -> BulletClient:
        """The PyBullet client this cell owns (for adding a robot later); raises once closed."""
        if self._client is None:
            raise SensorError("the simulated cell is closed; create a new SimCell")
        return self._client

    @property
    def bodies(self) -> Mapping[str, int]:
        """Read-only map of body name -> PyBullet body id."""
        return MappingProxyType(self._bodies)

    def body_id(self, name: str) -> int:
        """The PyBullet body id of ``name`` (``"ground"``, ``"table"``, a part name or ``"fixture:<name>"``)."""
        if name not in self._bodies:
            raise KeyError(f"no body {name!r}; bodies: {', '.join(self._bodies)}")
        return self._bodies[name]

    def _add_part(self, part_W: Part, rgba: tuple[float, float, float, float]) -> int:
        body = add_part(self.client, part_W, rgba)
        if not part_W.is_box:  # drawn from its vertices: the image's key needs them
            self._drawn[body] = mesh_digest(*part_W.triangles())
        return body

    def _add_box(self, name: str, box_W: Box, rgba: tuple[float, float, float, float]) -> int:
        body = add_box(self.client, box_W, rgba)
        self._bodies[name] = body
        return body

    # -- cameras ---------------------------------------------------------------------------------------------

    def camera_spec(self, camera: str) -> CameraSpec:
        """The scenario's spec of ``camera``; :class:`SensorError` naming the cameras if there is none."""
        spec = self.scenario.cameras.get(camera)
        if spec is None:
            raise SensorError(
                f"no camera {camera!r} in scenario {self.scenario.name!r}; cameras: {', '.join(self.scenario.cameras)}"
            )
        return spec

    def intrinsics(self, camera: str) -> CameraIntrinsics:
        """Exact pinhole intrinsics [px] of ``camera``'s images, with the lens model the cell is told."""
        spec = self.camera_spec(camera)
        w, h = spec.resolution
        return intrinsics_for(w, h, np.radians(spec.hfov_deg), spec.told_distortion)

    def render(
        self, X_WC: FloatArray, intrinsics: CameraIntrinsics, near_m: float, far_m: float
    ) -> tuple[npt.NDArray[np.uint8], FloatArray]:
        """Noise-free colour (H, W, 3) uint8 and depth (H, W) [m] (0: nothing between near and far) from X_WC (4, 4);
        read back when this process drew the same scene from the same camera before (:mod:`cell.sim.render_cache`)."""
        return draw(self.client, self._drawn, X_WC, intrinsics, near_m, far_m, floor=self._floor)

    def capture(self, camera: str, X_WC: FloatArray | None = None) -> DepthImage:
        """One depth image from ``camera``.

        X_WC : true pose (4, 4) of the optical frame in W to render from; when None, the scenario's pose, or
            for an eye-in-hand camera with a robot loaded, the pose of the arm's ``camera_optical`` link.
        The image carries the *believed* pose (true pose with the camera's calibration error) and exact
        intrinsics. With ``scenario.noise == "realistic"`` the camera's sensor model is applied; its random
        stream starts from ``scenario.rng(camera)`` and continues across captures (a second capture has new
        noise).
        """
        return self._capture(camera, X_WC, colour=False)[0]

    def capture_rgbd(self, camera: str, X_WC: FloatArray | None = None) -> tuple[DepthImage, npt.NDArray[np.uint8]]:
        """One depth image as :meth:`capture` and the colour image (H, W, 3) uint8 taken with it (the same
        intrinsics and pose; with realistic noise the lens' blur and pixel noise, a stream of its own)."""
        return self._capture(camera, X_WC, colour=True)

    def _capture(
        self, camera: str, X_WC: FloatArray | None, *, colour: bool
    ) -> tuple[DepthImage, npt.NDArray[np.uint8]]:
        spec = self.camera_spec(camera)
        if X_WC is None and spec.mount == "eye_in_hand" and self._robot is not None:
            X_WC = self._robot.link_pose(EYE_IN_HAND_LINK)  # the camera rides on the arm
        X_true = spec.X_WC if X_WC is None else np.asarray(X_WC, dtype=float)
        if X_true.shape != (4, 4):
            raise ValueError(f"X_WC must be (4, 4), got {X_true.shape}")
        told = self.intrinsics(camera)
        sensor = self._sensors.setdefault(camera, sensor_for(spec, told))  # its lens, true focal and depth scale
        rgb, depth = self.render(X_true, intr := sensor.render, spec.near_m, spec.far_m)
        rgb = sensor.colour(rgb)
        if self.scenario.noise == "realistic":
            if colour:  # its own stream: the depth noise draws are the same with colour taken or not
                crng = self._noise_rngs.setdefault(camera + "/colour", self.scenario.rng(camera + "/colour"))
                rgb = colour_noise(rgb, spec.noise.colour_blur_px, spec.noise.colour_sigma, crng)
            rng = self._noise_rngs.setdefault(camera, self.scenario.rng(camera))
            noisy = apply_noise(depth, intr, spec.noise, rng)
            shiny = self.scenario.simulation.specular_dropout
            if shiny is not None:  # its own stream: the noise draws are the same with it on or off
                srng = self._noise_rngs.setdefault(camera + "/specular", self.scenario.rng(camera + "/specular"))
                noisy = specular_dropout(noisy, depth, intr, shiny, srng)
        else:
            noisy = depth.astype(np.float32)
        fault = self.scenario.faults.cameras.get(camera)
        if fault is not None:  # a broken camera (fault scenarios); its own stream, so noise draws are unchanged
            rng = self._noise_rngs.setdefault(camera + "/fault", self.scenario.rng(camera + "/fault"))
            noisy = corrupt_depth(noisy, fault, spec.near_m, spec.far_m, rng)
        X_WF = self._robot.link_pose(FLANGE_LINK) if self._robot is not None else None  # the measured X_FC's base
        X_told = believed_pose(spec, X_true, self.scenario.X_WR, X_WF, self.scenario.rng(camera + "/extrinsics"))
        return DepthImage(camera=camera, depth=sensor.depth(noisy), intrinsics=told, X_WC=X_told, mount=spec.mount), rgb

    def add_board(self, name: str, image: npt.ArrayLike, face_m: Size2, origin_m: Size2) -> None:
        """A calibration board (:func:`cell.sim.board.add_board`) as body ``name``, at W's origin until placed."""
        self._bodies[name] = add_board(self.client, image, face_m, origin_m)

    def place(self, name: str, X_W: FloatArray) -> None:
        """Put body ``name`` (a board) at X_W (4, 4) in W."""
        place_body(self.client, self.body_id(name), X_W)

    def capture_all(self) -> dict[str, DepthImage]:
        """One capture from every camera of the scenario, by camera name: fixed cameras at their scenario pose,
        an eye-in-hand camera where the arm holds it (its scenario pose when no robot is loaded)."""
        return {name: self.capture(name) for name in self.scenario.cameras}

    # -- robot -----------------------------------------------------------------------------------------------

    def load_robot(
        self,
        urdf_path: str | Path,
        X_WR: npt.ArrayLike,
        q: npt.ArrayLike,
        *,
        joint_names: Sequence[str] | None = None,
    ) -> SimRobot:
        """Add the arm: its URDF with a fixed base, root link (``base_link``) at X_WR (4, 4) in W, joints at q.

        q : (dof,) [rad] in the order of ``joint_names`` (default: the URDF's movable joints in tree order;
        pass ``RobotModel.joint_names`` to tie both models to one order). One robot per cell.
        """
        if self._robot is not None:
            raise ScenarioError(f"a robot ({self._robot.name}) is already loaded; one robot per SimCell")
        self._robot = SimRobot(self.client, urdf_path, X_WR, q, joint_names)
        return self._robot

    @property
    def robot(self) -> SimRobot:
        """The loaded arm; ScenarioError when there is none (SensorError once the cell is closed)."""
        self.client  # noqa: B018 - raises once closed, before a stale robot is used
        if self._robot is None:
            raise ScenarioError("this cell has no robot; call SimCell.load_robot(urdf_path, X_WR, q) first")
        return self._robot

    def set_q(self, q: npt.ArrayLike) -> None:
        """Put the arm at joint values q (dof,) [rad]."""
        self.robot.set_q(q)

    def link_pose(self, link: str) -> FloatArray:
        """X_W_link (4, 4): pose of the arm's link frame ``link`` (by URDF name) in W, from PyBullet."""
        return self.robot.link_pose(link)

    def execute(
        self,
        times: npt.ArrayLike,
        q: npt.ArrayLike,
        arc_on: npt.ArrayLike,
        *,
        tcp_link: str = "torch_tcp",
        record_dt: float = 0.01,
        record_poses: bool = True,
        marks: Sequence[tuple[float, str]] = (),
        bead: BeadStyle | None = DEFAULT_BEAD,
    ) -> Execution:
        """Drive the arm along a timed joint trajectory and record what the tool did.

        times : (n,) strictly increasing [s]; q : (n, dof) [rad]; arc_on : (n,) bool, holding from each sample
            to the next (the arc switches exactly at the sample where the flag changes).
        Playback is kinematic and deterministic (joint values interpolated linearly between samples), far
        faster than real time. Records every ``record_dt`` [s], at every arc switch and at the end: the pose of
        ``tcp_link`` in W from PyBullet's own kinematics, and the arc state. ``marks`` (time [s], text) are
        logged as ``"move"`` events (e.g. segment starts). Where the arc is on, a weld bead is drawn (visual
        only, see :class:`BeadStyle`; None draws none). PlanError when q leaves the URDF's joint limits.
        The arm stays at the last configuration.
        """
        robot = self.robot
        ex = robot.play(
            times, q, arc_on, tcp_link=tcp_link, record_dt=record_dt, record_poses=record_poses, marks=marks
        )
        if bead is not None:
            self.add_beads(bead_chords(ex.tcp_W, ex.arc_on, bead.step_m), bead)
        return ex

    def add_beads(self, chords: Iterable[tuple[FloatArray, FloatArray]], style: BeadStyle) -> None:
        """Draw a weld bead (visual capsules) along the chords (a, b) [m] in W; it moves with the part."""
        self._beads.extend(add_bead(self.client, a, b, style) for a, b in chords)

    def bead_segments(self) -> FloatArray:
        """(m, 2, 3) end points [m] in W of every bead capsule drawn so far, read back from PyBullet."""
        segs = [bead_segment(self.client, b) for b in self._beads]
        return np.array(segs, dtype=float).reshape(len(segs), 2, 3)

    def clear_beads(self) -> None:
        """Remove every weld bead drawn so far."""
        for b in self._beads:
            self.client.removeBody(b)
        self._beads.clear()

    def move_part(self, X_W_new_old: FloatArray) -> tuple[Part, ...]:
        """Move the part (every built part, one rigid body now, and every bead drawn on it) by the rigid motion
        X_W_new_old (4, 4) in W: the part turned over and set down again. Returns the parts as they now lie (the
        new ground truth); the table, the ground, the fixtures and the occluders stay where they are."""
        X = np.asarray(X_W_new_old, dtype=float)
        names = {p.name for p in self.parts_W}
        bodies = [b for n, b in self._bodies.items() if n in names or n in self._tacks] + list(self._beads)
        move_bodies(self.client, bodies, X)
        self.parts_W = tuple(p.moved(X) for p in self.parts_W)
        return self.parts_W

    def capture_from_link(self, camera: str, link: str = EYE_IN_HAND_LINK) -> DepthImage:
        """One depth image from ``camera`` rendered from the arm's link frame ``link`` (optical convention:
        z forward, x right, y down), with the camera's noise and calibration error as in :meth:`capture`."""
        return self.capture(camera, X_WC=self.robot.link_pose(link))

    # -- lifetime --------------------------------------------------------------------------------------------

    def close(self) -> None:
        """Disconnect the PyBullet client (idempotent)."""
        if self._client is not None:
            self._client.disconnect()
            self._client = None
        self._robot = None
        self._beads.clear()

    def __enter__(self) -> SimCell:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()
