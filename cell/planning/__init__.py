"""The welding planner: detected seams to a frozen :class:`~cell.types.plan.WeldPlan` (:mod:`~cell.planning.plan`),
from the seams' tasks and passes, the reach pre-check, the torch search and its placement, straight lines, the
order, the transfers and their assembly, a linear track, and the turn that exposes the seams left against the
table (:mod:`~cell.planning.turnover`). Its values live in :mod:`cell.types.plan`."""
