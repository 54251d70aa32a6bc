"""Ways in and out of a seam that the general transfers leave out: along the torch's own axis."""
