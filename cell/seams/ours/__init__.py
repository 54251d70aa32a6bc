"""Our map-guided seam locator: fit the two weld faces near the map's seam, intersect them, find the ends.

The package's public names: :class:`OursLocator`, its :class:`OursOptions`, and the standard errors behind a seam's
confidence (:class:`SeamErrors`); one concept per module (the driver ``locator``, ``options``, ``confidence``, the
points ``_points``, the planes ``_planes``, the joint's geometry ``_geometry``, the faces ``_faces``, the side
faces' points ``_sides``, the ends ``_ends``).

Method (general: no assumption that a seam runs along x, y or z):

1. From the aligned map: the weld faces, A's ``face_abutting`` (n_a, d_a) and B's ``face_receiving`` (n_b,
   d_b), the seam line where they meet with its direction t, and A's side faces across t (where the seam
   ends).
2. Points in a tube around the map seam, from a fixed share (``sample_share``: every k-th point of each voxel)
   of ``scene.dense`` (:class:`~cell.seams._index.CloudIndex`, on the voxel table perception hands on: thousands
   of points per face are plenty for a sub-0.1 mm offset); points within a band of any other part of the map
   are left out, so neighbouring parts never lend a face their points. Point counts that decide whether a face
   is seen (``min_face_points``) are the dense cloud's.
3. Face A's support: points near A's plane, away from B's face by a corner band (gap, shadow and corner noise
   live there), inside A's extent along t less an edge band (flying pixels on convex edges), above the table.
   Face B's support: points near B's plane inside B's face less an edge band, outside the footprint of A grown
   by the band. A's side faces across the seam (where it ends) likewise. All of them are fitted at once
   (:func:`~cell.seams._batch.fit_offsets`): each plane's offset along the map's normal by iteratively
   reweighted least squares (Tukey biweight), each camera weighted by its own measured noise on that face.
   ``passes`` passes: the first from the map with wide gates (from each face's densest layer), the others with
   gates and bands from the measured noise and the ends found. In the last pass (``refine_normals``) the weld
   faces may tilt a little, held near the map's normal by a Gaussian prior (as-built parts are rotated by
   hundredths of a degree, not degrees): one weighted least-squares step with the fit's weights.
4. A weld face no camera sees (too oblique, occluded) is placed from the edge where an adjacent face of the
   same part ends (:mod:`cell.seams._edge`): the extent of that face's points across the edge (a blurred-step
   likelihood), searched as far from the map as a fitted face may drift, each camera's edge on its own (from
   ``edge_sample_share`` of the dense cloud: an edge needs density). A camera's edge counts only when enough
   points define it, it is not blurred beyond the likelihood's widest blur (grazing incidence), few points lie
   beyond it (flying pixels), and it is neither at the searched range's limit nor where the cloud stops (the
   sample's own cut-off, not an edge). Its standard error: the likelihood's and the sampling pitch of the face
   (``edge_pitch_factor``); the cameras' edges are combined by inverse variance, the error inflated when they
   disagree beyond it (Birge ratio). With no such edge, the seam is NOT_FOUND naming the face and why.
5. The seam line is the intersection of the fitted planes. Each end is where the line meets A's side face
   across it, fitted from that face's points when it is seen, the table when A rests on it there, or else the
   extent of face A's support along t (its empirical CDF extrapolated, then refined by the same edge
   likelihood on every dense point about it). An extent end where the cloud stops (the workspace crop:
   ``workspace_R``, or the cloud's bounds along R's axes) is not an end: the seam is NOT_FOUND.
6. Confidence from the standard errors of the fitted offsets (an edge-placed face: its edge's) and ends
   (:class:`SeamErrors`, :meth:`OursLocator.locate_with_errors`), each face's support and the residual scale.

The seams of a scene are found together (:meth:`OursLocator.locate_many`): each seam's steps are as above, but
every plane fit of a pass, and every tilt step, is one vectorised fit for all the seams (numpy costs about the
same per call whatever the size: on the 156-seam ladder, 1.38 ms for the median seam alone, 0.94 ms per seam
together; benchmarks/bench_scaling.py).
"""

from cell.seams.ours.confidence import NO_ERRORS, SUPPORT_FULL_MARKS, SeamErrors
from cell.seams.ours.locator import OursLocator
from cell.seams.ours.options import OursOptions

__all__ = ["NO_ERRORS", "SUPPORT_FULL_MARKS", "OursLocator", "OursOptions", "SeamErrors"]
