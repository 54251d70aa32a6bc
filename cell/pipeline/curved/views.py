"""Where a curve's close-up is taken from: a view of a stretch planned from where the arm is, and on a linear track,
when no view reaches the stretch from the carriage's E1, the carriage moved abreast of it (the arm at its scan
configuration while the carriage moves) and back to E1 = 0 before the re-scan ends, where the plan after it starts
(docs/curves.md section 6). Frames: R is the base at E1 = 0, every view's pose is in R; metres."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from cell.errors import CellError, PlanError
from cell.geometry import FloatArray
from cell.station import Arm
from cell.types.rescan import Viewpoint
from cell.types.track import LinearTrack

if TYPE_CHECKING:
    from cell.config.rescan import RescanOptions
    from cell.motion.collision import CollisionChecker
    from cell.pipeline.rescan import _Run
    from cell.rescan.view_grid import ViewTarget
    from cell.types import CameraIntrinsics, Part

E1_STEP = 0.01  # [m] the carriage is moved to E1 values on this grid (the track planner's)


def planned_view(
    arm: Arm, checker: CollisionChecker, target: ViewTarget, q: FloatArray, K: CameraIntrinsics,
    parts: Sequence[Part], table_z: float, rng: np.random.Generator, o: RescanOptions, carriage: Carriage | None,
) -> tuple[Viewpoint | None, str]:  # fmt: skip
    """:func:`view_of` from ``q`` with the base where ``carriage`` stands (None: a fixed arm); on a track, when no
    view works from there, :meth:`Carriage.plan_abreast`'s (its ``e1_m`` says where; moving the carriage there is
    the caller's). The checker's base is left where it was."""
    if carriage is None:
        return view_of(arm, checker, target, q, K, parts, table_z, rng, o)
    vp, why = carriage.view_at(carriage.e1, arm, checker, target, q, K, parts, table_z, rng, o)
    if vp is not None:
        return vp, ""
    vp, elsewhere = carriage.plan_abreast(arm, checker, target, K, parts, table_z, rng, o)
    return vp, "" if vp is not None else "; ".join(w for w in (why, elsewhere) if w)


def view_of(
    arm: Arm, checker: CollisionChecker, target: ViewTarget, q: FloatArray, K: CameraIntrinsics,
    parts: Sequence[Part], table_z: float, rng: np.random.Generator, o: RescanOptions,
) -> tuple[Viewpoint | None, str]:  # fmt: skip
    """A close-up's view of the stretch ``target`` from ``q``: at the usual stand-offs, then nearer
    (:func:`cell.rescan.curve_views.near_view`); or None and why no view works."""
    from cell.rescan.curve_views import near_view
    from cell.rescan.viewpoint import plan_view

    why = ""
    for view in (replace(o.view, fallback_tilts_deg=()), near_view(o.view)):
        try:
            vp = plan_view(arm.model, checker, target, q, K, parts, table_z, rng=rng, q_via=arm.q_scan, options=view)
            return vp, ""
        except CellError as exc:
            why = f"no view: {exc.message}"
    return None, why


@dataclass
class Carriage:
    """The linear track's carriage during a curve re-scan: the track and where the base stands now (E1 [m])."""

    track: LinearTrack
    e1: float = 0.0

    def arm(self, arm: Arm) -> Arm:
        """``arm`` with its base where the carriage stands (every pose it gives still in R)."""
        return replace(arm, model=arm.model.shifted(self.track.offset_R(self.e1))) if self.e1 else arm

    def abreast(self, p_R: FloatArray) -> float:
        """The E1 [m] that puts the base's origin nearest ``p_R`` (3,) in R, on the :data:`E1_STEP` grid within
        the track's limits."""
        e = round(float(np.dot(p_R, self.track.axis_R)) / E1_STEP) * E1_STEP
        return float(np.clip(e, self.track.e1_min, self.track.e1_max))

    def plan_abreast(
        self, arm: Arm, checker: CollisionChecker, target: ViewTarget, K: CameraIntrinsics, parts: Sequence[Part],
        table_z: float, rng: np.random.Generator, o: RescanOptions,
    ) -> tuple[Viewpoint | None, str]:  # fmt: skip
        """The view of ``target`` with the carriage :meth:`abreast` of it, from the scan configuration there, planned
        and not taken (its ``e1_m`` set; the checker's base left where it was); or None and why, and None and ""
        when the carriage stands there already."""
        e = self.abreast(target.mid)
        if abs(e - self.e1) < 1e-9:
            return None, ""
        vp, why = self.view_at(e, arm, checker, target, arm.q_scan, K, parts, table_z, rng, o)
        return (vp, "") if vp is not None else (None, f"from E1 = {e * 1000:.0f} mm on the track: {why}")

    def view_at(
        self, e: float, arm: Arm, checker: CollisionChecker, target: ViewTarget, q: FloatArray, K: CameraIntrinsics,
        parts: Sequence[Part], table_z: float, rng: np.random.Generator, o: RescanOptions,
    ) -> tuple[Viewpoint | None, str]:  # fmt: skip
        """:func:`view_of` from ``q`` with the base at E1 = ``e`` [m] (the view's ``e1_m`` set; the checker's base
        left where it was)."""
        keep = checker.base_offset_R
        checker.set_base(self.track.offset_R(e))
        try:
            vp, why = view_of(Carriage(self.track, e).arm(arm), checker, target, q, K, parts, table_z, rng, o)
        finally:
            checker.set_base(keep)
        return (replace(vp, e1_m=e), "") if vp is not None else (None, why)

    def home(self, run: _Run) -> None:
        """The carriage back to E1 = 0 (the arm at its scan configuration as it moves), played on ``run``. Raises
        PlanError when it cannot go (the way out reversed: not expected): the plan after the re-scan starts at
        E1 = 0, and nothing is planned from a carriage elsewhere."""
        why = self.to(run, 0.0) if self.e1 else ""
        if why:
            raise PlanError(f"the carriage cannot go back to E1 = 0 after the curves' close-ups: {why}")

    def to(self, run: _Run, e: float) -> str:
        """The arm back to its scan configuration where it stands (the way it came), then the carriage to E1 = ``e``
        [m], both checked and played on ``run``; "" when done, else why not (nothing played)."""
        from cell.planning.track import track_move
        from cell.rescan.viewpoint import way_back

        q_scan = np.asarray(run.arm.q_scan, dtype=float)
        dt = run.options.view.dt
        back = None
        if not np.allclose(run.q, q_scan):
            back = way_back(run.arm.model, run.checker, run.stops, q_scan, dt)  # the checker's base is the carriage's
            if back is None:
                return "no way back to the scan configuration to move the carriage"
        move = track_move(self.track, q_scan, self.e1, e, dt)
        hit = run.checker.check_trajectory(move, self.track)
        if hit is not None:
            return f"the carriage's move to E1 = {e * 1000:.0f} mm collides ({hit.describe()})"
        if back is not None:
            run.play(back)
        run.play(move)
        self.e1 = e
        run.checker.set_base(self.track.offset_R(e))
        run.stops[:] = [q_scan]
        return ""
