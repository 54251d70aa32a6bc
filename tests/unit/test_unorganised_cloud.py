"""The unorganised-cloud steps of ``cell locate`` on a synthetic scan of the tee: a tilted, perforated table found
from the data with its noise, normals oriented without a view direction, and the map found with no placement."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cloud_writers import seen_faces

from cell.geometry import FloatArray, make_pose, rpy_to_matrix, transform_points
from cell.perception.unorganised import find_table, levelling, orient_normals, sampling
from cell.pipeline import locate_cloud
from cell.types import Cloud, SeamStatus, WeldMap
from cell.weldmap import read_map

MAP = Path(__file__).resolve().parents[2] / "maps" / "tee.dxf"
TILT = math.radians(1.0)
TOP_Z = -0.005
NOISE = 0.0012


def _table(rng: np.random.Generator) -> FloatArray:
    """A 0.6 x 0.6 m table top, tilted 1 deg about x, at z = -5 mm at the origin, with 20 mm holes on a 50 mm
    grid, scanned in lines 5 mm apart with 1 mm between points along them."""
    x, y = np.meshgrid(np.arange(-0.3, 0.3, 0.001), np.arange(-0.9, -0.3, 0.005))
    x, y = x.ravel(), y.ravel()
    hole = (np.abs((x + 0.025) % 0.05 - 0.025) < 0.01) & (np.abs((y + 0.025) % 0.05 - 0.025) < 0.01)
    x, y = x[~hole], y[~hole]
    z = TOP_Z + math.tan(TILT) * (y + 0.6) + rng.normal(0.0, NOISE, len(x))
    return np.column_stack([x, y, z])


def _part(weldmap: WeldMap, X_FM: FloatArray, rng: np.random.Generator) -> FloatArray:
    """The tee's faces seen from above and from -y (the others in shadow), 2.5 mm samples, with noise."""
    P = transform_points(X_FM, seen_faces(weldmap, 0.0025))
    return P + rng.normal(0.0, NOISE, P.shape)


@pytest.fixture(scope="module")
def scan() -> tuple[WeldMap, FloatArray, FloatArray]:
    rng = np.random.default_rng(7)
    weldmap = read_map(MAP)
    X_FM = make_pose(rpy_to_matrix((TILT, 0.0, math.radians(10.0))), (0.02, -0.6, 0.0254 + TOP_Z))
    return weldmap, X_FM, np.vstack([_table(rng), _part(weldmap, X_FM, rng)])


def test_the_tilted_table_and_its_noise_are_found_from_the_data(scan: tuple[WeldMap, FloatArray, FloatArray]) -> None:
    _, _, P = scan
    table = find_table(P, np.random.default_rng(0))
    assert math.degrees(table.tilt_rad) == pytest.approx(1.0, abs=0.1)
    assert float(table.height(np.array([[0.0, -0.6, TOP_Z]]))[0]) == pytest.approx(0.0, abs=5e-4)
    assert table.sigma_m == pytest.approx(NOISE, rel=0.15)
    X_LF = levelling(table)
    np.testing.assert_allclose(X_LF[:3, :3] @ table.normal, [0.0, 0.0, 1.0], atol=1e-9)
    along, between = sampling(transform_points(X_LF, P), table)
    assert along == pytest.approx(0.001, rel=0.35) and between == pytest.approx(0.005, rel=0.35)


def test_normals_point_up_on_flat_faces_and_outwards_on_steep_ones() -> None:
    P = np.array([[0.0, 0.0, 0.1], [0.1, 0.0, 0.05], [-0.1, 0.0, 0.05]])
    n = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    np.testing.assert_allclose(orient_normals(n, P), [[0, 0, 1], [1, 0, 0], [-1, 0, 0]])
    np.testing.assert_allclose(orient_normals(n, P, viewpoint=np.array([0.0, 0.0, -1.0]))[0], [0, 0, -1])


def test_global_registration_recovers_a_part_far_from_any_placement(
    scan: tuple[WeldMap, FloatArray, FloatArray],
) -> None:
    weldmap, X_FM, P = scan
    # A placement 20 cm and 30 deg off: the ICP from it fails, the global registration finds the part.
    off = make_pose(rpy_to_matrix((0.0, 0.0, math.radians(30.0))), (0.2, 0.0, 0.0)) @ X_FM
    det = locate_cloud(Cloud(P, "F"), weldmap, off, name="synthetic")
    assert det.error is None
    X = det.scenario.X_WM
    assert np.linalg.norm(X[:3, 3] - X_FM[:3, 3]) < 0.003
    assert math.degrees(math.atan2(X[1, 0], X[0, 0])) == pytest.approx(10.0, abs=0.5)
    assert [e.status for e in det.estimates].count(SeamStatus.FOUND) >= 1, [e.reason for e in det.estimates]


def test_a_table_with_no_part_on_it_gives_reasons_not_seams() -> None:
    P = _table(np.random.default_rng(2))
    weldmap = read_map(MAP)
    for X0 in (None, make_pose(p=(0.0, -0.6, 0.0254 + TOP_Z))):
        det = locate_cloud(Cloud(P, "F"), weldmap, X0, name="bare")
        assert det.error is not None
        assert all(e.status is SeamStatus.NOT_FOUND and e.reason for e in det.estimates)
