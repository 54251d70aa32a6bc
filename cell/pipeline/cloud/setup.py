"""What :func:`cell.pipeline.cloud.locate_cloud` derives from a brought cloud before it looks for seams: the options
that fit the data (its noise and density, not the D415's constants) and the scenario that stands for the cell the
cloud came from, so that the usual report describes the run (docs/locate.md, "From the cloud to the seams")."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from cell.geometry import FloatArray, make_pose, matrix_to_rpy, transform_points
from cell.perception.align.cloud import FRAME, crop_bounds
from cell.perception.unorganised import TablePlane
from cell.scenario import Scenario
from cell.types import WeldMap

ALIGN_NOISE_SIGMAS = 20.0  # the ICP's largest correspondence, in noise sigmas (at least the default 20 mm)
# The sigma floor's parts [-]: the noise of one scan line (each line is a rigid arm pose: its error does not
# average out along it) and the spacing between lines across the seam (where the corner falls between two lines).
FLOOR_NOISE_SHARE = 1.0
FLOOR_SPACING_SHARE = 1.0 / math.sqrt(12.0)  # RMS of a uniform position within one spacing
# A part's top half covered is a map placed half off the cloud for a depth camera over solid boxes; a real tube is
# open at its ends, and its top shows only its rim (the scans' vertical tube: 37-46 % of its top within 1 cm).
MIN_SEEN = 0.3
NO_EDGES = 10**9  # min_edge_points that no edge reaches: a weld face must be seen
# The locator's tube about the seam holds this many scan lines across (within 60..150 mm): 60 mm (the default, for
# a depth camera's 1-2 mm pitch) held 14-30 points of the scans' grazing wall (x0y24), its seam found or refused by a
# hair as the placement moved by 1 cm; 100 mm (28 lines of 3.6 mm) finds it from every placement tried.
TUBE_LINES = 28.0
MIN_FACE_AREA_M2 = 30e-6  # a weld face is seen with the points of 30 mm^2 of it (the default 30 at a 1 mm pitch)


def sigma_floor(noise_m: float, between_m: float) -> float:
    """The floor of a found seam's sigma [m] in such a cloud: the noise of one scan line and the RMS position of
    the corner within the spacing between lines, in quadrature (``FLOOR_*``).

    Why a floor this size: the locator's own statistical error (a biweight fit of hundreds to thousands of points)
    is 0.05-0.12 mm on the real scans, but the seams it finds lie 0.83-1.36 mm from a line fitted independently
    from the same scans (benchmarks/bench_real_scans.py): what the fit cannot see (each scan line is one arm pose
    whose error does not average out along it, the corner falls between lines 3.6 mm apart, the tubes are not
    the drawing's boxes) dominates. With the scans' 1.2 mm noise and 3.6 mm spacing the floor is 1.6 mm: their
    three seams lie within 1 sigma of the independent line (within 2 sigma is what a calibrated sigma promises
    for 95 %); on a synthetic scan of the tee with the same noise and spacing but no systematic error the errors
    against the truth are 0.03-0.13 mm, so the floor is conservative there. Three real seams calibrate nothing
    finely: the floor is a model of the sensor's systematics, checked, not fitted."""
    spacing = between_m if math.isfinite(between_m) else 0.0
    return math.hypot(FLOOR_NOISE_SHARE * noise_m, FLOOR_SPACING_SHARE * spacing)


def min_face_points(along_m: float, between_m: float) -> int:
    """The fewest points that make a weld face seen in a cloud of this spacing [m]: those of MIN_FACE_AREA_M2 at
    its density (a sparse line scan has a third of the points a 1 mm grid would), within 8..30 (the default)."""
    if not (math.isfinite(along_m) and math.isfinite(between_m)) or along_m * between_m <= 0.0:
        return 30
    return int(min(30, max(8, math.ceil(MIN_FACE_AREA_M2 / (along_m * between_m)))))


def ours_overrides(noise_m: float, along_m: float, between_m: float) -> dict[str, Any]:
    """Our locator's options for a cloud of this noise and point spacing along / between lines [m] (module
    docstring)."""
    floor = float(sigma_floor(noise_m, between_m))
    tube = min(0.15, max(0.06, TUBE_LINES * between_m)) if math.isfinite(between_m) else 0.06
    return {
        "tube_radius_m": float(tube),
        "sensor_sigma_m": float(max(noise_m, 2e-4)),
        "min_face_points": min_face_points(along_m, between_m),
        "sample_share": 1.0,
        "min_edge_points": NO_EDGES,
        "sigma_floor_m": floor,
        "target_se_m": floor,
    }


def _pose(X: FloatArray) -> dict[str, list[float]]:
    rpy = np.degrees(matrix_to_rpy(X[:3, :3]))
    return {"xyz_m": [float(v) for v in X[:3, 3]], "rpy_deg": [float(v) for v in rpy]}


def cloud_scenario(
    name: str,
    weldmap: WeldMap,
    X_FM: FloatArray,
    workspace_F: tuple[FloatArray, FloatArray],
    table_F: tuple[FloatArray, tuple[float, float, float]],
    eye_F: FloatArray,
    noise_m: float,
) -> Scenario:
    """The scenario that describes a run on a brought cloud: the world is the cloud's frame F (the robot base at
    its origin, no arm model), the map at ``X_FM`` (4, 4) [m], the workspace ``workspace_F`` (lo, hi) (3,) that the
    cloud was cropped to, the table ``table_F`` (centre, size) (3,) found in the data, one fixed "sensor" at
    ``eye_F`` (3,) looking at the part (the cloud's, for the record: nothing is rendered), no simulation.
    ``noise_m`` goes into the map-to-cloud ICP's settings (module docstring)."""
    lo, hi = (np.asarray(v, dtype=np.float64) for v in workspace_F)
    target = (X_FM @ np.array([*np.mean([p.center for p in weldmap.parts], axis=0), 1.0]))[:3]
    eye = np.asarray(eye_F, dtype=np.float64)
    if np.linalg.norm(eye - target) < 0.1:
        eye = target + np.array([0.0, 0.0, 1.0])
    source = weldmap.source
    data: dict[str, Any] = {
        "name": name,
        "description": f"a brought point cloud ({name}) against {Path(source).name}",
        "seed": 0,
        "map": {"file": source, "units": weldmap.units, "X_WM": _pose(X_FM)},
        "table": {"center_m": [float(v) for v in table_F[0]], "size_m": [float(max(v, 1e-3)) for v in table_F[1]]},
        "cameras": {"sensor": {"eye_m": [float(v) for v in eye], "target_m": [float(v) for v in target]}},
        "perception": {
            "workspace": {"min_m": [float(v) for v in lo], "max_m": [float(v) for v in hi]},
            "align_max_correspondence_m": float(max(0.02, ALIGN_NOISE_SIGMAS * noise_m)),
            "coverage": {"min_seen": MIN_SEEN},
        },
        "simulation": {"noise": "none"},
        "base_dir": str(Path(source).parent) if source else ".",
    }
    return Scenario.model_validate(data)


def scenario_for(
    name: str,
    weldmap: WeldMap,
    X_FL: FloatArray,
    X_LM: FloatArray | None,
    P_L: FloatArray,
    above: np.ndarray,
    ground: tuple[TablePlane, float],
    viewpoint_L: FloatArray | None,
    measured: tuple[float, float, float],
    method: str,
) -> Scenario:
    """The scenario of a run on a brought cloud (:func:`cloud_scenario`) from what was measured in the levelled
    frame L: the map at ``X_LM`` (None: at the points' median), the crop about it (:func:`crop_bounds`, from the
    table up), the largest upward plane (its inliers) and the table's height in L (``ground``), the viewpoint;
    X_FL (4, 4) carries them into F. With the options from the
    data's ``measured`` noise and spacing along and between lines [m]."""
    from cell.seams.registry import with_method, with_options

    X = X_LM if X_LM is not None else make_pose(p=np.median(P_L[above] if above.any() else P_L, axis=0))
    map_L = weldmap.transformed(X, FRAME)
    corners_L = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    lo, hi = crop_bounds(map_L)
    table, top = ground
    lo[2] = max(float(lo[2]), top)  # the table itself is cut away
    box_F = transform_points(X_FL, lo + corners_L * (hi - lo))
    T = P_L[table.inliers]
    t_lo, t_hi = T.min(axis=0), T.max(axis=0)
    centre_F = transform_points(X_FL, np.array([[(t_lo[0] + t_hi[0]) / 2, (t_lo[1] + t_hi[1]) / 2, top - 0.05]]))[0]
    size = (float(t_hi[0] - t_lo[0]), float(t_hi[1] - t_lo[1]), 0.1)
    eye_L = viewpoint_L if viewpoint_L is not None else (lo + hi) / 2.0 + np.array([0.0, 0.0, 1.0])
    eye_F = transform_points(X_FL, np.reshape(eye_L, (1, 3)))[0]
    noise, along, between = measured
    workspace_F = (box_F.min(axis=0), box_F.max(axis=0))
    sc = cloud_scenario(name, weldmap, X_FL @ X, workspace_F, (centre_F, size), eye_F, noise)
    sc = with_method(sc, method)
    return with_options(sc, "ours", ours_overrides(noise, along, between)) if method == "ours" else sc
