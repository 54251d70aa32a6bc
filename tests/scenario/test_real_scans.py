"""The tee's fillets in the three real laser scans (``../shared/real-scans/`` beside the repository, or
``$CELL_REAL_SCANS``; read there, never copied): from the README's nominal placement, the fillet the sensor sees is
found with a sigma that covers its distance from a line fitted independently from the scan
(``benchmarks/bench_real_scans.py``, which also measures it), and the one behind the vertical tube is not."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from cell.pipeline import locate_cloud
from cell.types import SeamStatus
from cell.weldmap import read_map

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location("bench_real_scans", REPO / "benchmarks" / "bench_real_scans.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    folder = module.scans_dir()
    if not all((folder / f).is_file() for f, *_ in module.SCANS.values()):
        pytest.skip(f"the real scans are not at {folder} (set $CELL_REAL_SCANS to their folder)")
    return module


@pytest.mark.parametrize(
    ("stem", "offset"),
    [
        ("x0y24", (0.0, 0.0, 0.0)),
        ("x0y24", (-10.0, 0.0, -1.0)),  # 1 cm and 1 deg further off (the sparse wall's seam was once lost so)
        ("x4y24_45", (0.0, 0.0, 180.0)),  # turned round: the ICP alone settled there, the seams' ids swapped
        ("x4y24_45", (0.0, 0.0, 0.0)),
        ("longclamps_x4y24_45", (0.0, 0.0, 0.0)),
    ],
)
def test_the_seen_fillet_is_found_within_its_sigma_and_the_hidden_one_is_not(
    bench: Any, stem: str, offset: tuple[float, float, float]
) -> None:
    file, origin, yaw, seen = bench.SCANS[stem]
    cloud = bench.read_scan(bench.scans_dir() / file)
    X_FM = bench.nominal(origin, yaw)
    dx, dy, dyaw = offset
    X_place = bench.nominal((origin[0] + dx, origin[1] + dy, origin[2]), yaw + dyaw)
    det = locate_cloud(cloud, read_map(bench.MAP), X_place, name=stem)
    assert det.error is None
    est = {e.id: e for e in det.estimates}
    e = est[seen]
    assert e.status is SeamStatus.FOUND, e.reason
    # A 1.2 mm-noise scan with lines ~4 mm apart: a sigma of 1.6 mm (measured), never the D415's 0.05 mm.
    assert 1.2e-3 < e.sigma_m < 2.2e-3
    line = bench.independent_line(np.asarray(cloud.points), X_FM, 1.0 if seen.endswith("+x") else -1.0)
    lateral_mm = bench.lateral_mm(np.vstack([e.p_start, e.p_end]), line["p0"], line["t"])
    assert lateral_mm < 2.0 * e.sigma_m * 1e3  # measured 0.83-1.36 mm
    assert 45e-3 < float(np.linalg.norm(e.p_end - e.p_start)) < 56e-3  # the 50.8 mm wall
    (hidden,) = (k for k in est if k != seen)
    assert est[hidden].status in (SeamStatus.NOT_FOUND, SeamStatus.OCCLUDED)
    assert est[hidden].reason
    # The located seam stays within 1 mm of the drawing as the alignment placed it (measured 0.12-0.36 mm).
    cad = det.weldmap_R.seam(seen)
    assert bench.lateral_mm(np.vstack([e.p_start, e.p_end]), cad.p_start, cad.direction) < 1.0
