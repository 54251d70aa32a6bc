"""The weld run's curved seams: which located curves go to the planner, and what became of each one."""

from cell.pipeline.curved.welds import curve_seam_welds, curves_to_plan

__all__ = ["curve_seam_welds", "curves_to_plan"]
