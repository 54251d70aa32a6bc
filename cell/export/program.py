"""What a post-processor is given and what it must do: a :class:`ProgramJob` (the checked plan, the arm, the part's
base, the name, options, provenance) that a :class:`PostProcessor` (KUKA KRL, ABB RAPID) turns into named texts. A
weld segment without a procedure runs :func:`procedure_of`'s default at its own travel speed."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from cell.config.export import KrlOptions
from cell.geometry import FloatArray, readonly
from cell.outputs import make_folder, write_atomic
from cell.types.plan import Segment, WeldPlan
from cell.types.positioner import ExternalAxes
from cell.types.procedure import WeldProcedure
from cell.types.robot import Kinematics

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,23}")
DEFAULT_PROCEDURE = WeldProcedure(name="default")


@dataclass(frozen=True)
class ProgramJob:
    """One program to write.

    plan : the checked WeldPlan (frames R, metres, radians); robot : its kinematics (fk by frame name).
    name : the program's name (a letter or _, then letters, digits, _; at most 24; written upper-case).
    X_RB : (4, 4) the part's base in R (the aligned map's pose X_RM): every weld point is written in it.
    X_WR : (4, 4) the robot's mounting in the cell's world (a comment only), or None.
    provenance : what made the program (:func:`cell.provenance.provenance`), or None.
    not_welded : the map's seams the job does not weld, each (id, why as a code, e.g. ``not_supported: curved``):
        the header lists them, so a program never drops a seam in silence.
    external : a positioner's axes for the whole program (None: none); its points are then in the base on the
        positioner's faceplate (X_RB the faceplate's base at the program's pose, ``external.X_FB`` on the flange).
    """

    plan: WeldPlan
    robot: Kinematics
    name: str
    X_RB: FloatArray = field(default_factory=lambda: np.eye(4))
    X_WR: FloatArray | None = None
    options: KrlOptions = field(default_factory=KrlOptions)
    provenance: Mapping[str, Any] | None = None
    not_welded: tuple[tuple[str, str], ...] = ()
    external: ExternalAxes | None = None

    def __post_init__(self) -> None:
        if not _NAME.fullmatch(self.name):
            raise ValueError(
                f"program name {self.name!r} is invalid: 1-24 characters, a letter or _ first, then letters, digits, _"
            )
        if not self.plan.segments:
            raise ValueError("the plan has no motion: nothing to export")
        X = readonly(self.X_RB)
        if X.shape != (4, 4) or not np.all(np.isfinite(X)):
            raise ValueError(f"X_RB must be a finite 4 x 4 pose, got shape {X.shape}")
        object.__setattr__(self, "X_RB", X)
        object.__setattr__(self, "name", self.name.upper())


class PostProcessor(Protocol):
    """A controller's language: ``name`` (the ``--controller`` value) and ``texts(job)``: file name -> text."""

    name: str

    def texts(self, job: ProgramJob) -> dict[str, str]: ...


def not_welded_lines(job: ProgramJob, prefix: str = ";- ") -> list[str]:
    """The header's comment lines naming the map's seams the job does not weld and why (none when it welds all)."""
    if not job.not_welded:
        return []
    lines = [f"{prefix}Not welded by this job: {len(job.not_welded)} seam(s) of the map"]
    lines += [f"{prefix}  {sid}: {why}" for sid, why in job.not_welded]
    return [ln.encode("ascii", errors="replace").decode("ascii") for ln in lines]


def procedure_of(seg: Segment) -> WeldProcedure:
    """The procedure a weld segment runs: its own, else the default at the segment's travel speed."""
    if seg.procedure is not None:
        return seg.procedure
    return replace(DEFAULT_PROCEDURE, travel_speed_mm_s=round(seg.speed * 1000.0, 6))


def write_texts(texts: Mapping[str, str], directory: str | Path, *, crlf: bool = True) -> list[Path]:
    """Write each text (ASCII, CRLF line ends as on a controller unless ``crlf`` is False) atomically into
    ``directory`` (made if missing: its parent must exist); their paths. OutputError when a file cannot be
    written."""
    d = Path(directory)
    make_folder(d, "robot program folder")
    paths = []
    for name, text in texts.items():
        body = text.replace("\n", "\r\n") if crlf else text
        paths.append(write_atomic(d / name, body.encode("ascii", errors="replace"), what="robot program"))
    return paths
