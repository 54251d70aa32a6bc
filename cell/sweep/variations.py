"""N varied builds of one scenario (part tolerances, placement error, camera extrinsic error and seed): run k is drawn
from the scenario's seed and k alone, each kind from its own generator, each tolerance read as a 3-sigma bound
(docs/sweep.md, "What varies"). There is no global RNG."""

from __future__ import annotations

import zlib
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cell.errors import UsageError
from cell.scenario import Deviation, ExtrinsicErrorSpec, PoseSpec, Scenario
from cell.types import WeldMap

VARY_WORDS = ("tolerances", "placement", "extrinsics", "seed")


@dataclass(frozen=True)
class Tolerances:
    """The spread of the varied builds. Part tolerances as fractions of the part's dimension (3-sigma bounds);
    placement and extrinsic errors as 3-sigma bounds in SI units (metres, radians)."""

    width_height: float = 0.01  # of the part's width and height (paper: up to 1 %)
    length: float = 0.05  # of the part's longest edge (paper: up to 5 %)
    location: float = 0.01  # of the part's length, per axis (paper: location up to 1 %)
    placement_xy_m: float = 0.005  # [m] where the part lies on the table, per axis of the table
    placement_yaw_rad: float = float(np.radians(0.3))  # [rad] its turn about the table's normal
    extrinsic_translation_m: float = 0.001  # [m] a camera pose's calibration error (magnitude)
    extrinsic_rotation_rad: float = float(np.radians(0.1))  # [rad]


@dataclass(frozen=True)
class Variation:
    """One varied build: run ``k``, and what it changes (None: the scenario's own value is kept).

    deviations_mm : part name -> (size (3,), offset (3,)) as built minus drawn, in the part's frame [mm].
    placement : (x [m], y [m], yaw [deg]) of the part's placement error. extrinsics : camera name ->
    (translation [mm], rotation [deg]) magnitudes (the directions are the simulator's, from the seed).
    seed : the run's scenario seed (sensor noise, extrinsic directions, the planner's and locators' streams).
    """

    k: int
    deviations_mm: dict[str, tuple[tuple[float, ...], tuple[float, ...]]] | None = None
    placement: tuple[float, float, float] | None = None
    extrinsics: dict[str, tuple[float, float]] | None = None
    seed: int | None = None
    vary: tuple[str, ...] = field(default=())

    def to_json(self) -> dict[str, Any]:
        """The variation as plain JSON values (rounded: the line of runs.jsonl is the same on every machine)."""
        out: dict[str, Any] = {"k": self.k}
        if self.deviations_mm is not None:
            out["deviations_mm"] = {
                n: {"size": [round(v, 4) for v in s], "offset": [round(v, 4) for v in o]}
                for n, (s, o) in sorted(self.deviations_mm.items())
            }
        if self.placement is not None:
            x, y, yaw = self.placement
            out["placement"] = {"x_mm": round(x * 1000, 4), "y_mm": round(y * 1000, 4), "yaw_deg": round(yaw, 5)}
        if self.extrinsics is not None:
            out["extrinsics"] = {
                c: {"translation_mm": round(t, 4), "rotation_deg": round(r, 5)}
                for c, (t, r) in sorted(self.extrinsics.items())
            }
        if self.seed is not None:
            out["seed"] = self.seed
        return out


def parse_vary(text: str) -> tuple[str, ...]:
    """``--vary`` as a tuple of words in the canonical order; UsageError naming an unknown word and the valid
    ones."""
    words = [w.strip() for w in text.split(",") if w.strip()]
    unknown = [w for w in words if w not in VARY_WORDS]
    if unknown or not words:
        what = f"unknown word(s) {', '.join(unknown)}" if unknown else "nothing to vary"
        raise UsageError(f"--vary: {what}; valid: {', '.join(VARY_WORDS)} (comma-separated)")
    return tuple(w for w in VARY_WORDS if w in words)


def stream(seed: int, kind: str, k: int) -> np.random.Generator:
    """The generator of one kind of variation for run k: keyed by the scenario seed, the kind and k only."""
    return np.random.default_rng([seed, zlib.crc32(f"sweep/{kind}".encode()), k])


def _bounded(rng: np.random.Generator, bound: float, n: int) -> list[float]:
    """n normal draws with sigma = bound / 3, clipped at +-bound."""
    if bound <= 0.0:
        return [0.0] * n
    return [float(v) for v in np.clip(rng.normal(0.0, bound / 3.0, n), -bound, bound)]


def variation(
    scenario: Scenario, weldmap_M: WeldMap, k: int, vary: Sequence[str], tol: Tolerances = Tolerances()
) -> Variation:
    """Run k's build of ``scenario``: what ``vary`` selects, drawn from (scenario seed, kind, k)."""
    devs = place = extr = seed = None
    if "tolerances" in vary:
        rng = stream(scenario.seed, "tolerances", k)
        devs = {}
        for part in weldmap_M.parts:  # map order: a part's draws never depend on another's
            # a body that is not a box keeps its drawn size (same draws, so the next parts' stay the same)
            size_mm = np.asarray(part.box.size if part.is_box else np.ptp(part.vertices(), axis=0)) * 1000.0
            axis = int(np.argmax(size_mm))
            bounds = [(tol.length if i == axis else tol.width_height) * size_mm[i] for i in range(3)]
            ds = [_bounded(rng, b, 1)[0] * part.is_box for b in bounds]
            do = _bounded(rng, tol.location * size_mm[axis], 3)
            do[2] = 0.0  # the part rests on the table whatever its drawn height offset (cell/sim/asbuilt/parts.py)
            devs[part.name] = (tuple(round(v, 6) for v in ds), tuple(round(v, 6) for v in do))
    if "placement" in vary:
        rng = stream(scenario.seed, "placement", k)
        x, y = _bounded(rng, tol.placement_xy_m, 2)
        yaw = float(np.degrees(_bounded(rng, tol.placement_yaw_rad, 1)[0]))
        place = (round(x, 9), round(y, 9), round(yaw, 9))
    if "extrinsics" in vary:
        rng = stream(scenario.seed, "extrinsics", k)
        extr = {}
        for name in sorted(scenario.cameras):
            t = abs(_bounded(rng, tol.extrinsic_translation_m, 1)[0]) * 1000.0
            r = abs(float(np.degrees(_bounded(rng, tol.extrinsic_rotation_rad, 1)[0])))
            extr[name] = (round(t, 6), round(r, 9))
    if "seed" in vary:
        seed = int(stream(scenario.seed, "seed", k).integers(0, 2**31 - 1))
    return Variation(k, devs, place, extr, seed, tuple(vary))


def variations(
    scenario: Scenario, weldmap_M: WeldMap, n: int, vary: Sequence[str], tol: Tolerances = Tolerances()
) -> list[Variation]:
    """Runs 0 .. n-1 of a sweep (each one :func:`variation`)."""
    return [variation(scenario, weldmap_M, k, vary, tol) for k in range(n)]


def varied(scenario: Scenario, v: Variation) -> Scenario:
    """The scenario built as ``v`` says: its deviations, placement error, cameras' extrinsic errors and seed
    replaced where ``v`` gives them."""
    sc = scenario
    changes: dict[str, object] = {}
    if v.deviations_mm is not None:
        changes["deviations"] = {
            n: Deviation(size_mm=s, offset_mm=o, rpy_deg=(0.0, 0.0, 0.0))  # type: ignore[arg-type]
            for n, (s, o) in v.deviations_mm.items()
        }
    if v.placement is not None:
        x, y, yaw = v.placement
        changes["placement_error"] = PoseSpec(xyz_m=(x, y, 0.0), rpy_deg=(0.0, 0.0, yaw))
    if changes:
        sc = sc.with_simulation(**changes)
    if v.extrinsics is not None and any(cam.measured is not None for cam in sc.cameras.values()):
        from cell.sim.calibrated import off_calibration  # a calibrated cell: the true cameras off its belief

        errors = {n: ExtrinsicErrorSpec(translation_mm=t, rotation_deg=r) for n, (t, r) in v.extrinsics.items()}
        sc = off_calibration(sc, errors)
    elif v.extrinsics is not None:
        cams = {
            name: cam.model_copy(
                update={
                    "extrinsic_error": ExtrinsicErrorSpec(
                        translation_mm=v.extrinsics[name][0], rotation_deg=v.extrinsics[name][1]
                    )
                }
            )
            if name in v.extrinsics
            else cam
            for name, cam in sc.cameras.items()
        }
        sc = sc.model_copy(update={"cameras": cams})
    if v.seed is not None:
        sc = sc.model_copy(update={"seed": v.seed})
    return sc
