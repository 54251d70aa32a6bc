"""Options of the seam locators (:mod:`cell.seams`): the paper's, RANSAC's and ours; lengths [m].

What a scenario can set (``locator: {method: <name>, options: {...}}``); the run-time values a locator also needs
(ours' workspace crop in R) are added by the registry when it builds the locator.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from cell.config.bounds import Bounds, check_bounds
from cell.errors import ScenarioError

# How far an as-built part's faces and ends may lie from the aligned map [m]: the paper's industrial tolerances
# (docs/reference.md: 1 % of a part's width and location, 5 % of its length) on the public parts' members, a few mm.
# The one source of the part tolerance: our locator's ``map_tolerance_m`` default, and the sigma of an end that only
# the drawn length places (cell/seams/sigma.py).
PART_TOLERANCE_M = 0.006
INDEX_SHARES = (0.25, 0.5, 1.0)  # shares of the dense cloud a query may ask for (1 / k: every k-th point)
Positive = Bounds(gt=0.0)


@dataclass(frozen=True)
class PaperOptions:
    """Options of the paper's locator (section 3.6); masks are (across, along) half-widths... as in eq. 5-6 [m]."""

    outer_mask_m: Annotated[tuple[float, float], Positive] = (0.03, 0.05)
    inner_mask_m: Annotated[tuple[float, float], Positive] = (0.015, 0.03)
    frequency_bin_m: Annotated[float, Positive] = 0.001

    def __post_init__(self) -> None:
        check_bounds(self)


@dataclass(frozen=True)
class RansacThresholds:
    """The spacing-dependent thresholds of one RANSAC region (:meth:`RansacOptions.thresholds`)."""

    distance: float  # RANSAC inlier distance [m]
    min_inliers: int  # least plane [points]
    clip_radius: float  # [m]
    clip_band: float  # [m]


@dataclass(frozen=True)
class RansacOptions:
    """Options of :class:`RansacLocator`; lengths [m]."""

    cloud: str = "voxel"  # "voxel": the paper's 1 cm cloud (scene.cloud); "dense": full resolution
    runs: int = 3  # independent runs per seam; the median is reported (paper: three)
    region_m: float = 0.05  # points within this distance of the map's seam segment (extended as far) are used
    distance_m: float = 0.003  # least RANSAC inlier distance ...
    distance_spacings: float = 0.3  # ... or this many point spacings, whichever is larger
    min_plane_area_m2: float = 0.0008  # a plane needs the points of this much area (8 cm^2) ...
    min_inliers: int = 6  # ... and at least this many points; a smaller plane ends the segmentation
    iterations: int = 300  # hypotheses per plane
    max_planes: int = 5  # planes segmented per region
    sample_points: int = 4000  # points used to score hypotheses (all region points are used for the refits)
    parallel_deg: float = 30.0  # planes closer than this in angle count as parallel
    match_deg: float = 20.0  # a plane matches a map face when their normals are this close
    match_offset_m: float = 0.01  # ... and it passes this close to the map's seam
    clip_radius_m: float = 0.015  # inliers this near the line (or 2 spacings) give its extent ...
    clip_band_m: float = 0.006  # ... unless this near the other plane (or 0.6 spacings): the corner
    clip_quantile: float = 0.01  # ... from this quantile to 1 - this (0: the extreme inliers)

    def __post_init__(self) -> None:
        if self.cloud not in ("dense", "voxel"):
            raise ScenarioError(f"ransac option cloud is {self.cloud!r}; valid: 'dense', 'voxel'")
        if self.runs < 1 or self.iterations < 1 or self.max_planes < 2 or self.min_inliers < 3:
            raise ScenarioError("ransac options need runs >= 1, iterations >= 1, max_planes >= 2 and min_inliers >= 3")

    def thresholds(self, spacing: float) -> RansacThresholds:
        """The spacing-dependent thresholds for a cloud of point spacing ``spacing`` [m]."""
        return RansacThresholds(
            distance=max(self.distance_m, self.distance_spacings * spacing),
            min_inliers=max(self.min_inliers, int(self.min_plane_area_m2 / spacing**2)),
            clip_radius=max(self.clip_radius_m, 2.0 * spacing),
            clip_band=max(self.clip_band_m, 0.6 * spacing),
        )


@dataclass(frozen=True)
class OursSettings:
    """What a scenario sets of our locator (:class:`~cell.seams.ours.OursOptions` adds the run's workspace crop);
    defaults suit RealSense D4xx-class clouds at 1-2 m; lengths [m]."""

    tube_radius_m: float = 0.06  # points within this distance of the map seam are looked at
    extend_m: float = 0.02  # ... and this far past the map's ends
    corner_band_m: float = 0.005  # least band excluded next to the other weld face (gap, shadow, corner noise)
    edge_band_m: float = 0.004  # band excluded along convex edges (flying pixels, side faces)
    map_tolerance_m: float = PART_TOLERANCE_M  # how far the as-built faces and ends may lie from the aligned map
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
    # Added in quadrature to the standard error for the reported sigma: what the fit cannot see (calibration, tilt);
    # 0.05 mm puts 96 % of the scenarios' seams within 2 sigma (benchmarks/bench_coverage.py, cell/seams/sigma.py).
    sigma_floor_m: float = 0.00005
    # Scales each end source's floor of the ends' sigmas along the seam (cell/seams/sigma.py, OURS_END_FLOOR_M): 1 for
    # the fixed cameras; up close the close-up's own (the re-scan sets it, CLOSEUP_OURS_OPTIONS).
    end_floor_scale: float = 1.0
    min_edge_points: int = 20  # fewer points just inside an edge: it does not place an unseen face
    max_edge_strays: float = 0.3  # more density beyond an edge (share of that inside): it places nothing
    edge_pitch_factor: float = 0.15  # an edge's sampling error, in point pitches on its face [-] (0.29: aligned grid)

    def __post_init__(self) -> None:
        if self.passes < 1 or self.min_face_points < 3 or self.min_end_points < 3 or self.min_edge_points < 3:
            raise ValueError(
                "ours options need passes >= 1, min_face_points >= 3, min_end_points >= 3 and min_edge_points >= 3"
            )
        if self.sample_share not in INDEX_SHARES or self.edge_sample_share not in INDEX_SHARES:
            raise ValueError(f"ours options need sample_share and edge_sample_share among {INDEX_SHARES}")
        if self.tube_radius_m <= self.corner_band_m or self.tilt_prior_deg <= 0.0:
            raise ValueError("ours options need tube_radius_m > corner_band_m and tilt_prior_deg > 0")
