"""The calibration board as the cell knows it: a ChArUco board (:class:`~cell.scenario.calibration_specs.BoardSpec`),
its corners in its frame B, its printed picture and the corners found in a colour image."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.calibrate import _opencv
from cell.geometry import FloatArray, readonly
from cell.scenario.calibration_specs import BoardSpec

_PX_PER_M = 4000.0  # the printed picture's resolution (4 px per mm: far finer than any camera sees it)


@dataclass(frozen=True)
class Corners:
    """The board's corners found in one image: ids (k,) into :attr:`Board.p_B` and pixels (k, 2)."""

    ids: npt.NDArray[np.int64]
    px: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "ids", readonly(self.ids, np.int64))
        object.__setattr__(self, "px", readonly(np.asarray(self.px, dtype=float).reshape(-1, 2)))

    def __len__(self) -> int:
        return len(self.ids)


@dataclass(frozen=True)
class Board:
    """A ChArUco board at a scale: ``scale`` 1 is as stated; a simulation prints it at another to play a board
    whose stated size is wrong. p_B (n, 3) [m]: its inner corners in B."""

    spec: BoardSpec
    scale: float = 1.0
    _cv: Any = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        s = self.spec
        cv = _opencv.charuco_board(
            s.dictionary, s.squares, s.square_mm * 1e-3 * self.scale, s.marker_mm * 1e-3 * self.scale
        )
        object.__setattr__(self, "_cv", cv)

    @property
    def p_B(self) -> FloatArray:
        return readonly(_opencv.corners_B(self._cv))

    @property
    def pattern_m(self) -> tuple[float, float]:
        """The pattern's width and height [m] (squares times the square)."""
        sq = self.spec.square_mm * 1e-3 * self.scale
        return self.spec.squares[0] * sq, self.spec.squares[1] * sq

    @property
    def margin_m(self) -> float:
        return self.spec.margin_mm * 1e-3 * self.scale

    @property
    def centre_B(self) -> FloatArray:
        w, h = self.pattern_m
        return readonly([w / 2.0, h / 2.0, 0.0])

    def picture(self) -> tuple[npt.NDArray[np.uint8], tuple[float, float], tuple[float, float]]:
        """The printed face: its picture (h, w) uint8, its size [m] and where its top-left corner lies in B [m]."""
        w, h = self.pattern_m
        m = self.margin_m
        px_per_m = _PX_PER_M / self.scale
        margin_px = round(m * px_per_m)
        size_px = (round(w * px_per_m) + 2 * margin_px, round(h * px_per_m) + 2 * margin_px)
        picture = _opencv.board_picture(self._cv, size_px, margin_px)
        return picture, (w + 2 * m, h + 2 * m), (-m, -m)

    def detect(self, rgb: npt.ArrayLike) -> Corners:
        """The corners found in a colour image (h, w, 3) uint8 (none: an empty :class:`Corners`)."""
        ids, px = _opencv.detect(self._cv, rgb)
        return Corners(ids, px)
