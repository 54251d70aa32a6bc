"""Splice corrections with exact extrinsics: does the splice invent a correction the data cannot prove?

    .venv/bin/python benchmarks/bench_splice.py [--scenarios fence1-exact,fence1,...] [--seeds 5]
        [--extrinsics exact] [--stated 1/0.1] [--json PATH]

Each scenario (default: every public scenario whose fixed cameras are calibrated exactly, and the long parts seen
along their length, ``scenarios/long-*.yaml``) is captured with seeds 0 .. N-1 and perceived with each camera's
stated calibration as the splice's prior; one row per splice registration: what the data estimate along the
informed directions and what was applied (RMS displacement of the overlap), the informed directions, the
disagreement with the prior in its sigmas, and why nothing was applied. With exact extrinsics the true
correction is zero: every applied correction is an error. ``--extrinsics 1/0.1`` gives the fixed cameras a
calibration error and states it (as ``cell bench --extrinsics``): then a correction should be applied.
``--stated 1/0.1`` states that calibration for every camera whatever the extrinsics (exact cameras stated
uncertain: the case where the prior lets a false correction through). Rows go to ``--json`` when given.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from cell import pipeline
from cell import scenario as sc
from cell.bench import Extrinsics, with_extrinsics
from cell.export.reports.report import write_json
from cell.perception import perceive
from cell.pipeline.detect import pose_uncertainties
from cell.scenario import CalibrationSpec

SCENARIOS = ("fence1-exact", "fence1", "fence2", "ladder", "long-fence1", "long-ladder")


def rows(names: list[str], seeds: int, ext: Extrinsics, stated: Extrinsics | None = None) -> list[dict[str, Any]]:
    """One row per registration of every scenario x seed (``stated``: every camera's stated calibration)."""
    out = []
    for name in names:
        for seed in range(seeds):
            s = with_extrinsics(sc.load(name).model_copy(update={"seed": seed}), ext)
            if stated is not None:
                cal = CalibrationSpec(translation_mm=stated.translation_mm, rotation_deg=stated.rotation_deg)
                cams = {n: c.model_copy(update={"calibration": cal}) for n, c in s.cameras.items()}
                s = s.model_copy(update={"cameras": cams})
            cap = pipeline.capture(s)
            p = perceive(cap.images, s.X_WR, s.perception, s.perception.health, pose_uncertainties(s))
            for r in p.spliced.registrations:
                out.append(
                    {
                        "scenario": name,
                        "seed": seed,
                        "extrinsics": ext.label,
                        "camera": r.source,
                        "estimated_mm": round(r.shift_m * 1e3, 4),
                        "applied_mm": round(r.applied_shift_m * 1e3, 4),
                        "directions": f"{r.informed}/6",
                        "disagreement_sigmas": round(r.disagreement_sigmas, 2),
                        "misfit_before_mm": round(r.misfit_before_m * 1e3, 4),
                        "misfit_mm": round(r.misfit_m * 1e3, 4) if r.misfit_m != float("inf") else None,
                        "applied": r.accepted,
                        "refused": r.refused,
                    }
                )
                print(" ".join(f"{k}={v}" for k, v in out[-1].items()), flush=True)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenarios", default=",".join(SCENARIOS))
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--extrinsics", default="exact")
    ap.add_argument("--stated", default=None)
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args()
    ext = Extrinsics.parse(a.extrinsics)
    stated = Extrinsics.parse(a.stated) if a.stated else None
    table = rows([n for n in a.scenarios.split(",") if n], a.seeds, ext, stated)
    applied = [r for r in table if r["applied"]]
    print(f"{len(applied)} of {len(table)} registrations applied a correction (extrinsics {ext.label})")
    if a.json is not None:
        write_json(a.json, {"extrinsics": ext.label, "stated": a.stated, "seeds": a.seeds, "rows": table})


if __name__ == "__main__":
    main()
