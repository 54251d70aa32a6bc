"""The flat tee of the real scan cropped above its table (``shape2_T_0deg_cropped.pcd`` in ``../shared/real-scans/``
beside the repository, or ``$CELL_REAL_SCANS``; read there, never copied): no table is left in the cloud, so
``locate_cloud`` must recognise that, align the map on the tubes' own faces and locate the fillet the sensor saw.

Where the joint really is, is measured here from the scan alone, with no step of the pipeline (points in
hand-chosen boxes of the cloud's frame, planes refitted within 3 RMS): the long tube's seen side wall (1223 points)
is a plane; the cross tube's face beside the joint has only 57 points in a few scan lines 12 mm apart (its own
plane fit leans by 6 degrees), so it is taken square to that wall and to the tubes' top (a T of square tubes), at
the median of its points; the joint is where the two meet. The README says the tubes meet about 28 mm along the
cross tube from where the authors' CAD puts them; it gives no offset for that CAD, so ``maps/tee_flat.dxf`` draws
the long tube centred, and the scan puts it 17 mm towards one end of the cross tube (measured below from the cross
tube's seen side). The cell's answer to each drawing is asserted: the centred one aligns but leaves the seam
unfound, saying the cross tube's face runs on past where the drawing ends it by about that much (a deviation from the
drawing, not a hidden face), the drawing corrected to
the measured offset finds it on the measured line."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from tools_loader import load_tool

from cell.config.seams import PART_TOLERANCE_M
from cell.perception.align.drawn import past_drawn_edge
from cell.perception.cloud_files import read_cloud
from cell.pipeline import locate_cloud
from cell.types import Cloud, SeamStatus
from cell.weldmap import read_map

REPO = Path(__file__).resolve().parents[2]
SCAN = "shape2_T_0deg_cropped.pcd"
SEEN, HIDDEN = "LONG_TUBE>CROSS_TUBE:+y", "LONG_TUBE>CROSS_TUBE:-y"
# Hand-chosen boxes in the cloud's frame [mm] (x, y, z ranges), from a plot of the scan: the long tube's side wall
# facing +y (below its top edge), the cross tube's -x face beside the joint, and the cross tube's +x side.
WALL = ((-440.0, -180.0), (-664.0, -651.0), (8.0, 42.0))
FACE = ((-165.0, -142.0), (-652.0, -614.0), (8.0, 42.0))
CROSS_SIDE = ((-110.0, -95.0), (-730.0, -600.0), (8.0, 42.0))
TOP = ((-440.0, -180.0), (-695.0, -662.0), (44.0, 56.0))
HALF_MM = 25.4  # half a 2 in tube


def _box(P: np.ndarray, box: tuple[tuple[float, float], ...]) -> np.ndarray:
    keep = np.ones(len(P), dtype=bool)
    for k, (lo, hi) in enumerate(box):
        keep &= (P[:, k] >= lo) & (P[:, k] <= hi)
    return P[keep]


def _plane(P: np.ndarray) -> tuple[np.ndarray, float]:
    """Unit normal and offset of the least-squares plane of points (n, 3), refitted three times within 3 RMS."""
    keep = np.ones(len(P), dtype=bool)
    for _ in range(4):
        c = P[keep].mean(axis=0)
        n = np.linalg.svd(P[keep] - c, full_matrices=False)[2][2]
        r = (P - c) @ n
        keep = np.abs(r) < 3.0 * float(np.sqrt(np.mean(r[keep] ** 2)))
    return n, float(n @ c)


@pytest.fixture(scope="module")
def scan() -> tuple[Cloud, np.ndarray, np.ndarray, float]:
    """The cloud, the measured joint (a point and its direction, metres) and the cross tube's centre along y
    measured from the long tube's axis [mm]."""
    folder = Path(os.environ.get("CELL_REAL_SCANS", REPO.parent / "shared" / "real-scans"))
    if not (folder / SCAN).is_file():
        pytest.skip(f"the cropped real scan is not at {folder} (set $CELL_REAL_SCANS to its folder)")
    cloud = read_cloud(folder / SCAN, frame="base")
    P = np.asarray(cloud.points) * 1e3
    (n_a, d_a), (n_top, _) = _plane(_box(P, WALL)), _plane(_box(P, TOP))
    n_b = np.cross(n_a, n_top)
    n_b /= np.linalg.norm(n_b)
    d_b = float(np.median(_box(P, FACE) @ n_b))
    t = np.cross(n_a, n_b)
    t /= np.linalg.norm(t)
    p0 = np.linalg.solve(np.vstack([n_a, n_b, t]), [d_a, d_b, 25.0])
    side = _box(P, CROSS_SIDE)[:, 1]
    cross_centre = (float(np.percentile(side, 1)) + float(np.percentile(side, 99))) / 2.0
    wall_y = float(np.median(_box(P, WALL)[:, 1]))
    return cloud, p0 * 1e-3, t, cross_centre - (wall_y - HALF_MM)


def _lateral_mm(est_ends: np.ndarray, p0: np.ndarray, t: np.ndarray) -> float:
    d = est_ends - p0
    return float(np.max(np.linalg.norm(d - np.outer(d @ t, t), axis=1)) * 1e3)


def test_the_measured_joint_is_a_vertical_line_off_the_centre_of_the_cross_tube(scan: tuple) -> None:
    _, _, t, offset_mm = scan
    assert abs(float(t[2])) > 0.99  # the fillet is vertical (the tee lies flat)
    assert 12.0 < offset_mm < 22.0  # measured 16.8 mm: the long tube sits towards the cross tube's -y end


def test_with_no_table_the_drawing_corrected_to_the_measured_joint_finds_the_seen_fillet(
    scan: tuple, tmp_path: Path
) -> None:
    cloud, p0, t, offset_mm = scan
    make_maps = load_tool("make_maps")
    parts = dict(make_maps.TEE_FLAT_PARTS)
    (x0, y0, z0), (x1, y1, z1) = parts["CROSS_TUBE"]
    parts["CROSS_TUBE"] = ((x0, y0 + offset_mm, z0), (x1, y1 + offset_mm, z1))
    junctions = make_maps.TEE_FLAT_JUNCTIONS
    dxf = make_maps.write_map(
        tmp_path / "tee_as_built.dxf", parts, make_maps.design_seams("tee_flat", parts, junctions)
    )
    lines: list[str] = []
    det = locate_cloud(cloud, read_map(dxf), None, name="cropped", progress=lines.append)
    assert any(line.startswith("no table in the cloud") for line in lines), lines
    assert det.error is None
    est = {e.id: e for e in det.estimates}
    e = est[SEEN]
    assert e.status is SeamStatus.FOUND, e.reason
    ends = np.vstack([e.p_start, e.p_end])
    lateral = _lateral_mm(ends, p0, t)
    assert lateral < 1.0  # measured 0.47 mm from the measured joint
    assert 3e-3 < e.sigma_m < 6e-3  # 4.2 mm: the top's 2.2 mm noise and scan lines 12 mm apart, an honest sigma
    assert lateral < e.sigma_m * 1e3
    assert 45e-3 < float(np.linalg.norm(e.p_end - e.p_start)) < 56e-3  # the 50.8 mm wall, to the tubes' bottom
    # The other fillet is behind the long tube: its side wall has no point in the scan.
    assert est[HIDDEN].status is SeamStatus.NOT_FOUND and "LONG_TUBE -y" in est[HIDDEN].reason


def test_the_centred_drawing_aligns_and_its_seam_is_refused_as_a_deviation_from_the_drawing(scan: tuple) -> None:
    cloud, p0, t, offset_mm = scan
    det = locate_cloud(cloud, read_map(REPO / "maps" / "tee_flat.dxf"), None, name="cropped")
    assert det.error is None
    # The alignment lays the long tube on its faces: the drawing's joint line lies within a few mm of the measured
    # one (the cross tube, 17 mm off along its axis, pulls the fit a little).
    cad = det.weldmap_R.seam(SEEN)
    assert _lateral_mm(np.vstack([cad.p_start, cad.p_end]), p0, t) < 3.0  # measured 1.9 mm
    est = {e.id: e for e in det.estimates}
    # The drawing's face beside the joint is 17 mm narrower than the real one: too few of its points fall on it, and
    # the cell says why rather than put the seam where the drawing does: the face runs on past the drawn edge by
    # about the offset measured above (16 mm from the locator's view of it, 16.9 mm measured).
    for sid in (SEEN, HIDDEN):
        assert est[sid].status is SeamStatus.NOT_FOUND and est[sid].reason
    assert "does not lie as drawn" in est[SEEN].reason and "drawn" not in est[HIDDEN].reason
    past = past_drawn_edge(det.weldmap_R, "CROSS_TUBE", "-x", cad, np.asarray(cloud.points), PART_TOLERANCE_M)
    assert past is not None and abs(past.past_m * 1e3 - offset_mm) < 3.0
