"""Preview pictures (cell.preview) from a tiny synthetic T joint: files written, readable, showing what they should."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cell.geometry import FloatArray, make_pose
from cell.motion.limits import JointLimits
from cell.preview import ARC_COLOUR, STATUS_COLOURS, SeamView, render_html, render_joint_plots, render_overview
from cell.types import Box, MapSeam, Part, WeldMap

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# A post standing on a rail (frame R, metres); seams along the foot of the post.
RAIL = Box(make_pose(p=[0.0, 0.0, -1.0]), np.array([0.6, 0.08, 0.04]))
POST = Box(make_pose(p=[0.0, 0.0, -0.93]), np.array([0.04, 0.04, 0.1]))
SEAMS = (
    MapSeam("S_front", np.array([-0.02, -0.02, -0.98]), np.array([0.02, -0.02, -0.98])),
    MapSeam("S_back", np.array([-0.02, 0.02, -0.98]), np.array([0.02, 0.02, -0.98])),
    MapSeam("S_left", np.array([-0.02, -0.02, -0.98]), np.array([-0.02, 0.02, -0.98])),
)
WELDMAP = WeldMap((Part("RAIL", RAIL), Part("POST", POST)), SEAMS, "mm", "synthetic", frame="R")


def surface_cloud(rng: np.random.Generator, n: int = 4000) -> FloatArray:
    """Points on the top faces and sides of both boxes (what a camera above would see)."""
    pts = []
    for box in (RAIL, POST):
        u = rng.uniform(-0.5, 0.5, size=(n, 3)) * box.size
        face = rng.integers(0, 3, n)
        u[face == 0, 2] = box.size[2] / 2.0
        u[face == 1, 1] = np.sign(u[face == 1, 1]) * box.size[1] / 2.0
        u[face == 2, 0] = np.sign(u[face == 2, 0]) * box.size[0] / 2.0
        pts.append(u + box.center)
    return np.concatenate(pts)


def views() -> list[SeamView | tuple[Any, ...]]:
    front = SEAMS[0]
    offset = np.array([0.0005, 0.0, 0.0003])
    return [
        SeamView("S_front", "found", front.p_start + offset, front.p_end + offset, front.p_start, front.p_end),
        SeamView("S_back", "not_found", np.zeros(0), np.zeros(0), SEAMS[1].p_start, SEAMS[1].p_end),
        ("S_left", "not_visible", np.zeros(0), np.zeros(0), None, None),  # plain tuples are accepted too
    ]


def torch_along(seam: MapSeam, m: int = 10) -> FloatArray:
    x = seam.direction
    z = np.array([0.0, 0.7, -0.7])
    z -= x * (x @ z)
    z /= np.linalg.norm(z)
    R = np.column_stack([x, np.cross(z, x), z])
    return np.array([make_pose(R, p) for p in np.linspace(seam.p_start, seam.p_end, m)])


def colour_fraction(png: Path, hex_colour: str, alpha: float = 1.0, tol: float = 0.06) -> float:
    """Fraction of pixels of ``hex_colour`` drawn with ``alpha`` over white."""
    from matplotlib.image import imread

    img = imread(png)[..., :3]
    rgb = np.array([int(hex_colour[i : i + 2], 16) / 255.0 for i in (1, 3, 5)])
    rgb = alpha * rgb + (1.0 - alpha)
    return float(np.mean(np.all(np.abs(img - rgb) < tol, axis=-1)))


def assert_png(path: Path) -> None:
    assert path.is_file() and path.stat().st_size > 10_000
    assert path.read_bytes()[:8] == PNG_SIGNATURE


def test_overview_pngs_show_seams_by_status(tmp_path: Path) -> None:
    cloud = surface_cloud(np.random.default_rng(5))
    front = torch_along(SEAMS[0])
    files = render_overview(
        cloud, WELDMAP, views(), {"S_front": front}, {"S_front": front[:, :3, 3]}, tmp_path / "out", title="tiny"
    )
    assert [f.name for f in files] == ["overview_top.png", "overview_3d.png", "overview_seams.png"]
    for f in files:
        assert_png(f)
    for status in {v[1] for v in views()}:  # every status present is drawn in its own colour
        assert colour_fraction(files[2], STATUS_COLOURS[status]) > 1e-4, status
    assert colour_fraction(files[0], STATUS_COLOURS["found"]) > 1e-4


def test_overview_without_torch_or_paths_and_bad_input(tmp_path: Path) -> None:
    cloud = surface_cloud(np.random.default_rng(6), 500)
    files = render_overview(cloud, WELDMAP, [], {}, {}, tmp_path)
    assert [f.name for f in files] == ["overview_top.png", "overview_3d.png"]
    with pytest.raises(ValueError, match="status 'lost' unknown"):
        render_overview(cloud, WELDMAP, [("S_front", "lost", np.zeros(0), np.zeros(0))], {}, {}, tmp_path)
    with pytest.raises(ValueError, match="empty"):
        render_overview(np.zeros((0, 3)), WELDMAP, [], {}, {}, tmp_path)


def limits() -> JointLimits:
    names = tuple(f"joint_a{i}" for i in range(1, 4))
    return JointLimits(
        names,
        np.radians([-155.0, -180.0, -15.0]),
        np.radians([155.0, 65.0, 158.0]),
        np.radians([154.0, 154.0, 228.0]),
        np.full(3, 6.0),
        np.full(3, 60.0),
    )


def test_joint_plots(tmp_path: Path) -> None:
    t = np.linspace(0.0, 2.0, 201)
    q = np.column_stack([np.sin(t), 0.5 * t - 1.0, np.radians(150.0) + 0.2 * np.sin(3 * t)])  # A3 crosses its limit
    qd = np.gradient(q, t, axis=0)
    out = render_joint_plots(t, q, qd, limits(), tmp_path / "joints.png", arc_on=(t > 0.5) & (t < 1.5))
    assert_png(out)
    assert colour_fraction(out, ARC_COLOUR, alpha=0.35, tol=0.02) > 0.05  # the arc-on band is shaded
    with pytest.raises(ValueError, match="q and qd"):
        render_joint_plots(t, q[:, :2], qd, limits(), tmp_path / "bad.png")


def test_html_is_self_contained_plotly(tmp_path: Path) -> None:
    cloud = surface_cloud(np.random.default_rng(7), 1000)
    front = torch_along(SEAMS[0])
    out = render_html(
        cloud,
        WELDMAP,
        views(),
        {"S_front": front},
        {"S_front": front[:, :3, 3]},
        tmp_path / "view.html",
        title="tiny T joint",
    )
    text = out.read_text(encoding="utf-8")
    assert out.stat().st_size > 1_000_000  # plotly.js is inline
    assert "plotly" in text.lower() and "Plotly.newPlot" in text
    assert 'src="https://cdn' not in text  # nothing fetched at view time
    for name in ("S_front", "seams not found", "seams not visible", "torch z axis", "tiny T joint"):
        assert name in text


def test_importing_preview_does_not_import_plotting_libraries() -> None:
    code = "import sys, cell.preview; print('matplotlib' in sys.modules or 'plotly' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
