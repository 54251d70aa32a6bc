"""A station served from a recorded capture folder (docs/capture.md): the recorded images bit for bit and the
recorded truth, without the simulator; anything that would move the arm or take a new image is refused."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from cell.errors import UsageError
from cell.geometry import FloatArray
from cell.station.ports import Arm
from cell.types import CameraIntrinsics, DepthImage, Part

if TYPE_CHECKING:
    from cell.recorded.layout import RecordedCapture
    from cell.types.execution import Execution


class RecordedStation:
    """The ports of a cell whose cameras were recorded: a :class:`~cell.recorded.layout.RecordedCapture`.

    Use :meth:`open` to read a folder (CaptureError for one that cannot be read), or pass a capture read already.
    """

    def __init__(self, capture: RecordedCapture) -> None:
        self.recorded = capture

    @classmethod
    def open(cls, folder: str | Path) -> RecordedStation:
        """The station of the capture folder ``folder``."""
        from cell.recorded.layout import read_capture

        return cls(read_capture(folder))

    @property
    def arm(self) -> Arm | None:
        return None

    @property
    def source(self) -> str:
        return "capture"

    def capture(self) -> dict[str, DepthImage]:
        """The recorded image of every camera, by name (the same values every call)."""
        return dict(self.recorded.images)

    def capture_eye_in_hand(self, camera: str) -> DepthImage:
        raise UsageError(
            f"a recorded capture cannot move the arm or take a new image (asked for camera {camera!r}); "
            f"valid: the images of {self.recorded.folder} (capture)"
        )

    def intrinsics(self, camera: str) -> CameraIntrinsics:
        if camera not in self.recorded.images:
            raise UsageError(f"camera {camera!r} is not in the capture; valid: {', '.join(self.recorded.images)}")
        return self.recorded.images[camera].intrinsics

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
        raise UsageError(
            f"a recorded capture cannot move the arm ({self.recorded.folder}); valid: detect on it, weld on a cell"
        )

    def turn_part(self, X_W_turn: FloatArray) -> None:
        raise UsageError(
            f"a recorded capture cannot turn the part over ({self.recorded.folder}); valid: --sides first on a"
            " recording, both sides on a cell"
        )

    def joint_state(self) -> FloatArray:
        """(0,): a recorded capture has no arm to ask."""
        return np.zeros(0)

    def truth(self) -> tuple[Part, ...] | None:
        """The recorded as-built parts in W (truth.json), None when the capture has none."""
        return self.recorded.truth_parts_W

    def close(self) -> None:
        return None

    def __enter__(self) -> RecordedStation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
