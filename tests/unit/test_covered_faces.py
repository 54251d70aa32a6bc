"""A weld face another part covers near the seam (maps/brace.dxf: the brace's upper end meets POST_R below the top
rail, so the post's face beside the brace is a strip of under 30 mm): the close-up planner asks to see only the free
part of it (the 30 mm strip ran into the rail, and no view passed the line-of-sight test: the seam was never
re-scanned)."""

from __future__ import annotations

import math

import pytest
from dxf_factory import REPO_ROOT
from tiny_cell import URDF

from cell.motion.robot import RobotModel
from cell.rescan.view_grid import ViewTarget, ranked_views, torch_axis_in_camera
from cell.seams.joint import find_joints, weld_faces
from cell.sim.camera import intrinsics_for
from cell.types import Joint, Part, WeldMap
from cell.weldmap import read_map

K = intrinsics_for(1280, 720, math.radians(65.0))  # the D415 of the scenarios
UPPER = "BRACE>POST_R:upper"


@pytest.fixture(scope="module")
def brace() -> tuple[WeldMap, dict[str, Joint]]:
    weldmap = read_map(REPO_ROOT / "maps" / "brace.dxf")
    return weldmap, find_joints(weldmap)


def _third(weldmap: WeldMap, joint: Joint) -> tuple[Part, ...]:
    return tuple(p for p in weldmap.parts if p.name not in (joint.abutting, joint.receiving))


def test_a_face_strip_the_rail_covers_still_has_close_up_views(brace: tuple[WeldMap, dict[str, Joint]]) -> None:
    weldmap, joints = brace
    seam, joint = weldmap.seam(UPPER), joints[UPPER]
    n_a, _, n_b, _ = weld_faces(weldmap, joint)
    target = ViewTarget(UPPER, seam.p_start, seam.p_end, n_a, n_b)
    torch_C = torch_axis_in_camera(RobotModel.from_urdf(URDF))
    table_z = float(min(p.vertices()[:, 2].min() for p in weldmap.parts))
    views = ranked_views(target, K, torch_C, _third(weldmap, joint), table_z)
    first = next(views, None)
    assert first is not None  # none before: the 30 mm strip's far samples lay inside the top rail
    assert max(first.incidence) <= 72.0
