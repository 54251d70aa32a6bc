"""Every test in this folder runs the real pipeline headless on a shipped scenario: each carries the ``scenario``
marker (``-m "not scenario"`` leaves them out, as ``./scripts/test --fast`` does by running ``tests/unit/`` only)."""

from __future__ import annotations

from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    # A conftest's hook sees every collected item, not only this folder's: mark ours alone.
    for item in items:
        if item.path.is_relative_to(HERE):
            item.add_marker(pytest.mark.scenario)
