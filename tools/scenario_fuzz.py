"""Nonsense scenarios, seeded: mutations of the shipped scenarios that a run would refuse or misread, and the
verdict of ``cell scenario check`` on each (refused in one line, flagged by a warning the original does not have,
silently accepted, or a traceback). Used by tests/unit/test_fuzz_scenarios.py (a small sample) and
benchmarks/bench_fuzz_scenarios.py (the full count); docs/scenarios.md section "Checks" says what is checked.

Every mutation is nonsense by construction: a wrong type, a non-finite or absurd number, a key given twice, an
unknown key, a required key deleted, or a cell that cannot work (a camera inside the table or looking away, the
robot inside the table or upside down, a scan pose out of reach, a loose weld gate, a part drawn in the air)."""

from __future__ import annotations

import math
import re
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scenario_fuzz_corrupt import (
    Data,
    broken_yaml,
    corrupt_key,
    corrupt_shape,
    corrupt_value,
    delete_required,
    duplicate_key,
)

SOURCES = ("fence1", "fence2", "bracket", "brace")
REPO = Path(__file__).resolve().parents[1]
VERDICTS = ("refused", "flagged", "silent", "traceback")


@dataclass(frozen=True)
class Mutant:
    """One nonsense scenario: what was done (``kind``, ``what``: its `marked` words are what the check's line must
    name) to which shipped scenario, and its YAML text."""

    index: int
    source: str
    kind: str
    what: str
    text: str


def _source(name: str) -> tuple[str, Data]:
    text = (REPO / "scenarios" / f"{name}.yaml").read_text(encoding="utf-8")
    return text, yaml.safe_load(text)


def _dump(data: Data) -> str:
    return yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=200)


def _cams(d: Data, mount: str = "fixed") -> list[str]:
    return [n for n, c in d["cameras"].items() if c.get("mount", "fixed") == mount]


def _ws_centre(d: Data) -> np.ndarray:
    ws = d["perception"]["workspace"]
    return (np.array(ws["min_m"], float) + np.array(ws["max_m"], float)) / 2.0


def _l(v: np.ndarray) -> list[float]:
    return [round(float(x), 4) for x in v]


# -- the cell's nonsense: each takes (data, rng) and returns a description ----------------------------------------


def camera_far(d: Data, rng: np.random.Generator) -> str:
    cam = str(rng.choice(list(d["cameras"])))
    d["cameras"][cam]["eye_m"][int(rng.integers(3))] = float(rng.choice([1e300, -1e300, 1e30, 5e6]))
    return f"camera `{cam}` placed absurdly far"


def camera_in_table(d: Data, rng: np.random.Generator) -> str:
    cam = str(rng.choice(_cams(d)))
    c, s = np.array(d["table"]["center_m"], float), np.array(d["table"]["size_m"], float)
    d["cameras"][cam]["eye_m"] = _l(c + (rng.random(3) - 0.5) * 0.8 * s)
    return f"camera `{cam}` inside the table"


def camera_away(d: Data, rng: np.random.Generator) -> str:
    cam = str(rng.choice(_cams(d)))
    eye = np.array(d["cameras"][cam]["eye_m"], float)
    d["cameras"][cam]["target_m"] = _l(eye + (eye - _ws_centre(d)))
    return f"camera `{cam}` looking away from the workspace"


def camera_short(d: Data, rng: np.random.Generator) -> str:
    cam = str(rng.choice(_cams(d)))
    eye = np.array(d["cameras"][cam]["eye_m"], float)
    reach = float(np.linalg.norm(eye - _ws_centre(d)))
    d["cameras"][cam]["near_m"] = 0.05
    d["cameras"][cam]["far_m"] = round(reach * float(rng.uniform(0.1, 0.4)), 3)
    return f"camera `{cam}` with the workspace beyond its range"


def camera_moved_off(d: Data, rng: np.random.Generator) -> str:
    cam = str(rng.choice(_cams(d)))
    eye = np.array(d["cameras"][cam]["eye_m"], float)
    tgt = np.array(d["cameras"][cam]["target_m"], float)
    far = float(d["cameras"][cam].get("far_m", 4.0))
    d["cameras"][cam]["eye_m"] = _l(tgt + (eye - tgt) / np.linalg.norm(eye - tgt) * far * float(rng.uniform(1.5, 4)))
    return f"camera `{cam}` moved beyond its range"


def robot_in_table(d: Data, rng: np.random.Generator) -> str:
    c, s = np.array(d["table"]["center_m"], float), np.array(d["table"]["size_m"], float)
    d["robot"]["X_WR"] = {"xyz_m": _l(c + (rng.random(3) - 0.5) * 0.8 * s)}
    return "`robot.X_WR` inside the table"


def robot_upside_down(d: Data, rng: np.random.Generator) -> str:
    d["robot"]["X_WR"]["rpy_deg"] = [float(rng.choice([180.0, -180.0, 170.0])), 0.0, 0.0]
    return "robot upside down (its `scan pose` out of reach, or not `upright`)"


def robot_facing_away(d: Data, rng: np.random.Generator) -> str:
    d["robot"]["X_WR"]["rpy_deg"] = [0.0, 0.0, float(rng.choice([180.0, 160.0, -170.0]))]
    return "robot `faces away` from the table (or its `scan pose` out of reach)"


def scan_unreachable(d: Data, rng: np.random.Generator) -> str:
    cam = _cams(d, "eye_in_hand")[0]
    eye = np.array(d["cameras"][cam]["eye_m"], float)
    eye[2] += float(rng.uniform(1.5, 3.0))
    d["cameras"][cam]["eye_m"] = _l(eye)
    return f"`scan pose` of {cam} out of the arm's reach"


def _limits_deg(urdf: str) -> list[tuple[float, float]]:
    """(lower, upper) [deg] of each revolute joint of a robot in robots/, in the URDF's order."""
    import xml.etree.ElementTree as ET

    root = ET.parse(REPO / "robots" / urdf).getroot()
    out = []
    for joint in root.iter("joint"):
        lim = joint.find("limit")
        if joint.get("type") == "revolute" and lim is not None:
            out.append((math.degrees(float(lim.get("lower", 0))), math.degrees(float(lim.get("upper", 0)))))
    return out


def home_out(d: Data, rng: np.random.Generator) -> str:
    limits = _limits_deg(d["robot"]["urdf"])
    j = int(rng.integers(len(limits)))
    lo, hi = limits[j]
    beyond = float(rng.uniform(5.0, 60.0))
    d["robot"]["home_deg"][j] = round(hi + beyond if rng.random() < 0.5 else lo - beyond, 1)
    return f"`home_deg` A{j + 1} {d['robot']['home_deg'][j]} out of its limits ({lo:.0f} to {hi:.0f})"


def seed_text(d: Data, rng: np.random.Generator) -> str:
    d["seed"] = str(rng.choice(["12", "0", "seed", "1e3"]))
    return "`seed` given as text"


def gate_loose(d: Data, rng: np.random.Generator) -> str:
    r = d.setdefault("rescan", {})
    key = str(rng.choice(["weld_tolerance_mm", "end_tolerance_mm", "bound_sigmas", "bound_sigmas"]))
    r[key] = float(rng.choice([100.0, 25.0, 10.0])) if key != "bound_sigmas" else float(rng.choice([0.01, 0.2, 1e-6]))
    return f"rescan.`{key}` switches the weld gate off"


def part_above(d: Data, rng: np.random.Generator) -> str:
    xyz = d["map"]["X_WM"]["xyz_m"]
    xyz[2] = round(float(xyz[2]) + float(rng.uniform(0.1, 0.5)), 3)
    return "the part drawn in the air `above the table`"


def unknown_name(d: Data, rng: np.random.Generator) -> str:
    """A part or seam named that the map does not have (a typo in a name the user chose)."""
    sim = d.setdefault("simulation", {})
    choice = int(rng.integers(3))
    if choice == 0 and sim.get("deviations"):
        old = str(rng.choice(list(sim["deviations"])))
        sim["deviations"][old + "_X"] = sim["deviations"].pop(old)
        return f"simulation.deviations.{old} renamed `{old}_X`"
    if choice == 1:
        d.setdefault("process", {})["seam_leg_mm"] = {"NO_SUCH>SEAM:+z": 5.0}
        return "process.seam_leg_mm for a seam `NO_SUCH>SEAM:+z` not in the map"
    sim.setdefault("faults", {})["missing_parts"] = ["NO_SUCH_PART"]
    return "simulation.faults.missing_parts names a part `NO_SUCH_PART` not in the map"


DATA_KINDS: dict[str, Callable[[Data, np.random.Generator], str]] = {
    "camera_far": camera_far,
    "camera_in_table": camera_in_table,
    "camera_away": camera_away,
    "camera_short": camera_short,
    "camera_moved_off": camera_moved_off,
    "robot_in_table": robot_in_table,
    "robot_upside_down": robot_upside_down,
    "robot_facing_away": robot_facing_away,
    "scan_unreachable": scan_unreachable,
    "home_out": home_out,
    "seed_text": seed_text,
    "gate_loose": gate_loose,
    "part_above": part_above,
    "unknown_name": unknown_name,
    "corrupt_value": corrupt_value,
    "corrupt_shape": corrupt_shape,
    "corrupt_key": corrupt_key,
    "delete_required": delete_required,
}


TEXT_KINDS = {"duplicate_key": duplicate_key, "broken_yaml": broken_yaml}
KINDS = (*DATA_KINDS, *TEXT_KINDS)


def mutant(seed: int, index: int, sources: tuple[str, ...] = SOURCES) -> Mutant:
    """The ``index``-th nonsense scenario of the seeded sequence ``seed`` (each kind in turn, a random source)."""
    rng = np.random.default_rng([seed, index])
    kind = KINDS[index % len(KINDS)]
    source = sources[int(rng.integers(len(sources)))]
    text, data = _source(source)
    if kind in TEXT_KINDS:
        new, what = TEXT_KINDS[kind](text, rng)
    else:
        what = DATA_KINDS[kind](data, rng)
        new = _dump(data)
    return Mutant(index, source, kind, what, new)


def mutants(seed: int, n: int, sources: tuple[str, ...] = SOURCES) -> list[Mutant]:
    return [mutant(seed, i, sources) for i in range(n)]


# -- the verdict -------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Verdict:
    """What ``cell scenario check`` made of one mutant: ``verdict`` one of VERDICTS, the exit code, the line that
    refused or the warnings it added, the time it took [s]."""

    mutant: Mutant
    verdict: str
    exit_code: int
    lines: tuple[str, ...]
    seconds: float


def _run_check(path: Path) -> tuple[int, str, BaseException | None]:
    from typer.testing import CliRunner

    from cell.cli import app

    result = CliRunner().invoke(app, ["scenario", "check", str(path)], catch_exceptions=True)
    exc = result.exception if not isinstance(result.exception, SystemExit) else None
    return result.exit_code, result.output, exc


def _warnings(output: str) -> set[str]:
    return {ln.strip() for ln in output.splitlines() if ln.startswith("warning:")}


_BASELINE: dict[str, set[str]] = {}


def baseline(source: str) -> set[str]:
    """The warnings ``scenario check`` gives the unmutated source (a mutant must add one to be flagged)."""
    if source not in _BASELINE:
        code, output, exc = _run_check(REPO / "scenarios" / f"{source}.yaml")
        assert code == 0 and exc is None, f"{source}: {output}"
        _BASELINE[source] = _warnings(output)
    return _BASELINE[source]


def judge(m: Mutant) -> Verdict:
    """Run ``cell scenario check`` on the mutant, written beside the shipped scenarios' maps (a temporary folder
    holding a copy would not find ``../maps``: the loader also looks in maps/ by name)."""
    import time

    base = baseline(m.source)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{m.source}-{m.kind}-{m.index}.yaml"
        path.write_text(m.text, encoding="utf-8")
        t0 = time.perf_counter()
        code, output, exc = _run_check(path)
        seconds = time.perf_counter() - t0
    if exc is not None:
        return Verdict(m, "traceback", code, (f"{type(exc).__name__}: {exc}",), seconds)
    errors = [ln.strip() for ln in output.splitlines() if ln.startswith("error")]
    if code != 0:
        if len(errors) != 1 or "Traceback" in output:
            return Verdict(m, "traceback", code, tuple(errors) or (output[-300:],), seconds)
        return Verdict(m, "refused" if _names_it(m, errors) else "silent", code, tuple(errors), seconds)
    new = sorted(_warnings(output) - base)
    return Verdict(m, "flagged" if _names_it(m, new) else "silent", code, tuple(new), seconds)


def _names_it(m: Mutant, lines: list[str]) -> bool:
    """Whether an error or a new warning names what was done (a `marked` word of ``m.what``, any case): a line
    about something else does not count."""
    marks = re.findall(r"`([^`]+)`", m.what)
    text = " ".join(lines).lower()
    return bool(lines) and (not marks or any(k.lower() in text for k in marks))


def summary(verdicts: list[Verdict]) -> dict[str, Any]:
    """Counts per verdict and per kind, and each mutant that was silently accepted or gave a traceback."""
    by_kind: dict[str, dict[str, int]] = {}
    for v in verdicts:
        row = by_kind.setdefault(v.mutant.kind, dict.fromkeys(VERDICTS, 0))
        row[v.verdict] += 1
    bad = [v for v in verdicts if v.verdict in ("silent", "traceback")]
    return {
        "n": len(verdicts),
        **{k: sum(v.verdict == k for v in verdicts) for k in VERDICTS},
        "max_seconds": round(max((v.seconds for v in verdicts), default=0.0), 2),
        "by_kind": by_kind,
        "not_flagged": [
            {
                "index": v.mutant.index,
                "source": v.mutant.source,
                "kind": v.mutant.kind,
                "what": v.mutant.what,
                "verdict": v.verdict,
                "lines": list(v.lines),
            }
            for v in bad
        ],
    }
