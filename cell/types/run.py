"""One record per seam: everything a run knows about it, joined once by id.

The stages make the parts (the map its seam and joint, a locator its estimate, the re-scan its close-up, the
planner its outcome, the arm its weld); the pipeline joins them here, and reports and pictures read only these
records. Frame ``R`` (robot base), metres; millimetres where a name says ``_mm``.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from cell.geometry import FloatArray
from cell.types.execution import WeldQuality
from cell.types.map import MapSeam
from cell.types.plan import PlanReason, Remainder, SeamOutcome
from cell.types.procedure import WeldProcedure
from cell.types.rescan import SeamRescan
from cell.types.seams import Joint, SeamEstimate, SeamMetrics


class WeldReason(enum.StrEnum):
    """Why a seam was not welded, as a code (the detail text says more)."""

    NOT_VISIBLE = "not_visible"  # no camera can see it on this side (against the table)
    NOT_LOCATED = "not_located"  # visible, but not found (its estimate says why)
    LOW_CONFIDENCE = "low_confidence"  # found, but still too uncertain after the re-scan
    END_UNCERTAIN = "end_uncertain"  # found, but an end's bound along the seam still over the end tolerance
    NOT_PLANNED = "not_planned"  # the planner could not weld it (its outcome's code says why)
    NOT_EXECUTED = "not_executed"  # planned, but the run stopped before the arm moved (the run's error says why)
    PREVIEW = "preview"  # planned in a dry run: nothing moves
    NOT_SUPPORTED = "not_supported"  # drawn in the map, but not a seam the cell can weld (a curve, on a fixture)
    NO_TORCH_PATH = "no_torch_path"  # located (a curved seam), but no torch path along it exists yet
    LAST_CHECK = "last_check"  # found, but against the aligned map and the other parts it cannot be there
    #   (re-scanned, then refused: its ``check`` says which test and by how much)
    PARTIAL = "partial"  # a curved seam welded in part: the arm welds what it reaches, the ``remainder`` of the
    #   weld (each stretch along it and why) is left for a manual weld; never counted as welded


def partial_text(n: int, manual_mm: float | None) -> str:
    """How ``n`` curved seams welded in part are said everywhere (the console, the exit line, the page):
    ``1 curved seam partly welded: 21 mm left for a manual weld``."""
    return f"{n} curved seam{'s' * (n != 1)} partly welded: {manual_mm or 0.0:.0f} mm left for a manual weld"


def in_part_text(share: float, remainder: tuple[Remainder, ...], n_arcs: int, how: str = "") -> str:
    """How one curved seam welded in part is said in its reason (the planner's, the positioner's): the ``share``
    its ``n_arcs`` arcs weld (``how``: e.g. " with the part turning"), the length left and each stretch of its
    ``remainder`` (:meth:`Remainder.describe`)."""
    left = sum(r.length_m for r in remainder)
    stretches = "; ".join(r.describe() for r in remainder)
    return (f"welded in part: {share:.0%} in {n_arcs} arc{'s' * (n_arcs != 1)}{how}, {left * 1000:.0f} mm left for a "
            f"manual weld: {stretches}")  # fmt: skip


class LastCheck(enum.StrEnum):
    """Which test of the last check before the arc a located seam failed (:mod:`cell.seams.checks.last_check`)."""

    ACROSS = "across"  # its line lies further across the drawn seam than the build, placement and calibration allow
    LENGTH = "length"  # its length differs from the drawn length by more than the parts' tolerance
    END_IN_BODY = "end_in_body"  # an end lies inside another part's body
    END_OFF_FACE = "end_off_face"  # an end lies off a face its joint joins (a bead running on past the joint)


@dataclass(frozen=True)
class CheckFail:
    """A failed last check: which test (``code``), the measured ``value_m`` and its ``limit_m`` [m], which end
    (``"start"``, ``"end"``; ``""`` for the whole line) and the part concerned (the body an end lies in, the part
    whose face it is off; ``""`` otherwise)."""

    code: LastCheck
    value_m: float
    limit_m: float
    end: str = ""
    part: str = ""

    def describe(self) -> str:
        """One line for people: what, where, by how much against what."""
        where = f" at its {self.end}" if self.end else ""
        of = f" ({self.part})" if self.part else ""
        return f"{self.code}{where}{of}: {self.value_m * 1000.0:.2f} mm > {self.limit_m * 1000.0:.2f} mm"


@dataclass(frozen=True)
class SeamWeld:
    """What became of one seam in ``cell weld``: planned and welded, or why not (``code`` and the detail
    ``reason``); how well (the executed TCP against the true seam, when the truth is known: all passes together
    in ``quality``, each pass's bead in ``passes``, in pass order); the weld ``procedure`` it got (None: the
    plan used none); the last check it failed (``check``, with the code ``last_check``); the planner's code where
    it refused the seam (``plan_code``). A curved seam welded in part (code ``partial``, ``welded`` False: never
    counted as welded whole): ``share`` the part of it its arcs weld, ``remainder`` the stretches left for a manual
    weld, its arcs' ``quality`` (a loop the positioner turns welded in more than one arc: each arc's in
    ``arc_quality``, in order)."""

    id: str
    planned: bool
    welded: bool
    reason: str = ""
    quality: WeldQuality | None = None
    code: WeldReason | None = None
    procedure: WeldProcedure | None = None
    passes: tuple[WeldQuality, ...] = ()
    check: CheckFail | None = None
    plan_code: PlanReason | None = None
    share: float = 1.0
    remainder: tuple[Remainder, ...] = ()
    arc_quality: tuple[WeldQuality, ...] = ()

    @property
    def partial(self) -> bool:
        """Welded (or planned, in a preview) in part, the remainder left for a manual weld."""
        return bool(self.remainder)

    @property
    def manual_m(self) -> float:
        """The length [m] left for a manual weld."""
        return sum(r.length_m for r in self.remainder)


@dataclass(frozen=True)
class SeamRecord:
    """Everything one run knows about one seam.

    seam : the aligned map's seam; joint : how it is made (None when the map does not say).
    estimate : what the cell uses now (the fused estimate after a re-scan); truth : the as-built seam (start,
        end) when the station knows it; metrics : the estimate's errors against it (found seams with a truth).
    first, first_metrics : the estimate before the re-scan and its errors (None when the seam was not re-scanned).
    rescan : what the close-up did; outcome : the planner's word on it; weld : what became of it.
    """

    seam: MapSeam
    joint: Joint | None
    estimate: SeamEstimate
    truth: tuple[FloatArray, FloatArray] | None = None
    metrics: SeamMetrics | None = None
    first: SeamEstimate | None = None
    first_metrics: SeamMetrics | None = None
    rescan: SeamRescan | None = None
    outcome: SeamOutcome | None = None
    weld: SeamWeld | None = None

    @property
    def id(self) -> str:
        return self.seam.id
