"""Ways into and out of a seam that the general transfers leave out (:mod:`cell.planning.access.openings`)."""
