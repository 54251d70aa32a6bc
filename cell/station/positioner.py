"""The simulated positioner's axes (docs/positioner.md, "Sensing and the simulator"): where they stand, and a move
that carries the clamped part (its beads and tacks), the clamping table, the fixtures and the faceplate by the
kinematics, with the positioner's repeatability drawn as a small rigid error (``Scenario.rng("positioner")``)."""

from __future__ import annotations

import math

import numpy as np

from cell.geometry import FloatArray, axis_angle_to_matrix, invert, make_pose
from cell.positioner.bodies import CRADLE, FACEPLATE, positioner_parts
from cell.scenario import Scenario
from cell.types.positioner import TiltRotatePositioner


class SimPositioner:
    """The positioner of a simulated cell: its bodies added to ``sim`` (a :class:`cell.sim.SimCell`), its axes at
    home."""

    def __init__(self, scenario: Scenario, sim: object) -> None:
        from cell.sim.positioner import add_bodies

        spec = scenario.robot.positioner
        assert spec is not None
        self.scenario = scenario
        self.sim = sim
        self.pos: TiltRotatePositioner = spec.positioner(scenario.X_WR)
        self.axes: tuple[float, float] = self.pos.home
        parts_R = positioner_parts(self.pos, *self.axes)
        self.bodies = add_bodies(sim.client, [p.transformed(scenario.X_WR) for p in parts_R])  # type: ignore[attr-defined]
        self._rng = scenario.rng("positioner")
        self.X_W_true = np.eye(4)  # where the clamped things really are, as a motion in W from home

    def error_W(self) -> FloatArray:
        """(4, 4) the repeatability's rigid error in W about the faceplate's centre: a turn of repeatability /
        faceplate radius (one sigma) about a drawn axis and a shift of repeatability / sqrt(3) per axis."""
        rep = self.pos.repeatability_m
        axis = self._rng.normal(size=3)
        angle = float(self._rng.normal()) * rep / self.pos.faceplate_radius_m
        R = axis_angle_to_matrix(axis / np.linalg.norm(axis), angle)
        c = (self.scenario.X_WR @ self.pos.X_R_F(*self.axes))[:3, 3]
        X = make_pose(R, c - R @ c)
        X[:3, 3] += self._rng.normal(size=3) * rep / math.sqrt(3.0)
        return X

    def move_to(self, tilt: float, rotate: float) -> tuple[FloatArray, FloatArray]:
        """Turn the axes to (tilt, rotate) [rad]; returns (X_W nominal, X_W true): the motions in W the kinematics
        give and the one the clamped things really made (the nominal with the repeatability's error)."""
        from cell.sim.bodies import move_bodies

        X_WR = self.scenario.X_WR
        t_was = self.axes[0]
        X_nom = X_WR @ self.pos.move(tilt, rotate, start=self.axes) @ invert(X_WR)
        self.axes = (tilt, rotate)
        # Each pose reached within the repeatability of its nominal place (the errors do not add up move by move).
        X_home = X_WR @ self.pos.move(tilt, rotate) @ invert(X_WR)
        X_W_true = self.error_W() @ X_home if self.pos.repeatability_m > 0.0 else X_home
        X_true = X_W_true @ invert(self.X_W_true)
        self.X_W_true = X_W_true
        client = self.sim.client  # type: ignore[attr-defined]
        bodies = self.sim.bodies  # type: ignore[attr-defined]
        carried = [b for n, b in bodies.items() if n == "table" or n.startswith("fixture:")]
        move_bodies(client, carried, X_true)
        move_bodies(client, [self.bodies[FACEPLATE]], X_nom)
        X_tilt = X_WR @ self.pos.X_R_tilt(tilt) @ invert(self.pos.X_R_tilt(t_was)) @ invert(X_WR)
        move_bodies(client, [self.bodies[CRADLE]], X_tilt)
        return X_nom, X_true

    def follow(self, tilt: float, rotate: float) -> FloatArray:
        """Turn the axes to (tilt, rotate) [rad] as one step of a continuous move (the arm welding meanwhile): the
        clamped things carried by the nominal kinematics with the error they already have (nothing drawn: a part
        clamped on the faceplate turns with it). Returns the true motion X_W (4, 4) of this step."""
        from cell.sim.bodies import move_bodies

        X_WR = self.scenario.X_WR
        nominal = lambda a: X_WR @ self.pos.move(*a) @ invert(X_WR)  # noqa: E731  (from home, in W)
        X_nom = nominal((tilt, rotate)) @ invert(nominal(self.axes))
        X_W_true = X_nom @ self.X_W_true  # the error rides on the faceplate
        X_true = X_W_true @ invert(self.X_W_true)
        t_was = self.axes[0]
        self.axes, self.X_W_true = (tilt, rotate), X_W_true
        client, bodies = self.sim.client, self.sim.bodies  # type: ignore[attr-defined]
        move_bodies(client, [b for n, b in bodies.items() if n == "table" or n.startswith("fixture:")], X_true)
        move_bodies(client, [self.bodies[FACEPLATE]], X_nom)
        if tilt != t_was:
            X_tilt = X_WR @ self.pos.X_R_tilt(tilt) @ invert(self.pos.X_R_tilt(t_was)) @ invert(X_WR)
            move_bodies(client, [self.bodies[CRADLE]], X_tilt)
        return X_true
