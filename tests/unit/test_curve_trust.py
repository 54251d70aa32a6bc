"""What the curved-seam locator must not trust: a hollow tube's bore seen down its open end, a faceted round fitted
as a circle, cameras that disagree, and their calibration (docs/curves.md section 2)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from test_curve_locator import NOISE_M, _cloud, _tube_on_plate

from cell.perception.calibration import curve_calibration_sigma
from cell.perception.splicing.pose_prior import PoseUncertainty
from cell.seams.curved.fit import fit_surface
from cell.seams.curved.locate import locate_curve
from cell.seams.curved.metrics import distances_to_polyline
from cell.seams.curved.surfaces import CylinderModel, PlaneModel
from cell.types import Cloud, Cylinder, SeamScene, SeamStatus


def _prism(r_face: float, facets: int, rng: np.random.Generator, n: int = 4000) -> np.ndarray:
    """Points on the flat facets of a prism about +z whose facets' middles lie at ``r_face`` [m], with noise."""
    k = rng.integers(0, facets, n)
    half = r_face * math.tan(math.pi / facets)
    phi = 2.0 * math.pi * k / facets
    t, z = rng.uniform(-half, half, n), rng.uniform(0.0, 0.1, n)
    r = r_face + rng.normal(0.0, NOISE_M, n)
    x, y = r * np.cos(phi) - t * np.sin(phi), r * np.sin(phi) + t * np.cos(phi)
    return np.column_stack([x, y, z])


def test_a_faceted_round_shows_as_lack_of_fit_and_a_round_does_not() -> None:
    rng = np.random.default_rng(1)
    ref = CylinderModel(np.zeros(3), np.array([0.0, 0.0, 1.0]), 0.06)
    faceted = fit_surface(ref, _prism(0.06, 12, rng), 60)
    t = rng.uniform(-math.pi, math.pi, 4000)
    r = 0.06 + rng.normal(0.0, NOISE_M, 4000)
    round_ = fit_surface(ref, np.column_stack([r * np.cos(t), r * np.sin(t), rng.uniform(0.0, 0.1, 4000)]), 60)
    sagitta = 0.06 / math.cos(math.pi / 12) - 0.06  # 2.1 mm from corner to facet
    assert faceted.lack_m > 0.2 * sagitta and round_.lack_m < 0.05 * sagitta


def test_cameras_that_disagree_show_their_spread() -> None:
    rng = np.random.default_rng(2)
    ref = PlaneModel(np.zeros(3), np.array([0.0, 0.0, 1.0]))
    xy = rng.uniform(-0.05, 0.05, (3000, 2))
    cams = rng.integers(0, 2, 3000)
    z = rng.normal(0.0, NOISE_M, 3000)
    fit = fit_surface(ref, np.column_stack([xy, z + 0.001 * cams]), 60, groups=cams)  # the second 1 mm up
    same = fit_surface(ref, np.column_stack([xy, z]), 60, groups=cams)
    assert 0.0006 < fit.cameras_m < 0.0008 and same.cameras_m < 0.0001


def test_the_bore_seen_down_the_open_end_is_not_the_outer_round(tmp_path: Path) -> None:
    wm = _tube_on_plate(tmp_path, 0.0)
    [seam] = wm.curved
    c = wm.part("TUBE").cylinder
    assert c is not None
    rng = np.random.default_rng(4)
    # The part as built stands 2 mm off the map along x; the camera looks down from -x and sees, through the open
    # top, the bore's far wall (26.15 mm about the true axis: within 3 mm of the map's outer round there).
    true = Cylinder(np.asarray(c.p_base) + np.array([0.002, 0.0, 0.0]), np.asarray(c.axis), c.radius, c.length)
    outer = _cloud(true, rng, 0.5)
    outer = outer[outer[:, 0] < 0.002 + 0.3 * c.radius]  # the outer round seen from -x only, and the plate
    t, z = rng.uniform(-0.6, 0.6, 3000), rng.uniform(0.09, 0.2, 3000)
    bore = np.column_stack([0.002 + 0.02615 * np.cos(t), 0.02615 * np.sin(t), z])
    points = np.vstack([outer, bore])
    camera = np.zeros(len(points), np.int16)
    cloud = Cloud(points, "M", camera, ("cam",))
    eye = {"cam": np.array([-0.6, 0.0, 0.6])}
    truth = seam.sample(0.0002) + np.array([0.002, 0.0, 0.0])
    est = locate_curve(SeamScene(cloud, cloud, wm, {}, 0.0, eyes_R=eye), seam)
    assert est.status is SeamStatus.FOUND, est.reason
    d = distances_to_polyline(np.asarray(est.p_RS), truth, True)
    assert float(d.max()) < 0.0006 and float(np.mean(d <= 2.0 * np.asarray(est.sigma_m))) >= 0.95


def test_a_curve_carries_its_cameras_calibration() -> None:
    rng = np.random.default_rng(5)
    p = rng.uniform(-0.05, 0.05, (2000, 3))
    cloud = Cloud(p, "R", (p[:, 0] > 0).astype(np.int16), ("a", "b"))
    curve = np.column_stack([np.linspace(0.02, 0.04, 30), np.zeros(30), np.zeros(30)])  # where only b sees
    u = {"a": PoseUncertainty(0.003, 0.0), "b": PoseUncertainty(0.001, 0.0)}
    sigma = curve_calibration_sigma(cloud, curve, {"a": np.zeros(3), "b": np.ones(3)}, u, ())
    assert math.isclose(sigma, math.sqrt(2.0) * 0.001 / math.sqrt(3.0), rel_tol=1e-9)
    none = {k: PoseUncertainty(0.0, 0.0) for k in u}
    assert curve_calibration_sigma(cloud, curve, {"a": np.zeros(3), "b": np.ones(3)}, none, ()) == 0.0
