"""Coordinated motion of the arm and a tilt-rotate positioner along a curved seam (docs/positioner.md,
"Coordinated motion"): the tilt set so the fillet lies in PA, the rotate axis turning the part under a nearly still
torch, the arm making the small corrections the seam's deviation needs; planned, timed and gated together."""
