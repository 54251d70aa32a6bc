"""What a brought cloud's parts stand on (cell/perception/ground.py): a synthetic scan of the flat tee with its table
is recognised as having one, the same scan cropped 5 mm above the table (as people crop scans) as having none, and
``locate_cloud`` aligns the tee on its own faces and finds its seen fillet in the cropped one."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cloud_writers import seen_faces

from cell.geometry import FloatArray, make_pose, rpy_to_matrix, transform_points
from cell.perception.ground import TableSource, find_ground
from cell.pipeline import locate_cloud
from cell.types import Cloud, SeamStatus, WeldMap
from cell.weldmap import read_map

MAP = Path(__file__).resolve().parents[2] / "maps" / "tee_flat.dxf"
NOISE = 0.001
CROP_M = 0.005


def _scan(weldmap: WeldMap, X_FM: FloatArray, rng: np.random.Generator) -> FloatArray:
    """A 0.7 x 0.5 m table at z = 0 (3 mm grid) and the tee's faces seen from above and from +y, with noise."""
    x, y = np.meshgrid(np.arange(-0.2, 0.5, 0.003), np.arange(-0.25, 0.25, 0.003))
    table = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    faces_M = seen_faces(weldmap, 0.0025)
    P_F = transform_points(X_FM, faces_M[faces_M[:, 2] > 1e-4])
    under = np.any([part.contains(table, 0.0) for part in weldmap.transformed(X_FM, "F").parts], axis=0)
    P = np.vstack([table[~under], P_F])
    return P + rng.normal(0.0, NOISE, P.shape)


@pytest.fixture(scope="module")
def scans() -> tuple[WeldMap, FloatArray, FloatArray, FloatArray]:
    """The map, its true pose in F, the scan with its table, the scan cropped above the table."""
    weldmap = read_map(MAP)
    X_FM = make_pose(rpy_to_matrix((0.0, 0.0, math.radians(8.0))), (-0.05, -0.02, 0.0))
    P = _scan(weldmap, X_FM, np.random.default_rng(3))
    return weldmap, X_FM, P, P[P[:, 2] >= CROP_M]


def test_a_table_is_found_under_the_parts_and_none_in_a_cloud_cropped_above_it(scans: tuple) -> None:
    _, _, P, cropped = scans
    with_table = find_ground(P, np.random.default_rng(0))
    assert with_table.source is TableSource.FOUND and with_table.has_table
    assert abs(with_table.plane.offset) < 1e-3 and with_table.below_share < 0.01
    without = find_ground(cropped, np.random.default_rng(0))
    # Its largest upward plane is the tubes' top, 50.8 mm up, with their walls under it.
    assert without.source is TableSource.ABSENT and not without.has_table
    assert without.plane.offset == pytest.approx(0.0508, abs=2e-3)
    assert without.below_share > 0.2


def test_a_stated_table_or_none_wins_over_the_data(scans: tuple) -> None:
    _, _, P, cropped = scans
    given = find_ground(cropped, np.random.default_rng(0), table_z_m=0.0)
    assert given.source is TableSource.GIVEN and given.given_z_m == 0.0 and given.has_table
    assert find_ground(P, np.random.default_rng(0), no_table=True).source is TableSource.ABSENT


def test_the_tee_cropped_above_its_table_is_aligned_on_its_own_faces(scans: tuple) -> None:
    weldmap, X_FM, _, cropped = scans
    for options in ({}, {"no_table": True}, {"table_z_m": 0.0}):
        det = locate_cloud(Cloud(cropped, "F"), weldmap, None, name="cropped", **options)  # type: ignore[arg-type]
        assert det.error is None, options
        X = det.scenario.X_WM
        assert np.linalg.norm(X[:3, 3] - X_FM[:3, 3]) < 5e-4, options  # measured 0.07-0.14 mm
        est = {e.id: e for e in det.estimates}
        seen = est["LONG_TUBE>CROSS_TUBE:+y"]
        assert seen.status is SeamStatus.FOUND, (options, seen.reason)
        true = transform_points(X_FM, np.vstack([weldmap.seam(seen.id).p_start, weldmap.seam(seen.id).p_end]))
        assert np.linalg.norm(seen.p_start[:2] - true[0, :2]) < 5e-4, options  # across it: 0.04-0.23 mm
        # Its other fillet faces away from the sensor: not seen, not found.
        assert est["LONG_TUBE>CROSS_TUBE:-y"].status is not SeamStatus.FOUND
