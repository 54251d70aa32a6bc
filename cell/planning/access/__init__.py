"""Ways into and out of a seam that the general transfers leave out (:mod:`cell.planning.access.openings`), and a
seam no transfer joins to home either way (:mod:`cell.planning.access.home`)."""
