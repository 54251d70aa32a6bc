"""The simulated station: the station's ports (:mod:`cell.station.ports`) served by PyBullet.

The only station module that touches the simulator. It builds the as-built part from the welding map the pipeline
read and the scenario's deviations (ground truth: :meth:`SimStation.truth`), the cameras with their noise and
faults, and the arm it is handed, at its scan configuration.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from cell.errors import ScenarioError
from cell.geometry import FloatArray
from cell.scenario import Scenario
from cell.scenario.run_specs import CameraFaultSpec
from cell.station.arm import robot_urdf
from cell.station.ports import Arm
from cell.station.positioner import SimPositioner
from cell.types import CameraIntrinsics, DepthImage, Part, WeldMap

if TYPE_CHECKING:
    from cell.sim.cell import SimCell
    from cell.types.execution import Execution


class SimStation:
    """A running simulated cell built from a scenario and its welding map (as drawn, frame M).

    The as-built parts are the map's parts with the scenario's deviations
    (:func:`cell.sim.asbuilt.parts.as_built_parts`); ``arm`` the robot, its home and scan configurations (None: a
    cell without one). Use as a context manager; the simulator's client is released on exit.
    """

    def __init__(self, scenario: Scenario, weldmap: WeldMap, *, arm: Arm | None = None, gui: bool = False) -> None:
        from cell.sim import SimCell
        from cell.sim.asbuilt.parts import as_built_fixtures, as_built_parts

        self.scenario = scenario
        self.parts_W: tuple[Part, ...] = as_built_parts(weldmap, scenario)
        # The clamps and stops the map draws are there for the cameras too (never parts, never aligned).
        self.sim: SimCell = SimCell(scenario, self.parts_W, gui=gui, fixtures_W=as_built_fixtures(weldmap, scenario))
        self._arm = arm
        self.X_W_turned: FloatArray | None = None  # the true motion of the last turn (ground truth)
        self.positioner: SimPositioner | None = None  # robot.positioner's axes and bodies (docs/positioner.md)
        try:
            if scenario.robot.positioner is not None:
                self.positioner = SimPositioner(scenario, self.sim)
            if self._arm is not None:
                robot = self.sim.load_robot(
                    robot_urdf(scenario), scenario.X_WR, self._arm.q_scan, joint_names=self._arm.model.joint_names
                )
                if scenario.robot.track is not None:
                    robot.on_track(scenario.robot.track.axis_W)
        except BaseException:
            self.sim.close()
            raise

    @property
    def arm(self) -> Arm | None:
        return self._arm

    @property
    def source(self) -> str:
        return "simulation"

    def capture(self) -> dict[str, DepthImage]:
        """One image from every camera; the arm (if any) holds the eye-in-hand camera at its scan pose."""
        if self._arm is not None:
            self.sim.set_q(self._arm.q_scan)
        return self.sim.capture_all()

    def capture_eye_in_hand(self, camera: str) -> DepthImage:
        return self.sim.capture_from_link(camera)

    def intrinsics(self, camera: str) -> CameraIntrinsics:
        return self.sim.intrinsics(camera)

    def execute(
        self,
        times: npt.ArrayLike,
        q: npt.ArrayLike,
        arc_on: npt.ArrayLike,
        *,
        marks: Sequence[tuple[float, str]] = (),
        record_dt: float = 0.01,
        bead: bool = True,
        e1: npt.ArrayLike | None = None,
    ) -> Execution:
        if e1 is not None:
            self.sim.robot.stage_e1(e1)  # the track moves the base as the trajectory plays
        if not bead:
            return self.sim.execute(times, q, arc_on, marks=marks, record_dt=record_dt, bead=None)
        return self.sim.execute(times, q, arc_on, marks=marks, record_dt=record_dt, bead=self.scenario.simulation.bead)

    def turn_part(self, X_W_turn: FloatArray) -> None:
        """The operator turns the part over: the as-built part (its beads on it) moves by the nominal turn
        X_W_turn (4, 4) in W, settles on its own hull and is set down with ``simulation.flip_placement``'s error
        (drawn from ``Scenario.rng("flip")``); :meth:`truth` moves with it."""
        from cell.sim.turnover import turned_pose

        sim = self.scenario.simulation
        X = turned_pose(
            self.parts_W,
            self.sim.bead_segments(),
            sim.bead.radius_m,
            X_W_turn,
            self.scenario.table.top_z,
            sim.flip_placement,
            self.scenario.rng("flip"),
        )
        self.parts_W = self.sim.move_part(X)
        self.X_W_turned = X
        lost = sim.flip_placement.cameras_lost
        if lost:  # a camera lost at the turn: from now on it delivers no valid pixel
            unknown = sorted(set(lost) - set(self.scenario.cameras))
            if unknown:
                raise ScenarioError(
                    f"simulation.flip_placement.cameras_lost names unknown camera(s) {', '.join(unknown)}; "
                    f"cameras: {', '.join(self.scenario.cameras)}"
                )
            dead = dict(sim.faults.cameras) | {name: CameraFaultSpec(mode="dead") for name in lost}
            self.sim.scenario = self.scenario.with_simulation(faults=sim.faults.model_copy(update={"cameras": dead}))

    def move_positioner(self, tilt: float, rotate: float) -> FloatArray:
        """Turn the positioner's axes to (tilt, rotate) [rad]: the part (its beads), the clamping table and the
        fixtures move with the faceplate; :meth:`truth` follows. Returns the nominal motion X_W (4, 4)."""
        if self.positioner is None:
            raise ScenarioError(f"scenario {self.scenario.name!r} has no robot.positioner to move")
        X_nom, X_true = self.positioner.move_to(tilt, rotate)
        self.parts_W = self.sim.move_part(X_true)
        return X_nom

    def follow_positioner(self, tilt: float, rotate: float) -> FloatArray:
        """One step of a continuous positioner move (coordinated with the arm): the part, its beads, the clamping
        table and the fixtures carried with the faceplate, with the clamping error they have. Returns the true
        motion X_W (4, 4) of the step."""
        if self.positioner is None:
            raise ScenarioError(f"scenario {self.scenario.name!r} has no robot.positioner to move")
        X_true = self.positioner.follow(tilt, rotate)
        self.parts_W = self.sim.move_part(X_true)
        return X_true

    def joint_state(self) -> FloatArray:
        return np.asarray(self.sim.robot.q, dtype=float)

    def truth(self) -> tuple[Part, ...]:
        return self.parts_W

    def close(self) -> None:
        self.sim.close()

    def __enter__(self) -> SimStation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
