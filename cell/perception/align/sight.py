"""Where the sensor of a brought cloud was, as far as the cloud tells it, for the parts-seen check (a sensor's place
is rarely given with a lidar sweep): of a ring of candidate places around and above the aligned map, those from
which what the map shows in sight holds points about as well as from the best of them. A sweep from one side keeps
the places on that side; a plate's top in a standing part's shadow from all of them is then out of the check's
count (docs/locate.md, "From the cloud to the seams"). Frame R, metres."""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from cell.geometry import FloatArray
from cell.perception.align.fit import sample_map
from cell.perception.sky import in_sight
from cell.types import WeldMap

RANGE_M = 2.0  # the candidate places' distance from the map's centre
ELEVATIONS_DEG = (35.0, 65.0)  # above the horizontal through the map's centre
AZIMUTHS = 12  # around it, evenly
SPACING_M = 0.01  # the map's surfaces sampled this far apart
BAND_M = 0.01  # a sample holds a point within this distance
# A place is kept when the share of the samples in its sight that hold points is within HELD_MARGIN of the best
# place's, and the best's is at least MIN_HELD. Measured: 0.95-0.99 from the sensor's side on the four real scans and
# a synthetic plate shadowed by a web, 0.4-0.8 from the others (0.08-0.16 for the plate); places straight across
# the map from the sensor see faces and shadows it did not.
MIN_HELD = 0.5
HELD_MARGIN = 0.1


def candidate_places(centre_R: FloatArray) -> FloatArray:
    """(k, 3) the ring of candidate sensor places about ``centre_R`` (3,) [m], straight above it last."""
    out = []
    for el in np.radians(ELEVATIONS_DEG):
        for az in np.arange(AZIMUTHS) * 2.0 * math.pi / AZIMUTHS:
            out.append([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    out.append([0.0, 0.0, 1.0])
    return np.asarray(centre_R, dtype=np.float64) + RANGE_M * np.asarray(out)


def places_in_evidence(weldmap_R: WeldMap, cloud_tree: cKDTree) -> FloatArray | None:
    """(k, 3) the candidate places (:func:`candidate_places` about the map's parts' centre) from which the share of
    the map's samples in sight (facing the place, nothing of the map on the way) that hold a point of the cloud
    (``cloud_tree``, its KD-tree, frame R) is within HELD_MARGIN of the best place's; None when even the best's is
    under MIN_HELD (then nothing is said of the sensor)."""
    samples, normals = sample_map(weldmap_R, SPACING_M, SPACING_M)
    if not len(samples):
        return None
    held = np.isfinite(cloud_tree.query(samples, distance_upper_bound=BAND_M, workers=-1)[0])
    centre = np.mean([p.center for p in weldmap_R.parts], axis=0)
    places = candidate_places(centre)
    share = np.zeros(len(places))
    for k, eye in enumerate(places):
        front = np.flatnonzero(np.einsum("ij,ij->i", normals, eye - samples) > 0.0)
        seen = front[in_sight(samples[front], eye[None, :], weldmap_R.parts)]
        share[k] = float(held[seen].mean()) if len(seen) else 0.0
    best = float(share.max())
    return places[share >= best - HELD_MARGIN] if best >= MIN_HELD else None
