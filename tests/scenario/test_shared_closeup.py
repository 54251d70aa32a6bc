"""A close-up taken for one seam serves the other seams still to re-scan that it sees as well as a view of their
own must (cell.pipeline.rescan.shared_by), each with the view as it is for that seam; none farther than the
radius looked for, none that fails a view's tests (fence1's detection, each seam's best ranked view)."""

from __future__ import annotations

import numpy as np

from cell import pipeline
from cell.pipeline.rescan import _SHARE_RADIUS, _Run, shared_by
from cell.rescan.fusion import eye_in_hand_camera, occluders, view_target
from cell.rescan.view_grid import ranked_views, sees, torch_axis_in_camera
from cell.station.sim import SimStation
from cell.types import SeamStatus
from cell.types.rescan import Viewpoint
from cell.types.trajectory import Trajectory


def test_a_close_up_is_shared_only_with_the_seams_it_sees(
    fence1_detection: pipeline.Detection, fence1_station: SimStation
) -> None:
    det, station = fence1_detection, fence1_station
    assert det.scene is not None and station.arm is not None
    sc, ss = det.scenario, det.scene.seam_scene
    o = sc.rescan.closeup
    camera = eye_in_hand_camera(sc, o.camera)
    K, torch_C = station.intrinsics(camera), torch_axis_in_camera(station.arm.model, o.view)
    found = {e.id: e for e in det.estimates if e.status is SeamStatus.FOUND}
    targets = {i: view_target(ss, ss.weldmap.seam(i), e) for i, e in found.items()}
    run = _Run(station, station.arm, det, o, camera, None, None, station.arm.q_scan)  # type: ignore[arg-type]
    shared_any = 0
    for sid in sorted(found):
        best = next(ranked_views(targets[sid], K, torch_C, occluders(ss, sid), ss.table_z, o.view))
        q = np.asarray(station.arm.q_scan, dtype=float)
        still = Trajectory(np.array([0.0, 0.1]), np.stack([q, q]), np.zeros((2, len(q))), np.zeros((2, len(q))))
        vp = Viewpoint(sid, best.X_RC, q, still, 0.36, best.incidence, best.tilt, best.slant, best.roll, 1)
        pending = [i for i in found if i != sid]
        got = dict(shared_by(run, vp, pending))
        shared_any += len(got)
        for other in pending:
            near = float(np.linalg.norm(targets[other].mid - targets[sid].mid)) <= _SHARE_RADIUS
            seen = sees(best.X_RC, targets[other], K, torch_C, occluders(ss, other), ss.table_z, o.view)
            assert (other in got) == (near and seen is not None), other
            if other in got:
                view = got[other]
                assert view.seam_id == other and view.tried == 0 and view.incidence_deg == seen
                assert view.distance_m == np.linalg.norm(best.X_RC[:3, 3] - targets[other].mid)
    # fence1's seams lie too far apart or face away from each other's best views: its re-scan takes an image per
    # seam, as before sharing (its weld's figures are unchanged); the ladder's rungs share (docs/track.md)
    assert shared_any == 0
