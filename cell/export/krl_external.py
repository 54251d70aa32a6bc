"""A positioner in KRL (docs/positioner.md, "Programs"): the header that states its axes and limits, the base on its
kinematic chain (``$BASE = EK(MACHINE_DEF[m].ROOT, MACHINE_DEF[m].MECH_TYPE, BASE_DATA[n])``), the move of its axes
before the welds (``cell krl check`` reads the header back: :mod:`cell.export.checks.positioner`)."""

from __future__ import annotations

from typing import Any

from cell.export.krl_data import e6axis, frame_text, num
from cell.export.program import ProgramJob
from cell.geometry import FloatArray
from cell.types.positioner import ExternalAxes


def positioner_header(ext: ExternalAxes, X_RB: FloatArray) -> list[str]:
    """The header comment: the positioner's axes, their numbers and limits, how the base chains."""
    axes = "; ".join(
        f"E{n} {name} limits {lo:.1f} .. {hi:.1f} deg"
        for n, name, (lo, hi) in zip(ext.numbers, ext.names, ext.limits_deg, strict=True)
    )
    return [
        f";- Positioner (tilt-rotate, coordinated, MACHINE_DEF[{ext.machine}]): {axes}.",
        ";- The points are in BASE_DATA on the positioner's faceplate ($BASE = EK(...)); every point carries the"
        " axes' values: they stand still while the arm welds.",
        f";- The base at this program's axes in $ROBROOT = {frame_text(X_RB)} (what EK gives; for checking)",
    ]


def base_lines(job: ProgramJob) -> list[str]:
    """``BAS(#BASE, n)`` without a positioner; with one, the base on its kinematic chain."""
    n = job.options.base_index
    if job.external is None:
        return [f"BAS(#BASE, {n})"]
    m = job.external.machine
    return [
        f"$BASE = EK(MACHINE_DEF[{m}].ROOT, MACHINE_DEF[{m}].MECH_TYPE, BASE_DATA[{n}]) ; the part on the faceplate"
    ]


def positioner_move(b: Any, job: ProgramJob) -> list[str]:
    """The positioner's axes to the program's values, the arm at home (declared in the .dat ``b.dat``)."""
    ext = job.external
    if ext is None:
        return []
    b.dat.append(f"DECL E6AXIS XPOSITIONER={e6axis(job.plan.q_home, 0.0, ext.by_number())}")
    values = ", ".join(f"{name} {num(v, 1)} deg" for name, v in zip(ext.names, ext.values_deg, strict=True))
    return [f"PTP XPOSITIONER ; the positioner to {values}, the arm at home"]
