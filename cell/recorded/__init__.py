"""Recorded data: capture folders (:mod:`cell.recorded.layout`, docs/capture.md) and what converts into them.

Nothing here imports the simulator. The names are imported when first asked for, so ``import cell.recorded`` costs
nothing (pillow is only loaded by a read or a write).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cell.recorded.layout import RecordedCapture, read_capture, write_capture

__all__ = ["RecordedCapture", "read_capture", "write_capture"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from cell.recorded import layout

        return getattr(layout, name)
    raise AttributeError(f"module 'cell.recorded' has no attribute {name!r}")
