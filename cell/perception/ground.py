"""What the parts of a brought cloud stand on: the table found in the data, a table whose height is stated, or no
table at all (the cloud cropped just above it, a part held on a fixture). The largest upward plane of such a cloud is
then a part's own top face, and taking it for the table tilts and lifts everything (docs/locate.md, "Clouds without
a table"). Frames: F the cloud's, L levelled (+z up); metres."""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray
from cell.perception.unorganised import TablePlane, find_table

# A table has (almost) nothing under it: the real scans' tables have 0.6-0.7 % of their points more than 10 mm below
# (through the holes, off its edge); a tube's top face taken for the table has the tubes' walls under it: 36 % in the
# cropped real scan. A plane with more than BELOW_SHARE of the cloud more than BELOW_M (or BELOW_SIGMAS noise
# scales) below it is not a table.
BELOW_SHARE = 0.1
BELOW_M = 0.01
BELOW_SIGMAS = 5.0
FLOOR_PERCENTILE = 1.0  # no table: the lowest heights of the cloud (this percentile) are where the parts' bottoms are


class TableSource(enum.StrEnum):
    """Where the table's height came from."""

    FOUND = "found"  # the largest upward plane of the data, with (almost) nothing under it
    GIVEN = "given"  # stated (``--table-z``): F's z is up, the table at that height
    ABSENT = "absent"  # none: not in the data (recognised), or said so (``--no-table``)


@dataclass(frozen=True)
class Ground:
    """What the parts stand on, as read from a cloud.

    plane : the cloud's largest upward plane (frame F): the table when ``source`` is FOUND, else the parts' largest
        upward face. The noise and the point spacing are measured on it, and with no table stated the cloud is
        levelled by it (a part lying flat has its top parallel to what it lies on).
    source : :class:`TableSource`. below_share : share of the cloud's points well below ``plane`` (what told).
    given_z_m : the stated table height in F [m] (source GIVEN), else None.
    """

    plane: TablePlane
    source: TableSource
    below_share: float
    given_z_m: float | None = None

    @property
    def has_table(self) -> bool:
        """Whether a table height is known (found or given)."""
        return self.source is not TableSource.ABSENT


def below_share(points: FloatArray, plane: TablePlane) -> float:
    """Share of ``points`` (n, 3) more than BELOW_M (or BELOW_SIGMAS of the plane's noise) below ``plane``."""
    h = plane.height(np.asarray(points))
    return float(np.mean(h < -max(BELOW_M, BELOW_SIGMAS * plane.sigma_m))) if len(h) else 0.0


def find_ground(
    points_F: FloatArray, rng: np.random.Generator, *, table_z_m: float | None = None, no_table: bool = False
) -> Ground:
    """The ground of the cloud ``points_F`` (n, 3) [m] (module docstring): the largest upward plane
    (:func:`~cell.perception.unorganised.find_table`), a table unless more than BELOW_SHARE of the points lie well
    under it; ``table_z_m`` states the table's height in F (F's z up) and ``no_table`` that there is none, whatever
    the data look like. SensorError (from find_table) when the cloud has no upward plane at all."""
    plane = find_table(points_F, rng)
    below = below_share(points_F, plane)
    if table_z_m is not None:
        return Ground(plane, TableSource.GIVEN, below, float(table_z_m))
    if no_table or below > BELOW_SHARE:
        return Ground(plane, TableSource.ABSENT, below)
    return Ground(plane, TableSource.FOUND, below)


def floor_height(heights_m: FloatArray) -> float:
    """Where the parts' bottoms are when no table is known: the FLOOR_PERCENTILE of the points' heights (frame L)
    [m]. A start for the placement search only; the alignment on the parts' faces sets the part's height."""
    return float(np.percentile(np.asarray(heights_m), FLOOR_PERCENTILE))
