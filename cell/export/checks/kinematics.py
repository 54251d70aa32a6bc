"""The kinematic part of ``cell krl check``: every E6POS's S and T against the configuration the arm reaches it in,
followed from each axis point along every LIN by small IK steps on the arm's kinematics, the flange pose from the
program's own setup values (docs/reference.md section 5, "Status and Turn")."""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from cell.export.checks.program import Finding, Program
from cell.export.status_turn import ArmGeometry, status_turn
from cell.geometry import FloatArray, invert, make_pose, rpy_to_matrix
from cell.types.robot import Kinematics

FLANGE = "tool0"
POS_TOL_M = 5e-5  # 0.05 mm: points are written to 0.001 mm
ROT_TOL_RAD = math.radians(0.01)
STEP_M, STEP_RAD = 0.01, math.radians(5.0)  # IK steps along a LIN


def frame_of(v: dict[str, Any]) -> FloatArray:
    """The pose (4, 4) [m] of a KRL frame structure {X, Y, Z [mm], A, B, C [deg]}."""
    R = rpy_to_matrix(np.radians([float(v.get(k, 0.0)) for k in ("C", "B", "A")]))
    return make_pose(R, np.array([float(v.get(k, 0.0)) for k in "XYZ"]) / 1000.0)


def _error(X: FloatArray, X_goal: FloatArray) -> FloatArray:
    rv = Rotation.from_matrix(X_goal[:3, :3] @ X[:3, :3].T).as_rotvec()
    return np.concatenate([X_goal[:3, 3] - X[:3, 3], rv])


def _jacobian(robot: Kinematics, q: FloatArray) -> FloatArray:
    jac = getattr(robot, "jacobian", None)
    if jac is not None:
        return np.asarray(jac(q, FLANGE, reference="aligned"), dtype=float)
    X0, h, J = robot.fk(q, FLANGE), 1e-7, np.zeros((6, len(q)))
    for i in range(len(q)):
        dq = q.copy()
        dq[i] += h
        J[:, i] = _error(X0, robot.fk(dq, FLANGE)) / h
    return J


def _solve(robot: Kinematics, q: FloatArray, X_goal: FloatArray, iterations: int) -> FloatArray:
    for _ in range(iterations):
        e = _error(robot.fk(q, FLANGE), X_goal)
        if np.linalg.norm(e[:3]) < 1e-9 and np.linalg.norm(e[3:]) < 1e-9:
            break
        J = _jacobian(robot, q)
        q = q + J.T @ np.linalg.solve(J @ J.T + 1e-10 * np.eye(6), e)
    return q


def track(robot: Kinematics, q: FloatArray, X_goal: FloatArray) -> tuple[FloatArray, float, float]:
    """The configuration reached moving the flange on a straight line from fk(q) to X_goal (4, 4) [m], and the
    remaining position [m] and rotation [rad] error."""
    X0 = robot.fk(q, FLANGE)
    e = _error(X0, X_goal)
    steps = max(1, math.ceil(max(np.linalg.norm(e[:3]) / STEP_M, np.linalg.norm(e[3:]) / STEP_RAD)))
    R0 = Rotation.from_matrix(X0[:3, :3])
    for k in range(1, steps + 1):
        f = k / steps
        Xk = make_pose((Rotation.from_rotvec(e[3:] * f) * R0).as_matrix(), X0[:3, 3] + e[:3] * f)
        q = _solve(robot, q, Xk, 30 if k == steps else 6)
    r = _error(robot.fk(q, FLANGE), X_goal)
    return q, float(np.linalg.norm(r[:3])), float(np.linalg.norm(r[3:]))


def _index(p: Program, what: str) -> int | None:
    for s in p.src.statements:
        m = re.match(rf"^BAS\s*\(\s*#{what}\s*,\s*(\d+)\s*\)", s.text, re.I)
        if m is not None:
            return int(m.group(1))
    return None


def _axes(v: Any) -> FloatArray | None:
    if isinstance(v, dict) and all(f"A{i}" in v for i in range(1, 7)):
        return np.radians([float(v[f"A{i}"]) for i in range(1, 7)])
    return None


def _int(v: Any) -> str:
    return str(int(v)) if isinstance(v, float) and v.is_integer() else str(v)


def check_kinematics(
    p: Program, robot: Kinematics, base_R: dict[str, Any] | None = None, circles: bool = False
) -> list[Finding]:
    """S and T of every E6POS reached by a LIN against the arm (module docstring); unreachable points. base_R : the
    base in $ROBROOT when no BASE_DATA gives it (a positioner's, at the program's axes). A CIRC's auxiliary and
    end points are followed too, each from the point before (so that a LIN after a circle starts where the circle
    left the wrist: round a tube A4 and A6 wind on); their S and T are checked with ``circles`` only (a coordinated
    weld's, where the torch nearly stands still while the part turns: the controller ignores them on a CIRC)."""
    ti, bi = _index(p, "TOOL"), _index(p, "BASE")
    tool = p.src.setup.get(f"TOOL_DATA[{ti}]") if ti is not None else None
    base = base_R if base_R is not None else p.src.setup.get(f"BASE_DATA[{bi}]") if bi is not None else None
    if not isinstance(tool, dict) or not isinstance(base, dict):
        return [Finding(p.src_name, 0, "kinematics", "no BAS(#TOOL, n) / BAS(#BASE, n) with TOOL_DATA[n] and"
                        " BASE_DATA[n] values in the setup block: points not checked against the arm")]  # fmt: skip
    X_FT_inv, X_RB = invert(frame_of(tool)), frame_of(base)
    geo = ArmGeometry.of(robot)
    out: list[Finding] = []
    q: FloatArray | None = None
    moves = [(s.kind, pt) for s in p.src.statements for pt in ([s.aux, s.point] if s.kind == "CIRC" else [s.point])
             if s.kind in ("PTP", "LIN", "SPTP", "SLIN", "CIRC")]  # fmt: skip
    for kind, point in moves:
        name = point.upper() if isinstance(point, str) else ""
        d = p.dat.decls.get("XHOME_PLAN" if name == "XHOME" else name)
        value = point if isinstance(point, dict) else (d.value if d is not None else None)
        if kind in ("PTP", "SPTP"):
            q = _axes(value)
            continue
        if d is None or d.type not in ("E6POS", "POS") or not isinstance(value, dict) or q is None:
            q = None
            continue
        q, dp, dr = track(robot, q, X_RB @ frame_of(value) @ X_FT_inv)
        if dp > POS_TOL_M or dr > ROT_TOL_RAD:
            off = f"{dp * 1000:.2f} mm, {math.degrees(dr):.2f} deg off"
            msg = f"{d.name}: the arm does not reach it on a line from the point before ({off})"
            out.append(Finding(p.dat_name, d.line, "kinematics", msg))
            q = None
            continue
        if kind == "CIRC" and not circles:
            continue
        st = status_turn(robot, q, geo)
        written = (value.get("S"), value.get("T"))
        if written != (float(st[0]), float(st[1])):
            out.append(Finding(p.dat_name, d.line, "status_turn", f"{d.name}: S {_int(written[0])} T {_int(written[1])}"
                               f" written, the arm reaches it with S {st[0]} T {st[1]}"))  # fmt: skip
    return out
