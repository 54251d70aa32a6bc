"""Options of our map-guided seam locator (:mod:`cell.seams.ours`)."""

from __future__ import annotations

from dataclasses import dataclass

from cell.seams._index import INDEX_SHARES
from cell.types import Box


@dataclass(frozen=True)
class OursOptions:
    """Options of :class:`OursLocator` (defaults suit RealSense D4xx-class clouds at 1-2 m); lengths [m]."""

    tube_radius_m: float = 0.06  # points within this distance of the map seam are looked at
    extend_m: float = 0.02  # ... and this far past the map's ends
    corner_band_m: float = 0.005  # least band excluded next to the other weld face (gap, shadow, corner noise)
    edge_band_m: float = 0.004  # band excluded along convex edges (flying pixels, side faces)
    map_tolerance_m: float = 0.006  # how far the as-built faces and ends may lie from the aligned map
    sensor_sigma_m: float = 0.003  # depth noise assumed before it is measured
    gate_sigmas: float = 3.5  # half-width of the gate around a plane, in measured noise scales
    passes: int = 2  # fits: the first from the map with wide gates, the others with measured noise and ends
    min_face_points: int = 30  # fewer supporting points (dense cloud's) on a weld face: place it from an edge
    min_end_points: int = 40  # fewer points on a side face of A: take the end from the extent instead
    min_end_fill: float = 0.04  # ... or fewer than this fraction of the points its area would hold seen well
    refine_normals: bool = True  # let a face tilt off the map's normal in the last pass (as-built parts tilt)
    tilt_prior_deg: float = 0.05  # ... standard deviation of the tilt's Gaussian prior [deg]
    sample_share: float = 0.25  # share of the dense cloud looked at (layers of INDEX_SHARES: 0.25, 0.5 or 1)
    edge_sample_share: float = 1.0  # ... where an unseen face is placed from an edge (an edge needs every point)
    max_points: int = 40000  # random subsample of the tube above this
    max_fit_points: int = 1000  # a plane is fitted to an even stride of its support above this
    target_se_m: float = 0.0002  # standard error of the seam's position that still earns full confidence
    min_edge_points: int = 20  # fewer points just inside an edge: it does not place an unseen face
    max_edge_strays: float = 0.3  # more density beyond an edge (share of that inside): it places nothing
    edge_pitch_factor: float = 0.15  # an edge's sampling error, in point pitches on its face [-] (0.29: aligned grid)
    workspace_R: Box | None = None  # where the cloud was cropped (frame R); None: the cloud's bounds along R's axes

    def __post_init__(self) -> None:
        if self.passes < 1 or self.min_face_points < 3 or self.min_end_points < 3 or self.min_edge_points < 3:
            raise ValueError(
                "ours options need passes >= 1, min_face_points >= 3, min_end_points >= 3 and min_edge_points >= 3"
            )
        if self.sample_share not in INDEX_SHARES or self.edge_sample_share not in INDEX_SHARES:
            raise ValueError(f"ours options need sample_share and edge_sample_share among {INDEX_SHARES}")
        if self.tube_radius_m <= self.corner_band_m or self.tilt_prior_deg <= 0.0:
            raise ValueError("ours options need tube_radius_m > corner_band_m and tilt_prior_deg > 0")
