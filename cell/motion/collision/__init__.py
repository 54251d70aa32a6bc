"""Collision checking (coal through Pinocchio's GeometryModel): :class:`CollisionChecker` in :mod:`.checker`, the
torch test's shapes and boxes in :mod:`.shapes`. The only package that imports coal."""

from cell.config.motion import CollisionOptions
from cell.motion.collision.checker import CollisionChecker
from cell.motion.collision.contact import Contact

__all__ = ["CollisionChecker", "CollisionOptions", "Contact"]
