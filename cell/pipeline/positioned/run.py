"""The record of a part welded on a positioner: the detection at home, the poses chosen, each group's plan and
execution, each seam's weld and ISO 6947 position, and what no pose could hold. Values only."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

from cell.coordinated.record import CoordinatedWeld
from cell.errors import CellError
from cell.pipeline.records import Detection, WeldRun
from cell.positioner.poses import PositionerPose
from cell.types import SeamStatus, WeldReason
from cell.types.execution import Execution
from cell.types.plan import WeldPlan
from cell.types.run import SeamWeld
from cell.types.trajectory import Trajectory


@dataclass(frozen=True)
class GroupRun:
    """One positioner pose: the pose, the positioner's move to it [s], the plan (None: refused, ``error`` says
    why), the move before it, its execution, each seam's weld, and the planning's wall time [s]."""

    pose: PositionerPose
    move_s: float
    plan: WeldPlan | None
    pre: Trajectory | None
    execution: Execution | None
    seams: tuple[SeamWeld, ...]
    plan_wall_s: float
    error: CellError | None = None
    rescan_s: float = 0.0  # the close-ups at this pose (the seams hidden at home) [s]
    via: tuple[tuple[float, float], ...] = ()  # the positioner's (tilt, rotate) [rad] on its way here (around the arm)

    @property
    def robot_s(self) -> float:
        """The arm's time at this pose [s]: the close-ups, the move before the plan and the plan, as executed."""
        return self.rescan_s + (self.execution.duration if self.execution is not None else 0.0)


@dataclass(frozen=True)
class PositionerRun:
    """A whole part on a positioner. unheld : seam id -> why no pose holds it (beyond the tilt, out of reach, not
    located at home), its code in ``unheld_codes``. rescan_s : the close-ups' robot time at home [s]."""

    detection: Detection
    groups: tuple[GroupRun, ...] = ()
    unheld: Mapping[str, str] = field(default_factory=dict)
    rescan_s: float = 0.0
    error: CellError | None = None
    timings: Mapping[str, float] = field(default_factory=dict)
    unheld_codes: Mapping[str, WeldReason] = field(default_factory=dict)  # seam id -> why, as a code
    coordinated: tuple[CoordinatedWeld, ...] = ()  # curved seams welded with the rotate axis turning

    def welds(self) -> dict[str, SeamWeld]:
        return {w.id: w for g in self.groups for w in g.seams}

    @property
    def welded(self) -> int:
        return sum(w.welded for w in self.welds().values())

    @property
    def positioner_s(self) -> float:
        """The positioner's moves [s] (the arm waits at home meanwhile)."""
        return sum(g.move_s for g in self.groups)

    @property
    def cycle_time_s(self) -> float:
        """The job's time [s]: the close-ups at home, every pose's robot time and the positioner's moves."""
        return self.rescan_s + sum(g.robot_s for g in self.groups) + self.positioner_s

    def seam_ids(self) -> tuple[str, ...]:
        curves = tuple(c.id for c in self.detection.curve_estimates)
        return tuple(e.id for e in self.detection.estimates) + curves

    def located(self) -> int:
        return sum(e.status is SeamStatus.FOUND for e in self.detection.estimates)

    def as_weld_run(self) -> WeldRun:
        """The job as one :class:`~cell.pipeline.records.WeldRun` for its page (:func:`cell.preview.write_page`):
        the detection at home with each curved seam's weld, every straight seam's weld or why no pose holds it; no
        plan and no execution (the poses' plans are many, and the part moves between them)."""
        welds = self.welds()
        for sid, why in self.unheld.items():
            code = self.unheld_codes.get(sid, WeldReason.NOT_PLANNED)
            welds.setdefault(sid, SeamWeld(sid, False, False, why, code=code))
        curves = {c.id for c in self.detection.curve_estimates}
        det = replace(self.detection, curve_welds={k: w for k, w in welds.items() if k in curves})
        straight = tuple(w for k, w in welds.items() if k not in curves)
        return WeldRun(detection=det, seams=straight, error=self.error, timings=dict(self.timings))
