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
    """The positioner's axes to the program's values, the arm at home, through the route's via points when the
    move check sent it round the arm (declared in the .dat ``b.dat``)."""
    ext = job.external
    if ext is None:
        return []
    lines = []
    for k, via in enumerate(ext.via_deg, start=1):
        b.dat.append(f"DECL E6AXIS XPOSVIA{k}={e6axis(job.plan.q_home, 0.0, dict(zip(ext.numbers, via, strict=True)))}")
        lines.append(f"PTP XPOSVIA{k} ; on the way: {_axes_text(ext.names, via)} (a straight move meets the arm)")
    b.dat.append(f"DECL E6AXIS XPOSITIONER={e6axis(job.plan.q_home, 0.0, ext.by_number())}")
    return [*lines, f"PTP XPOSITIONER ; the positioner to {_axes_text(ext.names, ext.values_deg)}, the arm at home"]


def _axes_text(names: tuple[str, str], values_deg: tuple[float, float]) -> str:
    return ", ".join(f"{name} {num(v, 1)} deg" for name, v in zip(names, values_deg, strict=True))
