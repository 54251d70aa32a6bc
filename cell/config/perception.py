"""Options of perception's checks (:mod:`cell.perception`): camera health, the map fit's uniqueness, whether the
map lies on the cloud, the seam screen. Lengths [m]."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class HealthOptions:
    """Thresholds of the camera checks (defaults suit D4xx-class depth cameras at 1-2.5 m)."""

    min_valid_fraction: float = 0.01  # fewer valid pixels: the camera is dead or blinded
    max_constant_fraction: float = 0.5  # more valid pixels reading one identical value: stuck sensor
    rough_jump_m: float = 0.05  # a depth step to a neighbour pixel larger than this (and 5 % of the depth) ...
    max_rough_fraction: float = 0.2  # ... on more than this share of neighbour pairs: not a scene, garbage
    agree_voxel_m: float = 0.005  # clouds are compared on a grid of this [m] (averages the depth noise)
    agree_tol_m: float = 0.01  # a point agrees with another camera if that camera has a point this near [m]
    min_agreement: float = 0.5  # share of a camera's points that must agree with some other camera
    table_check: bool = True  # each camera's depth scale and focal length checked on the table (a flagged one lost)


@dataclass(frozen=True)
class SymmetryOptions:
    """Thresholds of :func:`~cell.perception.check_alignment_unique`; lengths [m]."""

    band_m: float = 0.01  # a map sample is supported if a cloud point lies this near
    spacing_m: float = 0.005  # map sample spacing
    min_self_overlap: float = 0.6  # alternatives that keep less of the map on itself are not near-symmetries
    min_margin: float = 0.3  # the chosen fit must be supported this much more than any alternative
    min_distinct: int = 50  # fewer telling samples: the map is exactly symmetric there (see the docstring)


@dataclass(frozen=True)
class ScreenOptions:
    """Thresholds of :func:`~cell.perception.screen`; lengths [m]."""

    radius_m: float = 0.06  # look this far around the seam for points of unknown objects (the locator's tube)
    margin_m: float = 0.02  # a point further than this from every part of the map is foreign (3 sigma at 2 m)
    min_foreign: int = 40  # this many foreign points (a few cm^2 of surface) near a seam: it is occluded
    min_confidence: float = 0.1  # found seams below this confidence are not trusted


@dataclass(frozen=True)
class CoverageOptions:
    """Thresholds of :func:`~cell.perception.check_parts_seen`: shares of each part's top that hold points."""

    min_coverage: float = 0.1  # less: the part is missing (its seams are not searched)
    min_seen: float = 0.6  # between the two: the map lies half off the cloud (alignment refused)
