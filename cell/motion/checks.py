"""The safety gate's old import path: it lives in :mod:`cell.motion.gate` now, one check per module."""

from cell.motion.gate import GateOptions, GateRefusedError, Violation, ViolationKind, check_plan, find_violations

__all__ = ["GateOptions", "GateRefusedError", "Violation", "ViolationKind", "check_plan", "find_violations"]
