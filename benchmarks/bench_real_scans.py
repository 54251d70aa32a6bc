"""The tee's fillets located in the three real laser scans, against the CAD placed by the alignment and against a
line fitted independently from each scan.

    .venv/bin/python benchmarks/bench_real_scans.py [--scans DIR] [--json PATH] [--pictures DIR]

The scans (``../shared/real-scans/`` beside the repository, or ``$CELL_REAL_SCANS``; GPL-3.0 data, read there, never
copied) are an RPLiDAR line scanner swept by an arm over a tee of two 2 in square tubes on a perforated table; the
map is ``maps/tee.dxf`` (drawn from the README's CAD sizes), the nominal placements are the README's. Per scan:
:func:`cell.pipeline.locate_cloud` from the nominal placement, then for the fillet the sensor sees:

- error against the CAD: the located seam against the map's seam as the alignment placed it (how far the locator
  moved off the aligned drawing: the part's real shape and what the ICP averages away);
- error against an independent line: two planes fitted to the points in hand-chosen boxes about the seam
  (:data:`BOXES`, in the drawing's frame at the README's nominal placement: the vertical wall from 5 to 175 mm
  above the top face, the top face from 8 to 60 mm beyond the wall, both within 18 mm of the seam's middle
  across; a RANSAC plane, 3 mm band, then least squares refitted to the points within 3 RMS: clamps and table
  holes fall out), intersected; no step of the cell's pipeline is used for it. Lateral: the largest distance of
  the located ends from that line, across it; along: the located ends against where face A's points along the
  line end (rough: one end is often shadowed);
- the hidden fillet's status and reason (it must not be found);
- the same from placements up to 2.8 cm and 3 degrees off the README's, and turned by 90 and 180 degrees
  (:data:`OFFSETS`): how often the seen fillet is found and how far it moves, and with no placement at all (the
  global registration).

Results to ``--json`` (default ``benchmarks/results/real_scans.json``), a picture per scan (the points in a slab
about the seam, seen along it, with the located seam, the independent line and the aligned CAD's seam) to
``--pictures`` (default ``benchmarks/results/real_scans/``).
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cell.export.reports.report import write_json
from cell.geometry import FloatArray, invert, make_pose, rpy_to_matrix, transform_points
from cell.pipeline import locate_cloud
from cell.types import Cloud, SeamStatus
from cell.weldmap import read_map

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
MAP = ROOT / "maps" / "tee.dxf"
# file stem -> (file, nominal CAD origin [mm], yaw [deg], the seen fillet's id) from the scans' README.
SCANS: dict[str, tuple[str, tuple[float, float, float], float, str]] = {
    "x0y24": ("table_8in10in_tee_x0y24.pcd", (0.0, -609.6, 25.4), 0.0, "V_TUBE>H_TUBE:-x"),
    "x4y24_45": ("table_8in10in_tee_x4y24_45.pcd", (101.6, -609.6, 25.4), 45.0, "V_TUBE>H_TUBE:+x"),
    "longclamps_x4y24_45": (
        "table_8in10in_tee_longclamps_x4y24_45.pcd",
        (101.6, -609.6, 25.4),
        45.0,
        "V_TUBE>H_TUBE:+x",
    ),
}
# Hand-chosen boxes about a fillet at x = s * 25.4 mm (s the side), drawing frame at the nominal placement [mm]:
# face name -> (x range outward from the wall, y range, z range); wide enough for a part 1 cm off its placement.
BOXES = {"wall": ((-14.0, 14.0), (-18.0, 18.0), (30.0, 200.0)), "top": ((8.0, 60.0), (-18.0, 18.0), (12.0, 32.0))}
PLANE_BAND_MM = 3.0  # a plane's RANSAC inliers, before the least-squares refits
WALL_X_MM = 25.4
SLAB_M = 0.03  # the pictures show the points of a slab this thick about the seam's middle (the y walls: 25 mm)
# Placements tried about the README's (dx, dy [mm], dyaw [deg]): the alignment must absorb them.
OFFSETS = (
    (10.0, 0.0, 1.0),
    (-10.0, 0.0, -1.0),
    (0.0, 10.0, -1.0),
    (0.0, -10.0, 1.0),
    (-15.0, 10.0, -2.0),
    (20.0, -20.0, 3.0),
    (0.0, 0.0, 90.0),
    (0.0, 0.0, 180.0),
)


def scans_dir() -> Path:
    """Where the scans are: ``$CELL_REAL_SCANS`` or ``../shared/real-scans`` beside the repository."""
    return Path(os.environ.get("CELL_REAL_SCANS", ROOT.parent / "shared" / "real-scans"))


def read_scan(path: Path) -> Cloud:
    """The scan's points (metres, the robot base frame, named ``base``), read as ``cell locate`` reads them."""
    from cell.perception.cloud_files import read_cloud

    return read_cloud(path, frame="base")


def nominal(origin_mm: tuple[float, float, float], yaw_deg: float) -> FloatArray:
    """X_FM (4, 4) of the README's nominal placement."""
    return make_pose(rpy_to_matrix((0.0, 0.0, math.radians(yaw_deg))), np.array(origin_mm) / 1000.0)


def _plane(P: FloatArray, rng: np.random.Generator) -> tuple[FloatArray, float, float]:
    """Plane (unit normal, offset, RMS) of points (n, 3) [m]: the best of 500 three-point hypotheses (most points
    within PLANE_BAND_MM), then least squares refitted three times to the points within 3 RMS."""
    best = np.zeros(len(P), dtype=bool)
    for _ in range(500):
        a, b, c = P[rng.choice(len(P), 3, replace=False)]
        n = np.cross(b - a, c - a)
        if np.linalg.norm(n) < 1e-12:
            continue
        n /= np.linalg.norm(n)
        inl = np.abs((P - a) @ n) < PLANE_BAND_MM / 1000.0
        if inl.sum() > best.sum():
            best = inl
    keep = best
    for _ in range(3):
        c = P[keep].mean(axis=0)
        n = np.linalg.svd(P[keep] - c, full_matrices=False)[2][2]
        r = (P - c) @ n
        rms = float(np.sqrt(np.mean(r[keep] ** 2)))
        keep = np.abs(r) < 3.0 * rms
    return n, float(n @ c), rms


def independent_line(P_F: FloatArray, X_FM: FloatArray, side: float) -> dict[str, Any]:
    """The fillet at x = side * 25.4 mm from two planes fitted to the points in :data:`BOXES` (frame F, metres)."""
    Q = transform_points(invert(X_FM), P_F) * 1000.0  # drawing frame at the nominal placement [mm]
    faces = {}
    for name, (xr, yr, zr) in BOXES.items():
        u = side * Q[:, 0] - WALL_X_MM  # outward from the wall
        sel = (xr[0] <= u) & (u <= xr[1]) & (yr[0] <= Q[:, 1]) & (Q[:, 1] <= yr[1]) & (zr[0] <= Q[:, 2])
        sel &= Q[:, 2] <= zr[1]
        faces[name] = P_F[sel]
    rng = np.random.default_rng(0)
    (n_a, d_a, rms_a), (n_b, d_b, rms_b) = (_plane(faces[k], rng) for k in ("wall", "top"))
    t = np.cross(n_a, n_b)
    t /= np.linalg.norm(t)
    A = np.vstack([n_a, n_b, t])
    centre = transform_points(X_FM, np.array([[side * WALL_X_MM / 1000.0, 0.0, WALL_X_MM / 1000.0]]))[0]
    p0 = np.linalg.solve(A, [d_a, d_b, float(t @ centre)])
    s = (faces["wall"] - p0) @ t
    return {
        "p0": p0,
        "t": t,
        "extent": (float(s.min()), float(s.max())),
        "points": {k: len(v) for k, v in faces.items()},
        "rms_mm": {"wall": rms_a * 1e3, "top": rms_b * 1e3},
        "angle_deg": math.degrees(math.acos(min(1.0, abs(float(n_a @ n_b))))),
    }


def lateral_mm(ends: FloatArray, p0: FloatArray, t: FloatArray) -> float:
    """Largest distance [mm] of points (k, 3) from the line p0 + s t, across it."""
    d = ends - p0
    return float(np.max(np.linalg.norm(d - np.outer(d @ t, t), axis=1)) * 1e3)


def run_scan(stem: str, folder: Path, pictures: Path | None) -> dict[str, Any]:
    """One scan's row (see the module docstring)."""
    file, origin, yaw, seen = SCANS[stem]
    cloud = read_scan(folder / file)
    X_FM = nominal(origin, yaw)
    weldmap = read_map(MAP)
    det = locate_cloud(cloud, weldmap, X_FM, name=stem)
    row: dict[str, Any] = {"scan": stem, "points": len(cloud), "seen": seen, "error": str(det.error or "") or None}
    est = {e.id: e for e in det.estimates}
    for e in det.estimates:
        row[e.id] = {"status": e.status.value, "reason": e.reason}
    side = 1.0 if seen.endswith("+x") else -1.0
    ind = independent_line(np.asarray(cloud.points), X_FM, side)
    row["independent"] = {
        "points": ind["points"],
        "plane_rms_mm": {k: round(v, 3) for k, v in ind["rms_mm"].items()},
        "angle_deg": round(ind["angle_deg"], 2),
    }
    e = est[seen]
    cad = det.weldmap_R.seam(seen)
    if e.status is SeamStatus.FOUND:
        ends = np.vstack([e.p_start, e.p_end])
        s = np.sort((ends - ind["p0"]) @ ind["t"])
        row["found"] = {
            "start_mm": [round(float(v) * 1e3, 2) for v in e.p_start],
            "end_mm": [round(float(v) * 1e3, 2) for v in e.p_end],
            "sigma_mm": round(e.sigma_m * 1e3, 3),
            "confidence": round(e.confidence, 3),
            "lateral_vs_independent_mm": round(lateral_mm(ends, ind["p0"], ind["t"]), 3),
            "along_vs_independent_mm": [
                round((s[0] - ind["extent"][0]) * 1e3, 2),
                round((s[1] - ind["extent"][1]) * 1e3, 2),
            ],
            "lateral_vs_cad_mm": round(lateral_mm(ends, cad.p_start, cad.direction), 3),
            "cad_vs_independent_mm": round(lateral_mm(np.vstack([cad.p_start, cad.p_end]), ind["p0"], ind["t"]), 3),
        }
        row["found"]["covered_2sigma"] = row["found"]["lateral_vs_independent_mm"] <= 2.0 * row["found"]["sigma_mm"]
    row["placements"] = placements(cloud, weldmap, origin, yaw, seen, e)
    if pictures is not None:
        row["picture"] = str(picture(stem, np.asarray(cloud.points), e, cad, ind, pictures).relative_to(ROOT))
    return row


def placements(cloud: Cloud, weldmap: Any, origin: Any, yaw: float, seen: str, ref: Any) -> dict[str, Any]:
    """The seen fillet located from each of OFFSETS about the nominal placement: how often found, how far its
    middle moved from the nominal run's [mm], and the hidden fillet's statuses."""
    moved, found, hidden = [], 0, set()
    for dx, dy, dyaw in OFFSETS:
        X = nominal((origin[0] + dx, origin[1] + dy, origin[2]), yaw + dyaw)
        det = locate_cloud(cloud, weldmap, X, name="offset")
        for e in det.estimates:
            if e.id != seen:
                hidden.add(e.status.value)
            elif e.status is SeamStatus.FOUND:
                found += 1
                if ref.status is SeamStatus.FOUND:
                    d = 0.5 * (e.p_start + e.p_end) - 0.5 * (ref.p_start + ref.p_end)
                    moved.append(float(np.linalg.norm(d)) * 1e3)
    det = locate_cloud(cloud, weldmap, None, name="global")  # no placement at all: the global registration
    e = next(e for e in det.estimates if e.id == seen)
    none_move = None
    if e.status is SeamStatus.FOUND and ref.status is SeamStatus.FOUND:
        d = 0.5 * (e.p_start + e.p_end) - 0.5 * (ref.p_start + ref.p_end)
        none_move = round(float(np.linalg.norm(d)) * 1e3, 3)
    return {
        "without_placement": {
            "status": e.status.value,
            "move_mm": none_move,
            "seconds": round(det.timings["total_s"], 2),
        },
        "offsets": [list(o) for o in OFFSETS],
        "found": found,
        "tried": len(OFFSETS),
        "max_move_mm": round(max(moved), 3) if moved else None,
        "hidden_statuses": sorted(hidden),
    }


def picture(stem: str, P_F: FloatArray, est: Any, cad: Any, ind: dict[str, Any], folder: Path) -> Path:
    """A PNG of the points in a SLAB_M slab about the seam's middle, seen along the independent line: the located
    seam, the independent line and the aligned CAD's seam as markers (mm from the independent line)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    p0, t = ind["p0"], ind["t"]
    up = np.array([0.0, 0.0, 1.0]) - t[2] * t
    up /= np.linalg.norm(up)
    across = np.cross(up, t)
    mid = p0 + t * 0.5 * (ind["extent"][0] + ind["extent"][1])
    d = P_F - mid
    near = (np.abs(d @ t) < SLAB_M / 2) & (np.abs(d @ across) < 0.07) & (np.abs(d @ up) < 0.07)

    def uv(p: FloatArray) -> tuple[float, float]:
        q = np.asarray(p) - mid
        q = q - (q @ t) * t
        return float(q @ across * 1e3), float(q @ up * 1e3)

    fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.4), dpi=80)
    for ax, half in zip(axes, (70.0, 6.0), strict=True):  # the whole corner, and zoomed on the seam
        label = f"scan points ({SLAB_M * 1e3:.0f} mm slab)"
        ax.scatter(d[near] @ across * 1e3, d[near] @ up * 1e3, s=2 if half > 10 else 8, c="0.55", lw=0, label=label)
        ax.plot(*uv(p0), "k+", ms=14, mew=2, label="independent two-plane line")
        ax.plot(*uv(0.5 * (cad.p_start + cad.p_end)), "bx", ms=10, mew=2, label="CAD seam (as aligned)")
        if est.status is SeamStatus.FOUND:
            m = uv(0.5 * (est.p_start + est.p_end))
            ax.add_patch(plt.Circle(m, 2.0 * est.sigma_m * 1e3, fill=False, color="r", lw=1))
            ax.plot(*m, "ro", ms=5, label=f"located (circle: 2 sigma = {2e3 * est.sigma_m:.1f} mm)")
        ax.set_xlim(-half, half)
        ax.set_ylim(-half, half)
        ax.set_aspect("equal")
        ax.set_xlabel("across the seam [mm]")
        ax.set_ylabel("up [mm]")
    axes[0].set_title(f"{stem}: {est.id}", fontsize=9)
    axes[1].set_title("zoomed on the seam", fontsize=9)
    axes[0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    folder.mkdir(parents=True, exist_ok=True)
    out = folder / f"{stem}.png"
    fig.savefig(out)
    plt.close(fig)
    return out


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--scans", type=Path, default=None, help="folder of the scans (default: $CELL_REAL_SCANS)")
    parser.add_argument("--json", type=Path, default=RESULTS / "real_scans.json")
    parser.add_argument("--pictures", type=Path, default=RESULTS / "real_scans")
    args = parser.parse_args(argv)
    folder = args.scans if args.scans is not None else scans_dir()
    if not folder.is_dir():
        parser.error(f"no scans at {folder}: set $CELL_REAL_SCANS or --scans")
    rows = [run_scan(stem, folder, args.pictures) for stem in SCANS]
    for r in rows:
        f = r.get("found")
        hidden = next(k for k in (s for s in r if s.startswith("V_TUBE")) if k != r["seen"])
        print(
            f"{r['scan']:>20}: {r['seen']} "
            + (
                f"found, {f['lateral_vs_independent_mm']:.2f} mm from the independent line, "
                f"{f['lateral_vs_cad_mm']:.2f} mm from the aligned CAD, sigma {f['sigma_mm']:.2f} mm"
                if f
                else f"{r[r['seen']]['status']}"
            )
            + f"; hidden {hidden}: {r[hidden]['status']}"
            + f"; from {r['placements']['tried']} other placements found {r['placements']['found']} times,"
            f" moved up to {r['placements']['max_move_mm']} mm; without a placement"
            f" {r['placements']['without_placement']['status']} ({r['placements']['without_placement']['move_mm']} mm)"
        )
    write_json(args.json, {"map": "maps/tee.dxf", "boxes_mm": BOXES, "scans": rows})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
