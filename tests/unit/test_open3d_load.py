"""open3d's core is loaded whole once, however many threads ask for it first (the splice and the map alignment
do, on two threads of a fresh process): no thread is handed a half-loaded core."""

from __future__ import annotations

import subprocess
import sys

# Four threads of a fresh process take the core at once and build what an ICP builds.
_RACE = """
import threading
from cell.perception import _open3d as m
errors = []
def take():
    try:
        o3d = m._o3d()
        o3d.pipelines.registration.TransformationEstimationPointToPlane()
        o3d.geometry.PointCloud()
    except Exception as e:
        errors.append(repr(e))
threads = [threading.Thread(target=take) for _ in range(4)]
for t in threads:
    t.start()
for t in threads:
    t.join()
print(errors[0] if errors else "ok")
"""


def test_threads_that_load_open3d_at_once_all_get_the_whole_core() -> None:
    for _ in range(2):  # without the lock, each run failed (a type defined twice, a function missing)
        out = subprocess.run([sys.executable, "-c", _RACE], capture_output=True, text=True, timeout=120, check=True)
        assert out.stdout.strip() == "ok"
