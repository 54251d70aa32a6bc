"""One camera's calibration as measured: the solution and its covariance, the residuals on held-out images, the
pose set's rotation spread, the intrinsics and depth scale checked, OpenCV's hand-eye methods alone on the same
images, and (in a simulation) the true pose to judge them all by."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from cell.calibrate.intrinsics import IntrinsicsCheck
from cell.calibrate.solve import Solution, pose_error
from cell.calibrate.views import Mount
from cell.geometry import FloatArray


@dataclass(frozen=True)
class CameraCalibration:
    """``camera``'s pose measured: X_AC in A (the robot base R for a fixed camera, the flange F for the arm's).

    poses / held_out_images : images fitted / held out; held_out_px, held_out_3d_m : their reprojection RMS [px]
    and the corners' 3D RMS against each image's PnP [m]; spread_deg : the poses' relative rotations on their two
    main axes [deg]; opencv : OpenCV's hand-eye method name -> its X_AC alone; X_AC_true : the simulation's truth
    (None on a real cell); dropped : the planned poses that gave no image, by why (a simulated cell's: below the
    table's clearance, out of reach, colliding, the board not found).
    """

    camera: str
    mount: Mount
    solution: Solution
    poses: int
    held_out_images: int
    held_out_px: float
    held_out_3d_m: float
    spread_deg: tuple[float, float]
    intrinsics: IntrinsicsCheck
    opencv: Mapping[str, FloatArray] = field(default_factory=dict)
    X_AC_true: FloatArray | None = None
    dropped: Mapping[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "opencv", MappingProxyType(dict(self.opencv)))
        object.__setattr__(self, "dropped", MappingProxyType(dict(self.dropped)))

    @property
    def X_AC(self) -> FloatArray:
        return self.solution.X_AC

    def truth_error(self, X_AC: FloatArray | None = None) -> tuple[float, float] | None:
        """(translation [m], rotation [rad]) of X_AC (default: the refined one) against the truth; None without."""
        if self.X_AC_true is None:
            return None
        return pose_error(self.X_AC if X_AC is None else X_AC, self.X_AC_true)

    def within_two_sigma(self) -> bool | None:
        """Whether the truth lies within the stated 2-sigma bounds, in translation and in rotation."""
        err = self.truth_error()
        if err is None:
            return None
        s = self.solution
        return bool(err[0] <= 2.0 * s.sigma_translation_m and err[1] <= 2.0 * s.sigma_rotation_rad)

    @property
    def frame(self) -> str:
        """The frame the measured pose is given in: ``robot_base`` (X_RC) or ``flange`` (X_FC)."""
        return "robot_base" if self.mount == Mount.EYE_TO_HAND else "flange"
