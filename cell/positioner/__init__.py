"""The tilt-rotate positioner's planning (docs/positioner.md): welding positions by ISO 6947 (``iso6947``), the
positioner's angles that bring a seam to the position its procedure asks, in closed form, and the seams grouped by
positioner pose (``poses``), the located seams carried into a group's pose (``carried``)."""
