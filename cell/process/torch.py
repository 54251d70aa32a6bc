"""Torch poses along a fillet seam, from the joint geometry alone (values in, poses out): work and travel angles,
spin and contact-tip-to-work distance (the geometry: docs/planning.md section 3).

Frames: ``R`` robot base; ``T`` the torch tool frame ``torch_tcp`` (origin at the wire tip, z along the wire into
the joint). Units: metres and radians."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from cell.config.motion import STICKOUT_MM
from cell.errors import PlanError
from cell.geometry import FloatArray, make_pose, readonly, rot_z
from cell.scenario import ProcessSpec

_DEG = math.pi / 180.0


@dataclass(frozen=True)
class WeldProcess:
    """The welding process in SI units, built from a :class:`~cell.scenario.ProcessSpec` (the one conversion).

    travel_speed [m/s]; work_angle, travel_angle [rad]; *_tol [rad] how far the planner may move them;
    ctwd, stickout, approach, depart [m]; approach_speed [m/s]; spin_tol [rad] (pi: fully free);
    reversible: the planner may weld the seam either way (False: only from p_start to p_end, e.g. a vertical
    seam its procedure welds upwards). closed_overlap [m]: how far a closed curved seam is welded on past its
    start (the start and the stop overlap). curve_remainder: ``manual`` welds what the arm reaches of a curved seam
    it cannot weld whole and lists the rest for a manual weld; ``refuse`` welds none of such a seam.
    """

    travel_speed: float
    work_angle: float
    work_angle_tol: float
    travel_angle: float
    travel_angle_tol: float
    ctwd: float
    stickout: float
    spin_tol: float
    approach: float
    depart: float
    approach_speed: float
    reversible: bool = True
    closed_overlap: float = 0.010
    curve_remainder: Literal["manual", "refuse"] = "manual"

    @classmethod
    def from_spec(cls, spec: ProcessSpec, stickout_mm: float = STICKOUT_MM) -> WeldProcess:
        """SI values from the scenario's process spec; ``stickout_mm`` is the scenario's robot.stickout_mm."""
        return cls(
            travel_speed=spec.travel_speed_mm_s / 1000.0,
            work_angle=spec.work_angle_deg * _DEG,
            work_angle_tol=spec.work_angle_tol_deg * _DEG,
            travel_angle=spec.travel_angle_deg * _DEG,
            travel_angle_tol=spec.travel_angle_tol_deg * _DEG,
            ctwd=spec.contact_tip_distance_mm / 1000.0,
            stickout=stickout_mm / 1000.0,
            spin_tol=spec.spin_tol_deg * _DEG,
            approach=spec.approach_mm / 1000.0,
            depart=spec.depart_mm / 1000.0,
            approach_speed=spec.approach_speed_mm_s / 1000.0,
            closed_overlap=spec.closed_overlap_mm / 1000.0,
            curve_remainder=spec.curve_remainder,
        )

    @property
    def standoff(self) -> float:
        """How far [m] the wire tip stays back from the seam along the torch axis (ctwd - stickout)."""
        return self.ctwd - self.stickout


def _unit(v: npt.ArrayLike, what: str) -> FloatArray:
    a = np.asarray(v, dtype=float).reshape(-1)
    n = float(np.linalg.norm(a))
    if a.shape != (3,) or not np.isfinite(n) or n < 1e-9:
        raise PlanError(f"{what} must be a finite non-zero 3-vector, got {np.round(a, 6).tolist()}")
    return np.asarray(a / n)


def fillet_axes(d_R: npt.ArrayLike, n_a_R: npt.ArrayLike, n_b_R: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """(t_b, n_b) (3,) each: the unit direction in face B away from the corner, and face B's unit normal, both
    perpendicular to the seam direction d. PlanError when the faces do not form a fillet along d."""
    d = _unit(d_R, "seam direction")
    n_a = _unit(n_a_R, "normal of face A")
    n_b = _unit(n_b_R, "normal of face B")
    n_b = n_b - (n_b @ d) * d  # the faces contain the seam: drop any rounding component along it
    n_a = n_a - (n_a @ d) * d
    if np.linalg.norm(n_b) < 0.5 or np.linalg.norm(n_a) < 0.5:
        raise PlanError("a weld face normal is nearly parallel to the seam: the seam does not lie on that face")
    n_b = n_b / np.linalg.norm(n_b)
    t_b = n_a - (n_a @ n_b) * n_b
    if np.linalg.norm(t_b) < 1e-3:
        raise PlanError("the two weld faces are parallel: there is no fillet between them")
    return np.asarray(t_b / np.linalg.norm(t_b)), n_b


def fillet_angle(d_R: npt.ArrayLike, n_a_R: npt.ArrayLike, n_b_R: npt.ArrayLike) -> float:
    """The fillet's opening angle [rad] between face B and face A about the seam d (3,): pi / 2 for a square T,
    less in an acute corner (a 35 deg brace), more in an obtuse one. Exactly pi / 2 when the faces are square
    within 1e-9 rad, so that a box's torch poses keep their last bits."""
    d = _unit(d_R, "seam direction")
    t_b, n_b = fillet_axes(d, n_a_R, n_b_R)
    n_a = _unit(n_a_R, "normal of face A")
    t_a = n_b - (n_b @ n_a) * n_a - ((n_b - (n_b @ n_a) * n_a) @ d) * d  # in face A away from the corner
    t_a = t_a / max(float(np.linalg.norm(t_a)), 1e-300)
    angle = math.atan2(float(t_a @ n_b), float(t_a @ t_b))
    return 0.5 * math.pi if abs(angle - 0.5 * math.pi) < 1e-9 else angle


def torch_rotation(
    d_R: npt.ArrayLike,
    n_a_R: npt.ArrayLike,
    n_b_R: npt.ArrayLike,
    work_angle: float,
    travel_angle: float,
    spin: float = 0.0,
) -> FloatArray:
    """R_RT (3, 3): the torch orientation for a seam of direction d with faces A, B (outward normals in R).

    work_angle, travel_angle, spin [rad]: see the module docstring.
    """
    d = _unit(d_R, "seam direction")
    t_b, n_b = fillet_axes(d, n_a_R, n_b_R)
    w = work_angle + 0.5 * fillet_angle(d, n_a_R, n_b_R) - 0.25 * math.pi  # about the actual bisector
    u = math.cos(w) * t_b + math.sin(w) * n_b  # out of the joint, perpendicular to d
    z = -math.cos(travel_angle) * u + math.sin(travel_angle) * d
    x = d - (d @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z]) @ rot_z(spin)


def torch_poses(
    p_start_R: npt.ArrayLike,
    p_end_R: npt.ArrayLike,
    n_a_R: npt.ArrayLike,
    n_b_R: npt.ArrayLike,
    process: WeldProcess,
    *,
    spin: float = 0.0,
    work_offset: float = 0.0,
    travel_offset: float = 0.0,
    spacing: float = 0.0025,
) -> FloatArray:
    """X_RT (n, 4, 4), read-only: torch poses along the seam from p_start to p_end (3,) [m] in R.

    n_a_R, n_b_R : outward normals (3,) of face A and face B in R.
    spin [rad] : rotation about the torch axis; work_offset, travel_offset [rad] : added to the process's
        nominal angles (the planner's tolerance search).
    spacing [m] : largest distance between consecutive poses; the poses are evenly spaced, ends included.
    The wire tip lies on the seam line, backed off along the torch axis by ``process.standoff``.
    """
    p0 = np.asarray(p_start_R, dtype=float).reshape(3)
    p1 = np.asarray(p_end_R, dtype=float).reshape(3)
    length = float(np.linalg.norm(p1 - p0))
    if length < 1e-4:
        raise PlanError(f"seam of length {length * 1000:.3f} mm: needs at least 0.1 mm between its ends")
    if not spacing > 0.0:
        raise ValueError(f"torch_poses: spacing must be positive, got {spacing}")
    d = (p1 - p0) / length
    R = torch_rotation(d, n_a_R, n_b_R, process.work_angle + work_offset, process.travel_angle + travel_offset, spin)
    n = max(2, math.ceil(length / spacing - 1e-9) + 1)
    p = p0 + np.outer(np.linspace(0.0, length, n), d) - process.standoff * R[:, 2]
    out = np.repeat(make_pose(R)[None], n, axis=0)
    out[:, :3, 3] = p
    return readonly(out)


def back_off(X_RT: npt.ArrayLike, distance: float) -> FloatArray:
    """X_RT (4, 4) moved back along its own torch axis (-z) by ``distance`` [m] (approach and depart poses)."""
    X = np.array(X_RT, dtype=float)
    X[:3, 3] -= distance * X[:3, 2]
    return X


def line_poses(X_from: npt.ArrayLike, X_to: npt.ArrayLike, spacing: float = 0.005) -> FloatArray:
    """(n, 4, 4) poses evenly spaced on the straight line between two poses of the same orientation, ends
    included, at most ``spacing`` [m] apart (the approach and depart moves along the torch axis)."""
    a, b = np.asarray(X_from, dtype=float), np.asarray(X_to, dtype=float)
    length = float(np.linalg.norm(b[:3, 3] - a[:3, 3]))
    n = max(2, math.ceil(length / spacing - 1e-9) + 1)
    out = np.repeat(a[None], n, axis=0)
    out[:, :3, 3] = a[:3, 3] + np.outer(np.linspace(0.0, 1.0, n), b[:3, 3] - a[:3, 3])
    return out


def measured_angles(
    X_RT: npt.ArrayLike, d_R: npt.ArrayLike, n_a_R: npt.ArrayLike, n_b_R: npt.ArrayLike
) -> tuple[float, float]:
    """(work angle, travel angle) [rad] of a torch pose on a seam (the inverse of :func:`torch_rotation`: the work
    angle as its argument, 45 deg on the bisector of whatever dihedral the faces make)."""
    z = np.asarray(X_RT, dtype=float)[:3, 2]
    d = _unit(d_R, "seam direction")
    t_b, n_b = fillet_axes(d, n_a_R, n_b_R)
    travel = math.asin(float(np.clip(z @ d, -1.0, 1.0)))
    u = -(z - (z @ d) * d)
    work = math.atan2(float(u @ n_b), float(u @ t_b)) - 0.5 * fillet_angle(d, n_a_R, n_b_R) + 0.25 * math.pi
    return work, travel
