"""Every splice registration on random cells measured against the truth: did the correction bring the camera nearer
its true pose, and was a refused camera really off?

    .venv/bin/python benchmarks/bench_splice_truth.py [--seed 7] [--cells 12] [--exact-stated 0.7/0.07]
        [--cache DIR] [--json PATH]

Cell k is the trust benchmark's cell k of ``--seed`` (``tools/random_cells.py``, :func:`trust_cells.cell_seed`).
Cells whose fixed cameras are perturbed (the generator states their true error as their calibration) are
perceived as ``cell detect`` would; cells with exact extrinsics are perceived with every fixed camera *stated*
``--exact-stated`` (translation mm / rotation deg; their true error is 0, so any applied correction is false).
The simulator's believed pose of a camera is its true pose moved by its extrinsic error (:mod:`cell.sim.noise`),
so its true error in R is ``E = X_RW X_believed X_true^-1 X_WR`` (the calibrated cloud is ``E`` of the true
points) and the correction that would undo it is ``E^-1``.

One row per registration, at the overlap (the source's points within a voxel of its targets' as they stood):
``true_mm`` the RMS distance of the overlap points from their true place before, ``after_mm`` after the applied
correction (equal when refused), ``relative_mm`` the source's error less its targets' (what the overlap can see),
``estimate_mm`` the data's estimate, ``applied_mm``, ``better`` (the applied correction lowered the true error),
``disagreement_sigmas``, ``refused``, ``prior_mm`` the prior's 1 sigma at the overlap (the camera's stated
calibration there). Captures are cached (pickled images) in ``--cache`` so a rerun only re-perceives.
"""

from __future__ import annotations

import argparse
import math
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

BENCH = Path(__file__).resolve().parent
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))
if str(BENCH.parent / "tools") not in sys.path:
    sys.path.insert(0, str(BENCH.parent / "tools"))

import random_cells  # noqa: E402
import trust_cells as tc  # noqa: E402

from cell import pipeline  # noqa: E402
from cell import scenario as sc  # noqa: E402
from cell.export.reports.report import write_json  # noqa: E402
from cell.geometry import FloatArray, invert, transform_points  # noqa: E402
from cell.perception import perceive  # noqa: E402
from cell.perception.deproject import clouds_in_robot_frame  # noqa: E402
from cell.perception.splicing.decision import FAULT  # noqa: E402
from cell.pipeline.detect import pose_uncertainties  # noqa: E402
from cell.scenario import CalibrationSpec, ExtrinsicErrorSpec, Scenario  # noqa: E402

KNOCKED = "cam_1"  # the camera ``--knock`` moves beyond its statement


def _scenario(
    seed: int,
    k: int,
    folder: Path,
    exact_stated: tuple[float, float],
    noise: str | None = None,
    knock: tuple[float, float] | None = None,
) -> tuple[Scenario, bool]:
    """Cell k's scenario (exact cells with their fixed cameras stated ``exact_stated``; ``knock``: cam_1's true
    error made that, its statement kept), and whether it is perturbed."""
    made = random_cells.make_cell(tc.cell_seed(seed, k), folder)
    s = sc.load(made.scenario)
    if noise is not None and "=" in noise:  # one key of every camera's noise model changed
        key, value = noise.split("=")
        cams = {
            n: c.model_copy(update={"noise": c.noise.model_copy(update={key: float(value)})})
            for n, c in s.cameras.items()
        }
        s = s.model_copy(update={"cameras": cams})
    elif noise is not None:
        s = s.with_simulation(noise=noise)
    perturbed = any(c.extrinsic_error.translation_mm > 0.0 for c in s.cameras.values())
    if not perturbed:
        cal = CalibrationSpec(translation_mm=exact_stated[0], rotation_deg=exact_stated[1])
        cams = {n: c.model_copy(update={"calibration": cal}) if c.mount == "fixed" else c for n, c in s.cameras.items()}
        s = s.model_copy(update={"cameras": cams})
    if knock is not None:
        err = ExtrinsicErrorSpec(translation_mm=knock[0], rotation_deg=knock[1])
        cams = {n: c.model_copy(update={"extrinsic_error": err}) if n == KNOCKED else c for n, c in s.cameras.items()}
        s = s.model_copy(update={"cameras": cams})
    return s, perturbed


def _rms(a: FloatArray, b: FloatArray) -> float:
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1)))) if len(a) else 0.0


def rows_of_cell(
    seed: int,
    k: int,
    cache: Path,
    exact_stated: tuple[float, float],
    noise: str | None = None,
    knock: tuple[float, float] | None = None,
) -> list[dict[str, Any]]:
    """One row per registration of cell k of the benchmark seed ``seed`` (``noise``: the cell's noise model
    replaced; ``knock``: :data:`KNOCKED` knocked by (mm, deg))."""
    folder = cache / f"seed{seed}" / str(k)
    s, perturbed = _scenario(seed, k, folder, exact_stated, noise, knock)
    folder = folder / noise if noise is not None else folder
    folder = folder / f"knock{knock[0]}_{knock[1]}" if knock is not None else folder
    folder.mkdir(parents=True, exist_ok=True)
    pickled = folder / "images.pkl"
    if pickled.exists():
        images = pickle.loads(pickled.read_bytes())
    else:
        images = pipeline.capture(s).images
        pickled.write_bytes(pickle.dumps(images))
    rows = rows_of(s, images, {"seed": seed, "cell": k, "perturbed": perturbed})
    return [r | {"knocked": knock is not None and r["camera"] == KNOCKED} for r in rows]


def rows_of(s: Scenario, images: dict[str, Any], tags: dict[str, Any]) -> list[dict[str, Any]]:
    """One row per splice registration of the captured ``images`` of scenario ``s``, each starting with
    ``tags``."""
    priors = pose_uncertainties(s)
    p = perceive(images, s.X_WR, s.perception, s.perception.health, priors)
    X_WR = np.asarray(s.X_WR, dtype=float)
    X_RW = invert(X_WR)
    # The current pose error of each camera in R (the calibrated cloud is E of the true points).
    E = {n: X_RW @ np.asarray(images[n].X_WC) @ invert(np.asarray(s.cameras[n].X_WC)) @ X_WR for n in images}
    E = {n: (e if s.cameras[n].mount == "fixed" else np.eye(4)) for n, e in E.items()}
    clouds = clouds_in_robot_frame(images, X_WR, s.perception.workspace)  # a splice fault's cloud as well
    gone = set(p.lost) - set(p.spliced.faults)
    pts = {n: np.asarray(c.points) if n not in gone else np.zeros((0, 3)) for n, c in clouds.items()}
    out = []
    voxel = s.perception.voxel_m
    for r in p.spliced.registrations:
        src = pts.get(r.source, np.zeros((0, 3)))
        tgt_names = [n for n in r.target if len(pts.get(n, ()))]
        row: dict[str, Any] = {**tags, "camera": r.source}
        u = priors[r.source]
        if not len(src) or not tgt_names:
            out.append(row | {"refused": r.refused, "overlap": 0})
            continue
        tgt = np.concatenate([pts[n] for n in tgt_names])
        owner = np.concatenate([np.full(len(pts[n]), i) for i, n in enumerate(tgt_names)])
        dist, nearest = cKDTree(tgt).query(src, distance_upper_bound=voxel)
        near = np.isfinite(dist)
        o = src[near]
        true_o = transform_points(invert(E[r.source]), o)  # where the overlap's points really are
        after = transform_points(np.asarray(r.X_corr), o)
        # The targets' own error at these points (each overlap point by the camera of its nearest target point).
        tgt_disp = np.zeros_like(o)
        for i, n in enumerate(tgt_names):
            mine = owner[nearest[near]] == i
            tgt_disp[mine] = o[mine] - transform_points(invert(E[n]), o[mine])
        centre = o.mean(axis=0) if len(o) else np.zeros(3)
        rng_m = float(np.linalg.norm(centre - (X_RW @ np.asarray(images[r.source].X_WC))[:3, 3]))
        before_mm = _rms(o, true_o) * 1e3
        after_mm = _rms(after, true_o) * 1e3
        row |= {
            "overlap": len(o),
            "prior_mm": round(math.sqrt(3.0) * u.sigma_at(rng_m) * 1e3, 3),
            "true_mm": round(before_mm, 3),
            "relative_mm": round(_rms(o - true_o, tgt_disp) * 1e3, 3),
            "estimate_mm": round(r.shift_m * 1e3, 3),
            "applied_mm": round(r.applied_shift_m * 1e3, 3),
            "after_mm": round(after_mm, 3),
            "better": bool(after_mm < before_mm) if r.accepted else None,
            "noise_mm": round(r.noise_m * 1e3, 3),
            "directions": r.informed,
            "disagreement_sigmas": round(r.disagreement_sigmas, 2),
            "misfit_drop": round(1.0 - r.misfit_m / r.misfit_before_m, 3) if r.misfit_before_m > 0 else None,
            "refused": r.refused,
        }
        out.append(row)
        if r.accepted:  # the camera now sits where its correction put it
            E[r.source] = np.asarray(r.X_corr) @ E[r.source]
            pts[r.source] = transform_points(np.asarray(r.X_corr), src)
        if r.fault:
            pts[r.source] = np.zeros((0, 3))
    return out


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The acceptance's counts: applied corrections (better / worse by more than the prior's 1 sigma) and faults
    on cameras within their stated calibration, for perturbed and exact-but-stated cells."""
    out: dict[str, Any] = {}
    knocked = [r for r in rows if r.get("knocked") and r.get("overlap")]
    if knocked:
        out["knocked"] = {"registrations": len(knocked), "beyond_prior": sum(r["refused"] == FAULT for r in knocked)}
    for label, pert in (("perturbed", True), ("exact_stated", False)):
        rs = [r for r in rows if r["perturbed"] == pert and r.get("overlap") and not r.get("knocked")]
        applied = [r for r in rs if r["refused"] == ""]
        out[label] = {
            "registrations": len(rs),
            "applied": len(applied),
            "applied_better": sum(1 for r in applied if r["better"]),
            "applied_worse_than_prior": sum(1 for r in applied if r["after_mm"] - r["true_mm"] > r["prior_mm"]),
            "beyond_prior": sum(1 for r in rs if r["refused"] == "beyond_prior"),
            "refusals": {k: sum(1 for r in rs if r["refused"] == k) for k in sorted({r["refused"] for r in rs})},
        }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--cells", type=int, default=12)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--exact-stated", default="0.7/0.07")
    ap.add_argument("--cache", type=Path, default=Path("/tmp/splice_truth"))
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--knock", default=None, help=f"T/R: {KNOCKED} truly off by T mm / R deg (its statement kept)")
    ap.add_argument(
        "--noise", default=None, help="every cell's noise: realistic, none, or KEY=VALUE of the cameras' noise models"
    )
    a = ap.parse_args()
    t_mm, r_deg = (float(v) for v in a.exact_stated.split("/"))
    knock = tuple(float(v) for v in a.knock.split("/")) if a.knock else None
    rows: list[dict[str, Any]] = []
    for k in range(a.first, a.first + a.cells):
        try:
            got = rows_of_cell(a.seed, k, a.cache, (t_mm, r_deg), a.noise, knock)  # type: ignore[arg-type]
        except Exception as err:  # a cell that fails to perceive is reported, not fatal
            print(f"cell {k}: {type(err).__name__}: {err}", flush=True)
            continue
        for r in got:
            print(" ".join(f"{key}={v}" for key, v in r.items()), flush=True)
        rows += got
    s = summary(rows)
    print(s)
    if a.json is not None:
        write_json(
            a.json, {"seed": a.seed, "cells": a.cells, "exact_stated": a.exact_stated, "summary": s, "rows": rows}
        )


if __name__ == "__main__":
    main()
