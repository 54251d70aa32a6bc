"""The simulated cell: one object owns its PyBullet client, builds the as-built cell, renders depth cameras.

The world frame W has z up; the ground is the plane z = 0. Bodies are static boxes found by name
(``"ground"``, ``"table"`` and each part's name), never by index. Cameras render with PyBullet's TinyRenderer
(headless, CPU), also when a GUI is shown, because its sampling is the one :mod:`cell.sim.camera` models
exactly.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator, Mapping, Sequence
from types import MappingProxyType, TracebackType

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient
from scipy.spatial.transform import Rotation

from cell.errors import ScenarioError, SensorError
from cell.geometry import FloatArray, make_pose
from cell.scenario import CameraSpec, Scenario
from cell.sim.camera import gl_projection_matrix, gl_view_matrix, intrinsics_for, linearise_depth
from cell.sim.noise import apply_noise, perturb_pose
from cell.types import Box, CameraIntrinsics, DepthImage, Part

GROUND = "ground"
TABLE = "table"
_GROUND_SIZE = (20.0, 20.0, 0.02)  # [m] a thin box whose top face is the plane z = 0
_RGBA = {GROUND: (0.35, 0.35, 0.35, 1.0), TABLE: (0.55, 0.45, 0.35, 1.0)}
_PART_RGBA = (0.7, 0.72, 0.75, 1.0)


@contextlib.contextmanager
def _stdout_to_stderr() -> Iterator[None]:
    """Point file descriptor 1 at stderr for the duration (C libraries write to the descriptor, not sys.stdout)."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no real stdout (embedded, closed): nothing to protect
        yield
        return
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


class SimCell:
    """The as-built cell in PyBullet.

    scenario : the cell (table, cameras, noise, seed).
    parts_W : the as-built parts, boxes in W (``cell.asbuilt.as_built_parts``); names must be unique.
    gui : show PyBullet's GUI (needs a display); headless ``DIRECT`` by default.

    Use as a context manager (``with SimCell(scenario, parts) as sim:``) or call :meth:`close`.
    """

    def __init__(self, scenario: Scenario, parts_W: Sequence[Part], *, gui: bool = False) -> None:
        names = [p.name for p in parts_W]
        reserved = {GROUND, TABLE}
        clash = sorted({n for n in names if names.count(n) > 1 or n in reserved})
        if clash:
            raise ScenarioError(
                f"part names must be unique and not {GROUND!r}/{TABLE!r}; offending: {', '.join(clash)}"
            )
        self.scenario = scenario
        self.parts_W: tuple[Part, ...] = tuple(parts_W)
        with _stdout_to_stderr():  # pybullet's C code prints "argv[0]=" on stdout, which carries our results
            self._client: BulletClient | None = BulletClient(
                connection_mode=pybullet.GUI if gui else pybullet.DIRECT
            )
        self._bodies: dict[str, int] = {}
        self._noise_rngs: dict[str, np.random.Generator] = {}
        ground = Box(make_pose(p=(0.0, 0.0, -_GROUND_SIZE[2] / 2.0)), np.array(_GROUND_SIZE))
        self._add_box(GROUND, ground, _RGBA[GROUND])
        table = scenario.table
        self._add_box(TABLE, Box(make_pose(p=table.center_m), np.array(table.size_m)), _RGBA[TABLE])
        for part in self.parts_W:
            self._add_box(part.name, part.box, _PART_RGBA)

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
        """The PyBullet body id of ``name`` (``"ground"``, ``"table"`` or a part name)."""
        if name not in self._bodies:
            raise KeyError(f"no body {name!r}; bodies: {', '.join(self._bodies)}")
        return self._bodies[name]

    def _add_box(self, name: str, box_W: Box, rgba: tuple[float, float, float, float]) -> int:
        c = self.client
        half = [float(h) for h in box_W.size / 2.0]
        collision = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
        visual = c.createVisualShape(pybullet.GEOM_BOX, halfExtents=half, rgbaColor=list(rgba))
        # scipy and PyBullet both order quaternions (x, y, z, w): no conversion needed.
        quat = Rotation.from_matrix(box_W.X_AB[:3, :3]).as_quat()
        body = c.createMultiBody(
            baseMass=0.0,
            baseCollisionShapeIndex=collision,
            baseVisualShapeIndex=visual,
            basePosition=[float(v) for v in box_W.center],
            baseOrientation=[float(v) for v in quat],
        )
        self._bodies[name] = body
        return int(body)

    # -- cameras ---------------------------------------------------------------------------------------------

    def camera_spec(self, camera: str) -> CameraSpec:
        """The scenario's spec of ``camera``; :class:`SensorError` naming the cameras if there is none."""
        spec = self.scenario.cameras.get(camera)
        if spec is None:
            raise SensorError(
                f"no camera {camera!r} in scenario {self.scenario.name!r}; "
                f"cameras: {', '.join(self.scenario.cameras)}"
            )
        return spec

    def intrinsics(self, camera: str) -> CameraIntrinsics:
        """Exact pinhole intrinsics [px] of ``camera``'s rendered images."""
        spec = self.camera_spec(camera)
        return intrinsics_for(spec.resolution[0], spec.resolution[1], np.radians(spec.hfov_deg))

    def render_depth(
        self, X_WC: FloatArray, intrinsics: CameraIntrinsics, near_m: float, far_m: float
    ) -> FloatArray:
        """Noise-free depth (H, W) [m] along the optical axis seen from the optical frame at X_WC (4, 4) in W;
        0 where nothing lies between the near and far planes."""
        _, _, _, buffer, _ = self.client.getCameraImage(
            intrinsics.width,
            intrinsics.height,
            viewMatrix=gl_view_matrix(X_WC),
            projectionMatrix=gl_projection_matrix(intrinsics, near_m, far_m),
            renderer=pybullet.ER_TINY_RENDERER,
            flags=pybullet.ER_NO_SEGMENTATION_MASK,
        )
        d = np.asarray(buffer, dtype=float).reshape(intrinsics.height, intrinsics.width)
        return linearise_depth(d, near_m, far_m)

    def capture(self, camera: str, X_WC: FloatArray | None = None) -> DepthImage:
        """One depth image from ``camera``.

        X_WC : true pose (4, 4) of the optical frame in W to render from (an eye-in-hand camera's pose from
            the arm); the scenario's fixed pose when None.
        The image carries the *believed* pose (true pose with the camera's calibration error) and exact
        intrinsics. With ``scenario.noise == "realistic"`` the camera's sensor model is applied; its random
        stream starts from ``scenario.rng(camera)`` and continues across captures (a second capture has new
        noise).
        """
        spec = self.camera_spec(camera)
        X_true = spec.X_WC if X_WC is None else np.asarray(X_WC, dtype=float)
        if X_true.shape != (4, 4):
            raise ValueError(f"X_WC must be (4, 4), got {X_true.shape}")
        intr = self.intrinsics(camera)
        depth = self.render_depth(X_true, intr, spec.near_m, spec.far_m)
        if self.scenario.noise == "realistic":
            rng = self._noise_rngs.setdefault(camera, self.scenario.rng(camera))
            noisy = apply_noise(depth, intr, spec.noise, rng)
        else:
            noisy = depth.astype(np.float32)
        X_believed = perturb_pose(X_true, spec.extrinsic_error, self.scenario.rng(camera + "/extrinsics"))
        return DepthImage(camera=camera, depth=noisy, intrinsics=intr, X_WC=X_believed, mount=spec.mount)

    def capture_all(self) -> dict[str, DepthImage]:
        """One capture from every camera of the scenario at its scenario pose, by camera name."""
        return {name: self.capture(name) for name in self.scenario.cameras}

    # -- lifetime --------------------------------------------------------------------------------------------

    def close(self) -> None:
        """Disconnect the PyBullet client (idempotent)."""
        if self._client is not None:
            self._client.disconnect()
            self._client = None

    def __enter__(self) -> SimCell:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()
