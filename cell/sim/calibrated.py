"""A calibrated cell's cameras off their calibration, for the studies (``cell sweep`` and ``cell bench`` with
``--calibration``): the calibration file's measured poses stay the cell's belief, and the extrinsic error a study
draws moves the TRUE camera away from that belief (docs/calibration.md section 6)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from cell.geometry import matrix_to_rpy
from cell.scenario import ExtrinsicErrorSpec, PoseSpec, Scenario
from cell.sim.noise import perturb_pose


def off_calibration(scenario: Scenario, errors: Mapping[str, ExtrinsicErrorSpec]) -> Scenario:
    """``scenario`` (its cameras' ``measured`` poses applied) with each named camera truly ``errors[name]`` off its
    measured pose (directions drawn from ``scenario.rng(name + "/extrinsics")``): a fixed camera is rendered from
    there (its eye_m, target_m and up re-posed) and told its measured pose; the arm's camera, whose true pose is
    the robot model's, is told its measured pose moved by the error instead (an error of the same size between
    belief and truth). A camera without a measured pose keeps the scenario's own model (``extrinsic_error``)."""
    cams = dict(scenario.cameras)
    for name, err in errors.items():
        cam = cams[name]
        if cam.measured is None:
            cams[name] = cam.model_copy(update={"extrinsic_error": err})
            continue
        rng = scenario.rng(name + "/extrinsics")
        if cam.mount == "eye_in_hand":
            X_FC = perturb_pose(cam.measured.X, err, rng)
            told = PoseSpec(xyz_m=_three(X_FC[:3, 3]), rpy_deg=_three(np.degrees(matrix_to_rpy(X_FC[:3, :3]))))
            cams[name] = cam.model_copy(update={"measured": told})
            continue
        X_WC = perturb_pose(scenario.X_WR @ cam.measured.X, err, rng)
        eye = X_WC[:3, 3]
        cams[name] = cam.model_copy(
            update={
                "eye_m": _three(eye),
                "target_m": _three(eye + X_WC[:3, 2]),
                "up": _three(-X_WC[:3, 1]),
            }
        )
    return scenario.model_copy(update={"cameras": cams})


def _three(v: np.ndarray) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])
