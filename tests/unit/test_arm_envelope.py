"""The arm's collision shapes enclose the real arm: a dense set of points on the real arm's surface envelope (the
project's own figures of the KR 5 arc's outline, its dress pack and the torch: ``ENVELOPE`` of
robots/build_kr5_arc.py, docs/reference.md section 3) lies inside the URDF's collision shapes of the same link."""

from __future__ import annotations

import importlib.util
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from cell.geometry import make_pose, rpy_to_matrix

ROBOTS = Path(__file__).resolve().parents[2] / "robots"


@pytest.fixture(scope="module")
def build() -> ModuleType:
    spec = importlib.util.spec_from_file_location("build_kr5_arc", ROBOTS / "build_kr5_arc.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["build_kr5_arc"] = module  # dataclasses resolve their module by name
    spec.loader.exec_module(module)
    return module


def _pose(xyz: tuple[float, ...], rpy: tuple[float, ...]) -> np.ndarray:
    return make_pose(rpy_to_matrix(np.asarray(rpy, dtype=float)), np.asarray(xyz, dtype=float))


def _surface(kind: str, dims: tuple[float, ...], step: float = 0.004) -> np.ndarray:
    """Points (n, 3) [m] on the surface of a box (size x, y, z) or a cylinder (radius, length along z), in the
    shape's own frame, about ``step`` [m] apart."""
    if kind == "box":
        half = np.asarray(dims) / 2.0
        out = []
        for axis in range(3):
            u, v = [a for a in range(3) if a != axis]
            gu = np.linspace(-half[u], half[u], max(int(2 * half[u] / step), 2) + 1)
            gv = np.linspace(-half[v], half[v], max(int(2 * half[v] / step), 2) + 1)
            U, V = np.meshgrid(gu, gv)
            for sign in (-1.0, 1.0):
                p = np.zeros((U.size, 3))
                p[:, u], p[:, v], p[:, axis] = U.ravel(), V.ravel(), sign * half[axis]
                out.append(p)
        return np.concatenate(out)
    r, h = dims
    n_around = max(int(2 * math.pi * r / step), 8)
    ang = np.linspace(0.0, 2 * math.pi, n_around, endpoint=False)
    zs = np.linspace(-h / 2.0, h / 2.0, max(int(h / step), 2) + 1)
    A, Z = np.meshgrid(ang, zs)
    side = np.column_stack([r * np.cos(A.ravel()), r * np.sin(A.ravel()), Z.ravel()])
    rings = [rr * np.column_stack([np.cos(ang), np.sin(ang)]) for rr in np.linspace(0.0, r, max(int(r / step), 1) + 1)]
    disc = np.concatenate(rings)
    caps = [np.column_stack([disc, np.full(len(disc), z)]) for z in (-h / 2.0, h / 2.0)]
    return np.concatenate([side, *caps])


def _collision_shapes(link: str) -> list[tuple[str, tuple[float, ...], np.ndarray]]:
    """The URDF's collision shapes of ``link``: (kind, dims, X_LG (4, 4))."""
    root = ET.parse(ROBOTS / "kr5_arc.urdf").getroot()
    el = next(e for e in root.iter("link") if e.get("name") == link)
    out = []
    for col in el.iter("collision"):
        o = col.find("origin")
        assert o is not None
        X = _pose(tuple(map(float, o.get("xyz", "0 0 0").split())), tuple(map(float, o.get("rpy", "0 0 0").split())))
        g = col.find("geometry")
        assert g is not None
        box, cyl = g.find("box"), g.find("cylinder")
        if box is not None:
            out.append(("box", tuple(map(float, box.get("size", "").split())), X))
        elif cyl is not None:
            out.append(("cylinder", (float(cyl.get("radius", "0")), float(cyl.get("length", "0"))), X))
    return out


def _inside(kind: str, dims: tuple[float, ...], p_G: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    if kind == "box":
        return np.all(np.abs(p_G) <= np.asarray(dims) / 2.0 + tol, axis=1)
    r, h = dims
    return (np.hypot(p_G[:, 0], p_G[:, 1]) <= r + tol) & (np.abs(p_G[:, 2]) <= h / 2.0 + tol)


def test_collision_shapes_enclose_the_real_arm(build: ModuleType) -> None:
    total = 0
    for link, envelope in build.ENVELOPE.items():
        shapes = _collision_shapes(link)
        assert shapes, link
        for env in envelope:
            p_L = _surface(env.kind, env.dims) @ _pose(env.xyz, env.rpy)[:3, :3].T + np.asarray(env.xyz)
            inside = np.zeros(len(p_L), bool)
            for kind, dims, X_LG in shapes:
                p_G = (p_L - X_LG[:3, 3]) @ X_LG[:3, :3]
                inside |= _inside(kind, dims, p_G)
            assert inside.all(), f"{link}: {np.count_nonzero(~inside)} of {len(p_L)} envelope points outside"
            total += len(p_L)
    assert total > 50_000  # dense: about 4 mm apart over every link's outline


def test_the_envelope_is_the_arm(build: ModuleType) -> None:
    # The outline holds the axes it carries: A2 and A3 hubs, the forearm on A4's axis, the wrist round A5, and the
    # dress pack rides on the upper arm; sizes at least the real arm's (a 140 mm forearm, a 240 mm A2 hub).
    env = build.ENVELOPE
    kinds = {link: [(s.kind, s.dims) for s in shapes] for link, shapes in env.items()}
    assert any(k == "cylinder" and d[0] >= 0.07 and d[1] >= 0.4 for k, d in kinds["link_4"])
    assert any(k == "cylinder" and d[0] >= 0.12 for k, d in kinds["link_2"])
    assert sum(1 for k, d in kinds["link_2"] if k == "cylinder" and d[0] < 0.05) == 1  # the dress pack
    upper = next(s for s in env["link_2"] if s.kind == "box")
    assert upper.dims[0] == pytest.approx(build.C2)  # A2 to A3
    assert build.ARM_MARGIN >= 0.005 and build.TORCH_MARGIN >= 0.0
    nozzle = env["torch"][-1]
    assert nozzle.kind == "cylinder" and nozzle.dims[0] >= 0.011  # a gas nozzle of at least 22 mm
