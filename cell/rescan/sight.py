"""Which cameras of a cell will see each seam's two faces, predicted from the map at its nominal place before anything
is captured: the close-up view's own test (:func:`look`, on :mod:`cell.rescan.view_grid`'s samples: the seam line
and a strip of each weld face, all in the image, at the incidence a view allows, no other part in a line of sight)
and the camera's depth range. One frame for everything, the world W's or R's, as the caller gives it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from enum import StrEnum

import numpy as np

from cell.geometry import FloatArray, readonly
from cell.rescan.view_grid import ViewOptions, ViewTarget, _in_image, _incidence, _occluded, _samples
from cell.scenario import CameraSpec, Scenario
from cell.seams.joint import weld_faces
from cell.seams.visibility import visibility
from cell.types import CameraIntrinsics, Joint, Part, WeldMap

NO_TORCH = readonly(np.zeros((0, 3)))  # a fixed camera's torch axis: none in its image


@dataclass(frozen=True)
class Look:
    """What a camera at one pose makes of a seam's two weld faces, by :func:`cell.rescan.view_grid.sees`'s tests
    kept apart: ``in_view`` (every sample in the image with its margin, clear of the torch), the worst angle
    between a line of sight and face A's, face B's normal [deg] (90 when not in view), and whether a part stands
    in a line of sight to each face's strip (tested only for a face within the limit)."""

    in_view: bool
    incidence_deg: tuple[float, float]
    occluded: tuple[bool, bool]


def look(
    X_FC: FloatArray,
    target: ViewTarget,
    intrinsics: CameraIntrinsics,
    torch_C: FloatArray,
    parts: Sequence[Part],
    table_z: float,
    options: ViewOptions | None = None,
) -> Look:
    """:class:`Look` of ``target`` from a camera at X_FC (4, 4) in the target's frame F; ``torch_C`` (n, 3) the
    torch axis in the camera (:data:`NO_TORCH` for a fixed camera), ``parts`` those that may stand in the way,
    ``table_z`` [m] the table top in F (samples below it are dropped); the options' ``max_incidence_deg`` is the
    limit over which a face's lines of sight are not tested."""
    o = options or ViewOptions()
    pts, normals, face = _samples(target, table_z, o, parts)
    if not _in_image(X_FC, pts, intrinsics, torch_C, o):
        return Look(False, (90.0, 90.0), (False, False))
    _, inc_a, inc_b = _incidence(X_FC, pts, normals, face)
    hidden = []
    for k, inc in ((1, inc_a), (2, inc_b)):
        on = face == k  # a face's own strip: the seam line may run on into another part (a gusset's)
        hidden.append(
            inc <= o.max_incidence_deg and _occluded(X_FC[:3, 3], pts[on], normals[on], parts, o.occlusion_margin_m)
        )
    return Look(True, (inc_a, inc_b), (hidden[0], hidden[1]))


class Blind(StrEnum):
    """Why a camera will not see a weld face (the value is the message's words)."""

    OUT_OF_VIEW = "out of its image"
    GRAZING = "edge-on"
    OCCLUDED = "behind another part"
    OUT_OF_RANGE = "out of its depth range"


@dataclass(frozen=True)
class Lens:
    """A camera as the prediction needs it: its optical frame X_FC (4, 4) in the seams' frame F, pinhole
    intrinsics, depth range [m], the incidence [deg] up to which it sees a face well (``good_deg``) and at all
    (``max_deg``: beyond it the sensor drops the pixels, or too few are left to fit a face); ``torch_C`` the torch
    in its image (:func:`cell.rescan.view_grid.torch_axis_in_camera`) when it rides on the arm."""

    name: str
    X_FC: FloatArray
    intrinsics: CameraIntrinsics
    near_m: float
    far_m: float
    good_deg: float
    max_deg: float
    torch_C: FloatArray = field(default_factory=lambda: NO_TORCH)  # (n, 3) in the camera; none: a fixed camera

    def __post_init__(self) -> None:
        object.__setattr__(self, "X_FC", readonly(self.X_FC))
        object.__setattr__(self, "torch_C", readonly(self.torch_C))


@dataclass(frozen=True)
class CameraSight:
    """One camera's view of one seam: the worst incidence on face A and B [deg], the range from the camera to the
    seam's midpoint [m], and why it does not see each face (None: it does)."""

    camera: str
    incidence_deg: tuple[float, float]
    range_m: float
    blind: tuple[Blind | None, Blind | None]
    good_deg: float

    def sees(self, face: int) -> bool:
        """Whether it sees face ``face`` (0: A, 1: B)."""
        return self.blind[face] is None

    @property
    def seen(self) -> bool:
        """Both faces."""
        return self.sees(0) and self.sees(1)

    @property
    def grazing(self) -> bool:
        """A face it sees lies beyond the good incidence (fewer, noisier points)."""
        return any(self.sees(k) and self.incidence_deg[k] > self.good_deg for k in (0, 1))


@dataclass(frozen=True)
class SeamSight:
    """What every camera makes of one seam; ``faces`` names its two weld faces (``PART +y``); ``underside``: it lies
    against the table (no camera above it sees it; the part must be turned)."""

    seam_id: str
    faces: tuple[str, str]
    underside: bool
    cameras: tuple[CameraSight, ...]

    @property
    def seen_by(self) -> tuple[CameraSight, ...]:
        """The cameras that see both faces, best (smallest worst incidence) first."""
        return tuple(sorted((c for c in self.cameras if c.seen), key=lambda c: (max(c.incidence_deg), c.camera)))

    def face_seen_by(self, face: int) -> tuple[CameraSight, ...]:
        """The cameras that see face ``face`` (0: A, 1: B), best first."""
        return tuple(sorted((c for c in self.cameras if c.sees(face)), key=lambda c: (c.incidence_deg[face], c.camera)))

    @property
    def seen(self) -> bool:
        """Each face is seen by some camera (the locator fits them in the cameras' spliced cloud)."""
        return not self.underside and all(self.face_seen_by(k) for k in (0, 1))


def seam_target(weldmap: WeldMap, joint: Joint) -> ViewTarget:
    """The map seam of ``joint`` as a view target: its drawn ends and its weld faces' normals (the map's frame)."""
    seam = weldmap.seam(joint.seam_id)
    n_a, _, n_b, _ = weld_faces(weldmap, joint)
    return ViewTarget(seam.id, seam.p_start, seam.p_end, n_a, n_b)


def occluders(weldmap: WeldMap, joint: Joint) -> tuple[Part, ...]:
    """The parts that may stand between a camera and the seam: all but the joint's own two (as the re-scan's)."""
    return tuple(p for p in weldmap.parts if p.name not in (joint.abutting, joint.receiving))


def camera_sight(
    lens: Lens, target: ViewTarget, parts: Sequence[Part], table_z: float, view: ViewOptions
) -> CameraSight:
    """How ``lens`` sees ``target`` (:class:`CameraSight`): the view's tests at the lens's incidence limit."""
    ends = np.stack([target.p_start, target.p_end, target.mid])
    dist = np.linalg.norm(ends - lens.X_FC[:3, 3], axis=1)
    o = replace(view, max_incidence_deg=lens.max_deg)
    seen = look(lens.X_FC, target, lens.intrinsics, lens.torch_C, parts, table_z, o)
    blind: list[Blind | None] = []
    for k in (0, 1):
        if not seen.in_view:
            blind.append(Blind.OUT_OF_VIEW)
        elif dist.max() > lens.far_m or dist.min() < lens.near_m:
            blind.append(Blind.OUT_OF_RANGE)
        elif seen.incidence_deg[k] > lens.max_deg:
            blind.append(Blind.GRAZING)
        else:
            blind.append(Blind.OCCLUDED if seen.occluded[k] else None)
    return CameraSight(lens.name, seen.incidence_deg, float(dist[2]), (blind[0], blind[1]), lens.good_deg)


def predict(
    weldmap: WeldMap,
    joints: Mapping[str, Joint],
    lenses: Sequence[Lens],
    table_z: float,
    view: ViewOptions | None = None,
) -> tuple[SeamSight, ...]:
    """Every seam of ``weldmap`` (in the lenses' frame, +z up, table top at ``table_z`` [m]) as each lens sees it,
    in the map's order; a seam against the table is marked ``underside`` and looked at by none."""
    o = view or ViewOptions()
    out = []
    for seam in weldmap.seams:
        joint = joints[seam.id]
        faces = (f"{joint.abutting} {joint.face_abutting}", f"{joint.receiving} {joint.face_receiving}")
        if not visibility(weldmap, joint, table_z)[0]:
            out.append(SeamSight(seam.id, faces, True, ()))
            continue
        target, parts = seam_target(weldmap, joint), occluders(weldmap, joint)
        out.append(SeamSight(seam.id, faces, False, tuple(camera_sight(c, target, parts, table_z, o) for c in lenses)))
    return tuple(out)


def lens(
    name: str,
    X_FC: FloatArray,
    resolution: tuple[int, int],
    hfov_deg: float,
    near_m: float,
    far_m: float,
    good_deg: float,
    max_deg: float,
) -> Lens:
    """A :class:`Lens` with square pixels and the principal point at the image centre (as the simulator renders)."""
    w, h = resolution
    f = 0.5 * w / float(np.tan(np.radians(hfov_deg) / 2.0))
    K = CameraIntrinsics(w, h, f, f, (w - 1) / 2.0, (h - 1) / 2.0)
    return Lens(name, np.asarray(X_FC, dtype=float), K, near_m, far_m, good_deg, max_deg)


def camera_lens(name: str, cam: CameraSpec, view: ViewOptions, torch_C: FloatArray = NO_TORCH) -> Lens:
    """A scenario camera as a lens in the world W (an eye-in-hand camera at its scan pose): where it is, its image,
    its depth range; a face is seen well up to the view's ``max_incidence_deg`` and at all up to its grazing
    fallback's ``fallback_max_incidence_deg`` (less where the sensor drops grazing pixels:
    ``noise.grazing_dropout_deg``); ``torch_C`` (n, 3) the torch in its image when it rides on the arm."""
    most = min(view.fallback_max_incidence_deg, cam.noise.grazing_dropout_deg)
    good = min(view.max_incidence_deg, most)
    bare = lens(name, cam.X_WC, cam.resolution, cam.hfov_deg, cam.near_m, cam.far_m, good, most)
    return replace(bare, torch_C=np.asarray(torch_C, dtype=float))


def first_scan_sight(scenario: Scenario, weldmap_M: WeldMap, torch_C: FloatArray = NO_TORCH) -> tuple[SeamSight, ...]:
    """Every seam of the map (frame M, placed at the scenario's nominal ``map.X_WM``) as the cameras of the first
    scan will see it: the fixed ones and the eye-in-hand one at its scan pose, past the torch (``torch_C`` (n, 3) in
    its image); the view options of ``rescan.closeup.view``."""
    from cell.seams.joint import find_joints

    view = scenario.rescan.closeup.view
    weldmap_W = weldmap_M.transformed(scenario.X_WM, "W")
    lenses = [
        camera_lens(n, c, view, torch_C if c.mount == "eye_in_hand" else NO_TORCH) for n, c in scenario.cameras.items()
    ]
    return predict(weldmap_W, find_joints(weldmap_M), lenses, scenario.table.top_z, view)


def pose_sight(
    weldmap_W: WeldMap,
    table_z: float,
    poses: Sequence[tuple[FloatArray, FloatArray, FloatArray]],
    on_arm: Sequence[bool],
    *,
    torch_C: FloatArray = NO_TORCH,
    view: ViewOptions | None = None,
) -> FloatArray:
    """(poses, seams, 2) the worst incidence [deg] on each seam's face A and B from a camera of the scenario's
    default model (:class:`~cell.scenario.CameraSpec`) at each (eye, target, up) (3,) in W (past the torch, ``torch_C``
    (n, 3), where ``on_arm``), inf where it does not see that face, nan for a seam against the table (``table_z``
    [m]): what ``cell init`` lays its cameras out by."""
    from cell.seams.joint import find_joints

    o = view or ViewOptions()
    joints = find_joints(weldmap_W)
    lenses = [
        camera_lens(str(k), CameraSpec(eye_m=_vec3(e), target_m=_vec3(t), up=_vec3(u)), o, torch_C if arm else NO_TORCH)
        for k, ((e, t, u), arm) in enumerate(zip(poses, on_arm, strict=True))
    ]
    out = np.full((len(poses), len(weldmap_W.seams), 2), np.inf)
    for j, seen in enumerate(predict(weldmap_W, joints, lenses, table_z, o)):
        if seen.underside:
            out[:, j, :] = np.nan
        for i, c in enumerate(seen.cameras):
            for k in (0, 1):
                if c.sees(k):
                    out[i, j, k] = c.incidence_deg[k]
    return out


def _vec3(v: FloatArray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


__all__ = [
    "NO_TORCH",
    "Blind",
    "CameraSight",
    "Lens",
    "Look",
    "SeamSight",
    "camera_lens",
    "camera_sight",
    "first_scan_sight",
    "lens",
    "look",
    "occluders",
    "pose_sight",
    "predict",
    "seam_target",
]
