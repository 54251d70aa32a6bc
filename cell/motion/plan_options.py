"""The welding planner's settings (:class:`PlanOptions`, defined with every stage's options in
:mod:`cell.config.motion`; a scenario sets them as ``motion.plan``); the cell's welding figures come from the
scenario's ProcessSpec through :class:`~cell.motion.process.torch.WeldProcess`."""

from __future__ import annotations

from cell.config.motion import PlanOptions

__all__ = ["PlanOptions"]
