"""The scan configuration: the arm's joints that put the eye-in-hand camera on a viewpoint."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.motion.ik import IKOptions, solve_ik
from cell.motion.robot import RobotModel


def scan_configuration(
    robot: RobotModel,
    X_RC_desired: npt.ArrayLike,
    q_seed: npt.ArrayLike,
    *,
    rng: np.random.Generator | None = None,
    frame: str = "camera_optical",
    ik: IKOptions | None = None,
) -> FloatArray:
    """Joint values (dof,) [rad] that put the eye-in-hand camera's optical frame at X_RC_desired (4, 4) in R.

    Only the camera position and its optical axis (z) are matched: the rotation about the optical axis is left
    free (the image turns in its plane; the cloud is the same). Raises IKError when the view cannot be reached.
    """
    return solve_ik(robot, X_RC_desired, q_seed, frame=frame, rng=rng, free_axis=True, options=ik)
