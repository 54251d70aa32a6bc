"""Surfaces as implicit functions (a cylinder, a plane) with a parameter vector each, and the curve where two meet.

A surface is f(p; theta) (n,) [m], signed distance-like, positive outside the part (its outward side); its
gradient in p is its outward normal. The parameters are small offsets from a reference surface (theta = 0 is the
reference), so a least-squares fit starts at zero and its covariance is that of theta. Frame-free, metres."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray, cross3, readonly
from cell.types import Cylinder

# A surface as f(p) (n,) [m] and its gradient (n, 3), for points p (n, 3).
Implicit = Callable[[FloatArray], tuple[FloatArray, FloatArray]]

_ITERATIONS = 30
_CONVERGED_M = 1e-12


def basis(u: FloatArray) -> FloatArray:
    """(2, 3) two unit vectors perpendicular to the unit ``u`` (3,) and to each other."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = cross3(u, helper)
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, cross3(u, e1)])


@dataclass(frozen=True)
class CylinderModel:
    """A cylinder near a reference one: theta = (x, y, a, b, dr): the axis point moved by x e1 + y e2 [m], the axis
    tilted to u0 + a e1 + b e2 (normalised) [rad], the radius by dr [m] (e1, e2 perpendicular to u0)."""

    c0: FloatArray
    u0: FloatArray
    r0: float
    facets: int = 0  # how many flat faces draw the round (0: a true round)
    size = 5

    def __post_init__(self) -> None:
        object.__setattr__(self, "c0", readonly(np.asarray(self.c0, dtype=float)))
        object.__setattr__(self, "u0", readonly(np.asarray(self.u0, dtype=float)))
        object.__setattr__(self, "_e", readonly(basis(self.u0)))

    @staticmethod
    def about(c: Cylinder, p_near: FloatArray) -> CylinderModel:
        """The model of ``c`` with its axis point at the foot of ``p_near`` (3,) on the axis (good conditioning)."""
        foot = c.p_base + float((p_near - c.p_base) @ c.axis) * c.axis
        return CylinderModel(foot, np.asarray(c.axis), c.radius, c.facets)

    def axis(self, theta: FloatArray) -> tuple[FloatArray, FloatArray, float]:
        """(axis point (3,), unit axis (3,), radius) at ``theta``."""
        e = self._e  # type: ignore[attr-defined]
        u = self.u0 + theta[2] * e[0] + theta[3] * e[1]
        return self.c0 + theta[0] * e[0] + theta[1] * e[1], u / np.linalg.norm(u), self.r0 + float(theta[4])

    def value(self, p: FloatArray, theta: FloatArray) -> FloatArray:
        c, u, r = self.axis(theta)
        d = p - c
        return np.asarray(np.linalg.norm(d - np.outer(d @ u, u), axis=1) - r)

    def jac(self, p: FloatArray, theta: FloatArray) -> FloatArray:
        """(n, 5) d value / d theta at the points p (n, 3)."""
        e = self._e  # type: ignore[attr-defined]
        raw = self.u0 + theta[2] * e[0] + theta[3] * e[1]
        c, u, _ = self.axis(theta)
        d = p - c
        s = d @ u
        radial = d - np.outer(s, u)
        w = radial / np.maximum(np.linalg.norm(radial, axis=1), 1e-300)[:, None]
        du = (e - np.outer(e @ u, u)) / np.linalg.norm(raw)  # (2, 3) d u / d (a, b)
        J = np.empty((len(p), 5))
        J[:, :2] = -(w @ e.T)
        J[:, 2:4] = -s[:, None] * (w @ du.T)
        J[:, 4] = -1.0
        return J

    def implicit(self, theta: FloatArray) -> Implicit:
        c, u, r = self.axis(theta)

        def f(p: FloatArray) -> tuple[FloatArray, FloatArray]:
            d = p - c
            radial = d - np.outer(d @ u, u)
            norm = np.linalg.norm(radial, axis=1)
            return norm - r, radial / np.maximum(norm, 1e-300)[:, None]

        return f


@dataclass(frozen=True)
class PlaneModel:
    """A plane near a reference one n0 . (p - p0) = 0: theta = (a, b, d): normal n0 + a e1 + b e2 (normalised)
    [rad], offset d [m] along it (p0 a point of the reference plane near the seam: good conditioning)."""

    p0: FloatArray
    n0: FloatArray
    size = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "p0", readonly(np.asarray(self.p0, dtype=float)))
        object.__setattr__(self, "n0", readonly(np.asarray(self.n0, dtype=float)))
        object.__setattr__(self, "_e", readonly(basis(self.n0)))

    def plane(self, theta: FloatArray) -> tuple[FloatArray, float]:
        """(unit normal (3,), offset) of n . p = offset at ``theta``."""
        e = self._e  # type: ignore[attr-defined]
        n = self.n0 + theta[0] * e[0] + theta[1] * e[1]
        n = n / np.linalg.norm(n)
        return n, float(n @ self.p0 + theta[2])

    def value(self, p: FloatArray, theta: FloatArray) -> FloatArray:
        n, d = self.plane(theta)
        return np.asarray(p @ n - d)

    def jac(self, p: FloatArray, theta: FloatArray) -> FloatArray:
        """(n, 3) d value / d theta at the points p (n, 3)."""
        e = self._e  # type: ignore[attr-defined]
        raw = self.n0 + theta[0] * e[0] + theta[1] * e[1]
        n = raw / np.linalg.norm(raw)
        dn = (e - np.outer(e @ n, n)) / np.linalg.norm(raw)  # (2, 3) d n / d (a, b)
        J = np.empty((len(p), 3))
        J[:, :2] = (p - self.p0) @ dn.T
        J[:, 2] = -1.0
        return J

    def implicit(self, theta: FloatArray) -> Implicit:
        n, d = self.plane(theta)

        def f(p: FloatArray) -> tuple[FloatArray, FloatArray]:
            return p @ n - d, np.tile(n, (len(p), 1))

        return f


SurfaceModel = CylinderModel | PlaneModel


def param_jacobian(model: SurfaceModel, p: FloatArray, theta: FloatArray) -> FloatArray:
    """(n, k) d f(p_i; theta) / d theta at the points p (n, 3)."""
    return model.jac(p, theta)


def intersect(points: FloatArray, f1: Implicit, f2: Implicit) -> FloatArray:
    """The points (n, 3) moved onto the curve where f1 = f2 = 0 (Gauss-Newton, the least-norm step each time)."""
    p = np.array(points, dtype=float)
    for _ in range(_ITERATIONS):
        (v1, g1), (v2, g2) = f1(p), f2(p)
        J = np.stack([g1, g2], axis=1)  # (n, 2, 3)
        JJt = J @ np.transpose(J, (0, 2, 1))
        lam = np.linalg.solve(JJt, np.stack([v1, v2], axis=1)[:, :, None])
        step = (np.transpose(J, (0, 2, 1)) @ lam)[:, :, 0]
        p -= step
        if float(np.abs(step).max()) < _CONVERGED_M:
            break
    return p


def crossing_covariance(
    p: FloatArray,
    g1: FloatArray,
    g2: FloatArray,
    df1: FloatArray,
    cov1: FloatArray,
    df2: FloatArray,
    cov2: FloatArray,
    bias_m: tuple[float, float] = (0.0, 0.0),
) -> FloatArray:
    """(n, 3, 3) the covariance of the crossing points p (n, 3) of two surfaces with gradients g1, g2 (n, 3) there,
    from their parameters' covariances cov1 (k1, k1), cov2 (k2, k2) through d f / d theta df1 (n, k1), df2 (n, k2):
    a change of the parameters moves each point by the least-norm step that keeps it on both surfaces (first
    order), so within the plane across the curve. ``bias_m`` [m]: a shift of each surface along its normal that its
    fit does not see (one sigma, independent per surface)."""
    J = np.stack([g1, g2], axis=1)  # (n, 2, 3)
    pinv = np.transpose(J, (0, 2, 1)) @ np.linalg.inv(J @ np.transpose(J, (0, 2, 1)))  # (n, 3, 2)
    v1 = np.einsum("ni,ij,nj->n", df1, cov1, df1)
    v2 = np.einsum("ni,ij,nj->n", df2, cov2, df2)
    S = np.zeros((len(p), 2, 2))
    S[:, 0, 0], S[:, 1, 1] = v1 + bias_m[0] ** 2, v2 + bias_m[1] ** 2  # the two fits are independent (disjoint points)
    return np.asarray(pinv @ S @ np.transpose(pinv, (0, 2, 1)))
