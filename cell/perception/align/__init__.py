"""Aligning the welding map to the cloud (paper section 3.5): the fit (:mod:`~cell.perception.align.fit`: ICP of
the map's sampled faces, coarse to fine), what checks it (:mod:`~cell.perception.align.checks`: fitness, a fit one
rung off, parts not in the cloud), and where the part lies on the table when no placement is given or it fits
poorly (:mod:`~cell.perception.align.placement`)."""

from cell.perception.align.checks import check_alignment, check_alignment_unique, check_parts_seen
from cell.perception.align.fit import Alignment, align_map

__all__ = ["Alignment", "align_map", "check_alignment", "check_alignment_unique", "check_parts_seen"]
