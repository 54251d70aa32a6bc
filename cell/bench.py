"""``cell bench``: the paper's Table 1, every locator on the same captured clouds in the same run, one row per
scenario x noise x extrinsic-error setting x method; :func:`markdown_table` renders the rows next to the paper's
figures. How the times are taken: docs/results.md, "Table 1, reproduced and beaten"."""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from cell import pipeline
from cell.scenario import CalibrationSpec, ExtrinsicErrorSpec, Scenario
from cell.types import SeamEstimate

# The paper's Table 1 (ms and mm per seam, 8 seams each): scenario -> method -> (ME mm, ms).
PAPER_TABLE1: dict[str, dict[str, tuple[float, float]]] = {
    "fence1-exact": {"paper": (0.18, 44.0), "ransac": (3.90, 195.0)},
    "fence1": {"paper": (1.02, 565.0)},
    "fence2": {"paper": (2.71, 630.0)},
}


@dataclass(frozen=True)
class Extrinsics:
    """A calibration-error setting applied to every fixed camera: translation [mm], rotation [deg]."""

    translation_mm: float = 0.0
    rotation_deg: float = 0.0

    @property
    def label(self) -> str:
        if self.translation_mm == 0.0 and self.rotation_deg == 0.0:
            return "exact"
        return f"{self.translation_mm:g}mm/{self.rotation_deg:g}deg"

    @staticmethod
    def parse(text: str) -> Extrinsics:
        """``exact`` or ``MM/DEG`` (e.g. ``1/0.1``)."""
        if text in ("exact", "0", "0/0"):
            return Extrinsics()
        try:
            mm, deg = (float(v) for v in text.split("/"))
        except ValueError:
            raise ValueError(f"extrinsic error {text!r}; valid: exact or MM/DEG such as 0.3/0.03") from None
        if mm < 0 or deg < 0:
            raise ValueError(f"extrinsic error {text!r} must not be negative")
        return Extrinsics(mm, deg)


def with_extrinsics(scenario: Scenario, ext: Extrinsics) -> Scenario:
    """The scenario with every fixed camera's calibration off by ``ext`` (directions from the scenario seed), and
    stated so (``calibration``, as a calibration report would: the splice's prior and the seams' sigma). A camera
    with a measured pose (``--calibration``) is told it and truly sits ``ext`` off it
    (:func:`cell.sim.calibrated.off_calibration`)."""
    if ext.label == "exact":
        return scenario
    spec = ExtrinsicErrorSpec(translation_mm=ext.translation_mm, rotation_deg=ext.rotation_deg)
    stated = CalibrationSpec(translation_mm=ext.translation_mm, rotation_deg=ext.rotation_deg)
    cams = {
        name: cam.model_copy(update={"extrinsic_error": spec, "calibration": stated}) if cam.mount == "fixed" else cam
        for name, cam in scenario.cameras.items()
    }
    out = scenario.model_copy(update={"cameras": cams})
    fixed = [n for n, c in out.cameras.items() if c.mount == "fixed" and c.measured is not None]
    if fixed:  # a calibrated cell (--calibration): the true cameras off its measured poses by the error
        from cell.sim.calibrated import off_calibration

        out = off_calibration(out, dict.fromkeys(fixed, spec))
    return out


def _p95(values: Sequence[float]) -> float:
    if not values:
        return float("nan")
    s = sorted(values)
    k = 0.95 * (len(s) - 1)
    lo = int(k)
    hi = min(lo + 1, len(s) - 1)
    return s[lo] + (s[hi] - s[lo]) * (k - lo)


def _mean(values: Sequence[float]) -> float:
    return statistics.fmean(values) if values else float("nan")


def run(
    scenarios: Sequence[Scenario],
    methods: Sequence[str],
    *,
    noise: Literal["none", "realistic"] | None = None,
    extrinsics: Sequence[Extrinsics] = (Extrinsics(),),
    repeat: int = 1,
    progress: Callable[[str], None] = lambda _: None,
) -> list[dict[str, Any]]:
    """Benchmark rows. ``repeat`` re-runs each locator on the same scene and keeps each seam's fastest run (the
    one the rest of the machine disturbed least; every run is cold, so it still holds the per-scene work)."""
    rows: list[dict[str, Any]] = []
    for base in scenarios:
        scn = base.with_noise(noise) if noise else base
        for ext in extrinsics:
            s = with_extrinsics(scn, ext)
            progress(f"{s.name}: capture and perceive ({s.noise} noise, extrinsics {ext.label})")
            cap = pipeline.capture(s)
            scene = pipeline.build_scene(cap)
            truth = pipeline.truths(cap, scene.seam_scene.weldmap)
            progress(f"{s.name}: {', '.join(methods)} x {max(1, repeat)}")
            all_runs: dict[str, list[tuple[SeamEstimate, ...]]] = {method: [] for method in methods}
            for _ in range(max(1, repeat)):
                # The methods take turns (a slower spell of the machine hits them alike), every run from a cold
                # cache: each method's once-per-scene work (indexes, KD-trees, features) lands in every run,
                # so the amortised time includes it.
                for method in methods:
                    scene.seam_scene.cache.clear()
                    all_runs[method].append(pipeline.locate(scene, s, method))
            for method in methods:
                runs = all_runs[method]
                estimates = runs[0]
                per_seam, _ = pipeline.evaluate(estimates, truth)
                times = [
                    min(r[i].time_s for r in runs) * 1000.0
                    for i, e in enumerate(estimates)
                    if e.status.value != "not_visible"
                ]
                me = [m.paper_me_mm for m in per_seam.values()]
                rows.append(
                    {
                        "scenario": s.name,
                        "method": method,
                        "noise": s.noise,
                        "extrinsics": ext.label,
                        "seams": len(estimates),
                        "visible": sum(e.status.value != "not_visible" for e in estimates),
                        "found": len(per_seam),
                        "paper_me_mean_mm": _mean(me),
                        "paper_me_p95_mm": _p95(me),
                        "lateral_mean_mm": _mean([m.lateral_mm for m in per_seam.values()]),
                        "endpoint_mean_mm": _mean([m.endpoint_mm for m in per_seam.values()]),
                        "ms_per_seam_median": statistics.median(times) if times else float("nan"),
                        # Amortised: the mean, once-per-scene work (KD-trees, features, indexes) included.
                        "ms_per_seam_amortised": statistics.fmean(times) if times else float("nan"),
                        "points_dense": len(scene.seam_scene.dense),
                    }
                )
    return rows


def markdown_table(rows: Sequence[dict[str, Any]]) -> str:
    """Table 1 shape: scenario x method, with the paper's figures where it has them."""
    head = (
        "| scenario | noise | extrinsics | method | found/visible | paper ME mean mm | p95 mm | lateral mm | "
        "endpoint mm | ms/seam median | ms/seam amortised | paper: ME mm / ms |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rows:
        paper = PAPER_TABLE1.get(r["scenario"], {}).get(r["method"])
        ref = f"{paper[0]:.2f} / {paper[1]:.0f}" if paper else ""
        lines.append(
            f"| {r['scenario']} | {r['noise']} | {r['extrinsics']} | {r['method']} | {r['found']}/{r['visible']} | "
            f"{_mm(r['paper_me_mean_mm'])} | {_mm(r['paper_me_p95_mm'])} | {_mm(r['lateral_mean_mm'])} | "
            f"{_mm(r['endpoint_mean_mm'])} | {r['ms_per_seam_median']:.2f} | {r['ms_per_seam_amortised']:.2f} | {ref} |"
        )
    return head + "\n".join(lines) + "\n"


def _mm(x: float) -> str:
    """An error [mm] to three decimals; '-' when no seam was found to measure it on (NaN)."""
    return "-" if math.isnan(x) else f"{x:.3f}"
