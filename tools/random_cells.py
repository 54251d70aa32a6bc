"""Generate random welding cells (a map, a scenario and what was generated), reproducible from a seed alone.

Run from the repository root::

    .venv/bin/python tools/random_cells.py --seed 1 --count 20 --out /tmp/cells            # random weldments
    .venv/bin/python tools/random_cells.py --seed 1 --count 1 --out /tmp/cells --kind mitred_ladder:30

Each cell is a folder ``DIR/cell-<seed>/`` holding ``map.dxf`` (the drawing, ``tools/random_cell_parts.py``),
``scenario.yaml`` (what ``cell detect``, ``cell weld`` and :func:`cell.scenario.load` read) and ``truth.json`` (the
parts, seams, cameras, noise and deviations drawn: :func:`truth`). ``kind`` is ``random`` (a weldment of plates,
boxes, RHS, flat bars and mitred braces among round tubes: ``tools/random_cell_weldment.py``) or a named layout
(``tools/random_cell_layouts.py``: ``post_pipes``, ``web_tube[:YAW]``, ``mitred_ladder[:ANGLE]``). Every draw comes
from one ``np.random.default_rng(seed)``; a draw that fails a check (the map reads and every seam has the joint it
was drawn with, the scenario loads with no layout warning, the arm reaches its scan pose, the deviations apply) is
drawn again from the same generator, and the truth says how many times (``redraws``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))  # the sibling modules below, also when loaded by path

from random_cell_build import deviations, realism
from random_cell_layouts import Design, named
from random_cell_parts import write_map
from random_cell_scene import Camera, Placement, fixed_cameras, init_cameras, place, r6, scan_pose, scenario_dict, t3
from random_cell_weldment import random_design

from cell.errors import CellError
from cell.types import WeldMap

MAX_REDRAWS = 25
FILES = ("map.dxf", "scenario.yaml", "truth.json")


@dataclass(frozen=True)
class RandomCell:
    """A generated cell: its seed, ``kind`` (``random`` or a named layout), and its three files."""

    seed: int
    kind: str
    scenario: Path
    map: Path
    truth: Path


class RejectedDrawError(Exception):
    """A draw that fails one of the cell's checks (drawn again); ``why`` in one line."""


def _check_map(path: Path, design: Design) -> WeldMap:
    """The map as the cell reads it; every seam drawn gets the joint (abutting, receiving) it was drawn with."""
    from cell.seams.joint import find_joints
    from cell.weldmap import read_map

    weldmap = read_map(path)
    if not weldmap.seams:  # curved seams only: nothing the cell welds yet
        raise RejectedDrawError(f"no straight seam ({len(weldmap.curved)} curved)")
    joints = find_joints(weldmap)
    for s in design.seams:
        j = joints[s.id]
        if (j.abutting, j.receiving) != (s.abutting, s.receiving):
            raise RejectedDrawError(f"seam {s.id} read as {j.abutting}>{j.receiving}")
    if len(weldmap.curved) != len(design.circles) or weldmap.unsupported:
        raise RejectedDrawError(f"{len(weldmap.curved)} curved seams read, {len(design.circles)} circles drawn")
    return weldmap


def _check_scenario(path: Path, weldmap: WeldMap) -> None:
    """The scenario loads, ``cell scenario check`` has nothing to say, the as-built parts can be made, and the arm
    reaches the scan pose."""
    from cell import scenario as sc
    from cell.pipeline.geometry import robot_arm
    from cell.scenario.init import check_layout
    from cell.sim.asbuilt.parts import as_built_parts

    scn = sc.load(path)
    problems = check_layout(scn, weldmap)
    if problems:
        raise RejectedDrawError(problems[0])
    as_built_parts(weldmap, scn)
    robot_arm(scn)


def _cameras(kind: str, placement: Placement, rng: np.random.Generator) -> list[Camera]:
    """The fixed cameras and the arm camera. Named layouts: exact extrinsics stated 0, realistic stereo noise
    (``web_tube`` and ``mitred_ladder`` with cell init's pair, ``post_pipes`` three around the part); random: 2-4
    anywhere in range, each structured light or active stereo, extrinsics exact or perturbed with the matching
    stated calibration."""
    name = kind.partition(":")[0]
    if name in ("web_tube", "mitred_ladder"):
        pairs, up = init_cameras(placement), (0.0, 1.0, 0.0)
        names = ["cam_left", "cam_right"]
    else:
        count = 3 if name != "random" else int(rng.integers(2, 5))
        pairs = fixed_cameras(placement, rng, count, azimuth0=rng.uniform(0, 360) if name != "random" else None)
        up, names = (0.0, 0.0, 1.0), [f"cam_{k + 1}" for k in range(count)]
    perturbed = name == "random" and bool(rng.random() < 0.5)
    cams = []
    for cam_name, (eye, target) in zip(names, pairs, strict=True):
        model = "active_stereo" if name != "random" or rng.random() < 0.7 else "structured_light"
        err = (r6(rng.uniform(0.3, 1.0)), r6(rng.uniform(0.03, 0.1))) if perturbed else (0.0, 0.0)
        cams.append(Camera(cam_name, "fixed", t3(eye), t3(target), up, model, err, err))
    eye, target = scan_pose(placement, rng if name == "random" else None)
    cams.append(
        Camera(
            "eye_in_hand", "eye_in_hand", t3(eye), t3(target), (0.0, 0.0, 1.0), "active_stereo", (0.0, 0.0), (0.0, 0.0)
        )
    )
    return cams


def _draw(seed: int, kind: str, rng: np.random.Generator, out: Path) -> dict[str, Any]:
    """One draw of the whole cell written to ``out``; the truth's fields. RejectedDrawError when a check fails."""
    from cell.errors import IKError

    design, yaw = random_design(rng) if kind == "random" else named(kind)
    map_path = write_map(out / FILES[0], design.bodies, design.seams, design.circles)
    try:
        weldmap = _check_map(map_path, design)
    except CellError as err:
        raise RejectedDrawError(str(err)) from None
    if kind == "random":
        yaw = r6(rng.uniform(0.0, 360.0))
    placement = place(weldmap, yaw, rng if kind == "random" else None)
    if placement is None:
        raise RejectedDrawError("no place on the table within the arm's reach")
    cameras = _cameras(kind, placement, rng)
    simulation: dict[str, Any] = {"noise": "realistic"}
    if kind == "random":
        simulation = realism(rng)
        simulation["deviations"] = deviations(rng, design, weldmap)
    name = f"{kind.replace(':', '-')}-{seed}"
    text = scenario_dict(
        name,
        seed,
        FILES[0],
        placement,
        cameras,
        simulation,
        f"Generated by tools/random_cells.py (seed {seed}, {kind})",
    )
    (out / FILES[1]).write_text(
        yaml.safe_dump(text, sort_keys=False, width=120, default_flow_style=None), encoding="utf-8"
    )
    try:
        _check_scenario(out / FILES[1], weldmap)
    except (CellError, IKError) as err:
        raise RejectedDrawError(str(err)) from None
    return truth(design, weldmap, placement, cameras, simulation)


def truth(
    design: Design, weldmap: WeldMap, placement: Placement, cameras: Sequence[Camera], simulation: dict[str, Any]
) -> dict[str, Any]:
    """What was generated: parts and fixtures (kind, pose, size [mm]), each seam's drawn ends [mm, M] with the
    joint kind and dihedral the cell's joint finder gives it, curved seams, the placement, the cameras (distance,
    elevation, azimuth from the part's centre; extrinsic error and stated calibration), noise and deviations."""
    from cell.seams.joint import dihedral, find_joints, joint_kind

    joints = find_joints(weldmap)
    bodies = [
        {
            "name": b.name,
            "kind": b.kind,
            "drawn_as": b.drawn_as,
            "pose": {"centre_mm": list(t3(b.centre_mm)), "rpy_deg": list(t3(b.rpy_deg))},
            "size_mm": list(t3(b.size_mm)),
            **{k: r6(v) for k, v in b.extra.items()},
        }
        for b in design.bodies
    ]
    seams = [
        {
            "id": s.id,
            "p0_mm": list(t3(s.p0)),
            "p1_mm": list(t3(s.p1)),
            "length_mm": r6(s.length_mm),
            "abutting": s.abutting,
            "receiving": s.receiving,
            "joint": joint_kind(weldmap, joints[s.id]),
            "dihedral_deg": r6(math.degrees(dihedral(weldmap, joints[s.id]))),
        }
        for s in design.seams
    ]
    cams = [
        {
            "name": c.name,
            "mount": c.mount,
            "eye_m": list(c.eye_m),
            "target_m": list(c.target_m),
            "distance_m": r6(c.distance_m),
            "elevation_deg": r6(c.elevation_deg),
            "azimuth_deg": r6(c.azimuth_deg),
            "noise_model": c.model,
            "extrinsic_error": {"translation_mm": c.error[0], "rotation_deg": c.error[1]},
            "calibration": {"translation_mm": c.calibration[0], "rotation_deg": c.calibration[1]},
        }
        for c in cameras
    ]
    return {
        "placement": {
            "X_WM": {"xyz_m": list(placement.xyz_m), "rpy_deg": [0.0, 0.0, r6(placement.yaw_deg)]},
            "part_centre_m": list(t3(placement.centre_W)),
        },
        "parts": [b for b in bodies if b["kind"] != "fixture"],
        "fixtures": [b for b in bodies if b["kind"] == "fixture"],
        "seams": seams,
        "ends_against": [{"part": m, "against": host} for m, host in design.ending],
        "curved_seams": [
            {"id": c.id, "centre_mm": list(t3(c.centre)), "radius_mm": r6(c.radius)} for c in design.circles
        ],
        "cameras": cams,
        "noise": simulation.get("noise", "realistic"),
        "deviations": simulation.get("deviations", {}),
        "realism": {k: v for k, v in simulation.items() if k not in ("noise", "deviations")},
        "facts": {k: r6(v) for k, v in design.facts.items()},
    }


def cell_folder(root: Path, seed: int) -> Path:
    """Where the command line writes the cell of ``seed`` under ``root``: ``root/cell-<seed>``."""
    return Path(root) / f"cell-{seed}"


def _without_folder(message: str, folder: Path) -> str:
    """A rejection's reason without the output folder in it (the truth is the same wherever it is written)."""
    for prefix in dict.fromkeys((str(folder.resolve()), str(folder))):
        message = message.replace(prefix + "/", "")
    return message


def make_cell(seed: int, out_dir: Path, kind: str = "random") -> RandomCell:
    """Generate the cell of ``seed`` and ``kind`` into the folder ``out_dir`` (made if needed; its ``map.dxf``,
    ``scenario.yaml`` and ``truth.json`` are overwritten). The same seed and kind give byte-identical files.
    Raises RuntimeError when :data:`MAX_REDRAWS` draws all fail a check, ValueError for an unknown kind."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    if kind != "random":
        named(kind)  # an unknown kind is refused before anything is drawn
    rng = np.random.default_rng(seed)
    why: list[str] = []
    for redraws in range(MAX_REDRAWS):
        try:
            fields = _draw(seed, kind, rng, out_dir)
        except RejectedDrawError as err:
            why.append(_without_folder(str(err), out_dir))
            continue
        record = {
            "format": "weld-cell-random-truth",
            "version": 1,
            "seed": seed,
            "kind": kind,
            "redraws": redraws,
            "rejected": why,
            **fields,
        }
        (out_dir / FILES[2]).write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
        return RandomCell(seed, kind, out_dir / FILES[1], out_dir / FILES[0], out_dir / FILES[2])
    raise RuntimeError(f"seed {seed} ({kind}): {MAX_REDRAWS} draws failed; last: {why[-1]}")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--seed", type=int, required=True, help="the first cell's seed")
    parser.add_argument("--count", type=int, default=1, help="how many cells (seeds S..S+N-1)")
    parser.add_argument("--out", type=Path, required=True, help="folder; each cell goes to OUT/cell-<seed>/")
    parser.add_argument("--kind", default="random", help="random, post_pipes, web_tube[:YAW], mitred_ladder[:ANGLE]")
    args = parser.parse_args(argv)
    for seed in range(args.seed, args.seed + args.count):
        cell = make_cell(seed, cell_folder(args.out, seed), args.kind)
        t = json.loads(cell.truth.read_text(encoding="utf-8"))
        fixed = sum(c["mount"] == "fixed" for c in t["cameras"])
        print(
            f"{cell.scenario}: {cell.kind}, {len(t['parts'])} parts, {len(t['seams'])} seams, "
            f"{len(t['curved_seams'])} curved, {fixed} fixed cameras, noise {t['noise']}, redraws {t['redraws']}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
