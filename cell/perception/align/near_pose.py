"""Where a part lies near the pose it was put down in (a part turned over by an operator: the placement error is
not known): the height-image search of the cloud (:func:`cell.perception.align.placement.height_candidates`)
narrowed to turns and shifts near the nominal pose, each start scored by the share of the cloud on the map's
surfaces."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from cell.geometry import FloatArray
from cell.perception.align.fit import sample_map, surface_fit
from cell.perception.align.placement import height_candidates
from cell.types import Cloud, WeldMap

SEARCH_TURN_RAD = math.radians(15.0)  # how far off its nominal pose the search looks for the part
SEARCH_SHIFT_M = 0.15
_SCORE_BAND_M = 0.01  # the band a start pose is scored in (cloud points near the map's surfaces)


def near_seed(weldmap_M: WeldMap, table_z: float) -> Callable[[Cloud, FloatArray], FloatArray]:
    """A seed of the map's alignment (:data:`cell.pipeline.detect.Seed`: the dense cloud in R and the nominal X_RM
    (4, 4) in, the X_RM to align from out): the height-image search of the cloud (turns and shifts on the table,
    :func:`cell.perception.align.placement.height_candidates`) for the turned map, its candidates within
    SEARCH_TURN_RAD and SEARCH_SHIFT_M of the nominal pose, the best by the share of the cloud on the map's
    surfaces, the nominal pose itself among them."""

    def seed(cloud: Cloud, X_RM: FloatArray) -> FloatArray:
        nominal = weldmap_M.transformed(X_RM, "R")
        centre = np.mean([p.center for p in nominal.parts], axis=0)
        points = np.asarray(cloud.points)
        starts = [np.eye(4)]
        for X in height_candidates(points, nominal, table_z):
            turn = abs(math.atan2(float(X[1, 0]), float(X[0, 0])))
            shift = float(np.linalg.norm((X[:3, :3] @ centre + X[:3, 3] - centre)[:2]))
            if turn <= SEARCH_TURN_RAD and shift <= SEARCH_SHIFT_M:
                starts.append(X)

        def score(X: FloatArray) -> float:
            samples, normals = sample_map(nominal.transformed(X, "R"), _SCORE_BAND_M / 2, _SCORE_BAND_M / 2)
            return surface_fit(points, samples, normals, _SCORE_BAND_M, _SCORE_BAND_M / 2)[0]

        best = max(starts, key=lambda X: round(score(X), 9))  # near-ties to the first start, in every process
        return np.asarray(best @ X_RM)

    return seed
