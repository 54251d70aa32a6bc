"""A coordinated weld as values, for the simulator, the report and the programs: the arm's joints and the
positioner's axes sampled together, where the arc burns, the pieces, and the weld's knots in the part's frame.
Frames: F the faceplate (the part's frame while it turns), R the robot base; [m], [rad], [s]."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray, readonly
from cell.types.plan import Remainder
from cell.types.procedure import WeldProcedure

PIECES = ("transfer", "approach", "weld", "depart", "retreat")  # in this order


@dataclass(frozen=True)
class CoordinatedWeld:
    """One curved seam welded with the positioner turning the part.

    times (n,) [s]; q (n, dof) the arm's joints and axes (n, 2) the positioner's (tilt, rotate) [rad] at each
    sample; arc_on (n,) bool. pieces: (kind, t0, t1) [s] in order (``PIECES``). Knots along the weld: knot_q
    (m, dof), knot_axes (m, 2) [rad], X_FT (m, 4, 4) the torch in F (the part's frame: a circle's knots lie on a
    circle there however the part turns), s (m,) the length welded on the part [m], slope_deg / rotation_deg (m,)
    each knot's ISO 6947 slope and rotation at its axes, in_position: every one within the tolerance of PA.
    speed: the travel speed along the seam, relative to the part [m/s]; closed / overlap [m]: a loop welded on
    past its start. plan_s: the planning's wall time [s].
    """

    seam_id: str
    times: FloatArray
    q: FloatArray
    axes: FloatArray
    arc_on: FloatArray
    pieces: tuple[tuple[str, float, float], ...]
    knot_q: FloatArray
    knot_axes: FloatArray
    X_FT: FloatArray
    s: FloatArray
    slope_deg: FloatArray
    rotation_deg: FloatArray
    in_position: bool
    speed: float
    closed: bool
    overlap: float
    plan_s: float = 0.0
    tcp_spread_mm: float = 0.0  # the torch's knots in R: the largest distance from their mean (how still it stands)
    weave_F: FloatArray | None = None  # (m, 3) [m] the weave in X_FT, in F, at each knot (None: no weave)
    procedure: WeldProcedure | None = None  # the weld procedure it was planned with (its weave, for the programs)
    # Welded in part (the process's ``curve_remainder: manual``): the stretches left for a manual weld, the share
    # of the curve welded and the weld's (from, to) [m] along the located curve (an open weld of a closed one).
    remainder: tuple[Remainder, ...] = ()
    share: float = 1.0
    span_m: tuple[float, float] | None = None
    # A closed curve welded in more than one arc (cell.coordinated.cover): the arcs after this one, in order, each
    # its own open coordinated weld from home and back (its span_m its stretch), restarting over the beads before.
    then: tuple[CoordinatedWeld, ...] = ()

    @property
    def arcs(self) -> tuple[CoordinatedWeld, ...]:
        """This weld and the arcs after it."""
        return (self, *self.then)

    def __post_init__(self) -> None:
        for name in ("times", "q", "axes", "arc_on", "knot_q", "knot_axes", "X_FT", "s", "slope_deg", "rotation_deg"):
            object.__setattr__(self, name, readonly(np.asarray(getattr(self, name))))
        if self.weave_F is not None:
            object.__setattr__(self, "weave_F", readonly(np.asarray(self.weave_F, dtype=float)))

    @property
    def line_FT(self) -> FloatArray:
        """(m, 4, 4) the torch along the pass's line in F: X_FT without its weave (a pass's offset stays), what a
        controller weaving by itself is given."""
        X = np.array(self.X_FT)
        if self.weave_F is not None:
            X[:, :3, 3] -= np.asarray(self.weave_F)
        return X

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    def piece_s(self, kind: str) -> float:
        """[s] the pieces of ``kind`` together."""
        return sum(t1 - t0 for k, t0, t1 in self.pieces if k == kind)

    @property
    def arc_s(self) -> float:
        """[s] with the arc on (the weld, its crater)."""
        return self.piece_s("weld")
