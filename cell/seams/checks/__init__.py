"""What a located seam cannot be, checked against the aligned map: its ends (never inside another body, the length
as drawn within the part tolerance: :mod:`cell.seams.checks.ends`, after every locator) and the last check before
the arc (the line, the length, the ends against the map and the other parts: :mod:`cell.seams.checks.last_check`)."""

from cell.seams.checks.ends import BEAD_LIFT_M, bead_entry, check_ends
from cell.seams.checks.last_check import CHECK_SIGMAS, Budget, budget, last_check

__all__ = ["BEAD_LIFT_M", "CHECK_SIGMAS", "Budget", "bead_entry", "budget", "check_ends", "last_check"]
