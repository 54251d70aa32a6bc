"""What every test folder shares: the helper modules of ``tests/`` on the import path, and the session's scenes.

``tests/unit/`` holds the fast tests (property tests, tiny inline cells, synthetic clouds: no simulator render of
a whole scenario); ``tests/scenario/`` runs the real pipeline headless on the shipped scenarios (marked
``scenario``). A shipped scenario that several tests read is captured and perceived once per session here, and
shared read-only: the values are frozen dataclasses with read-only arrays. A test that needs a running station
opens its own (:func:`fence1_station`); none is shared, so no result depends on the order the tests run in.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from cell import pipeline
    from cell.pipeline.turnover import TurnoverRun
    from cell.station import SimStation

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:  # the helper modules (dxf_factory, fakes, pinhole, scenes): used from several folders
    sys.path.insert(0, str(HERE))

from scenes import Noise, Perceived  # noqa: E402  (after the path set-up above)
from shared_runs import Preview, half_resolution  # noqa: E402

# The test files that read the session's fence1 weld or perceived scenes (the fixtures below): one work unit of
# ``--dist loadfile``, so one worker builds each (fence1's weld is 20 s of CPU); the other worker takes the rest.
_SHARED_RUNS = re.compile(r"\b(fence1_(both|run|detection|station)|perceived)\b")
SHARED_UNIT = "tests/<the files that read the session's shared runs>"


def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """``--dist loadfile`` with the files that read the session's shared runs in one unit (:data:`SHARED_UNIT`);
    any other distribution as xdist has it."""
    if config.getoption("dist", None) != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    root = Path(str(config.rootpath))
    shared: dict[str, bool] = {}

    class SharedRunsTogether(LoadFileScheduling):  # type: ignore[misc]
        def _split_scope(self, nodeid: str) -> str:
            path = super()._split_scope(nodeid)
            if path not in shared:
                file = root / path
                shared[path] = file.is_file() and bool(_SHARED_RUNS.search(file.read_text()))
            return SHARED_UNIT if shared[path] else path

    return SharedRunsTogether(config, log)


@pytest.fixture(scope="session")
def fence1_both() -> TurnoverRun:
    """``cell weld fence1`` once per session: side A, the operator's turn and side B (read-only)."""
    from cell import scenario as sc
    from cell.pipeline.turnover import weld_part

    return weld_part(sc.load("fence1"))


@pytest.fixture(scope="session")
def fence1_run(fence1_both: TurnoverRun) -> pipeline.WeldRun:
    """Its side A: detection, re-scan, plan, gate and execution, as ``pipeline.weld(fence1)`` gives them."""
    return fence1_both.side_a


@pytest.fixture(scope="session")
def fence1_detection(fence1_run: pipeline.WeldRun) -> pipeline.Detection:
    """fence1's ``pipeline.detect`` result: the weld's own detection, before its re-scan (``first_detection``)."""
    det = fence1_run.first_detection
    if det is None or det.scene is None:
        raise RuntimeError(f"fence1's detection kept no scene: {fence1_run.error}")
    return det


@pytest.fixture(scope="session")
def perceived(request: pytest.FixtureRequest) -> Callable[[str, Noise], Perceived]:
    """``perceived(name, noise)``: scenario ``name`` with that noise, captured and perceived once per session
    (``pipeline.capture`` + ``pipeline.build_scene``); fence1 as shipped (realistic) is the weld's detection."""
    from cell import pipeline
    from cell import scenario as sc

    cache: dict[tuple[str, Noise], Perceived] = {}

    def get(name: str, noise: Noise) -> Perceived:
        if (name, noise) not in cache:
            s = sc.load(name)
            if s.with_noise(noise) == sc.load("fence1"):
                det: pipeline.Detection = request.getfixturevalue("fence1_detection")
                if det.scene is None:
                    raise RuntimeError("fence1's detection kept no scene")
                cache[name, noise] = Perceived(det.scenario, det.scene, det.truths, None)
            else:
                cap = pipeline.capture(s.with_noise(noise))
                scene = pipeline.build_scene(cap)
                truths = pipeline.truths(cap, scene.seam_scene.weldmap)
                cache[name, noise] = Perceived(cap.scenario, scene, truths, cap)
        return cache[name, noise]

    return get


@pytest.fixture
def fence1_station(fence1_detection: pipeline.Detection) -> Iterator[SimStation]:
    """A running fence1 cell of the test's own, as the session's detection left its station: the arm at its scan
    configuration and every camera one image on (a close-up draws the same noise as it does in ``cell weld``)."""
    from cell import pipeline
    from cell.pipeline.geometry import open_cell

    scn = fence1_detection.scenario
    with open_cell(scn, pipeline.read_weldmap(scn)) as station:
        station.capture()
        yield station


@pytest.fixture(scope="session")
def detected() -> Callable[..., pipeline.Detection]:
    """``detected(name, half=False)``: ``pipeline.detect`` of scenario ``name`` as shipped, once per session (read
    only), for the tests of several modules that detect the same cell (faults, the CLI's reports, the splice);
    ``half``: its cameras at half resolution (tests/resolution.py)."""
    from cell import pipeline
    from cell import scenario as sc

    cache: dict[tuple[str, bool], pipeline.Detection] = {}

    def get(name: str, half: bool = False) -> pipeline.Detection:
        if (name, half) not in cache:
            s = sc.load(name)
            cache[name, half] = pipeline.detect(half_resolution(s) if half else s)
        return cache[name, half]

    return get


@pytest.fixture(scope="session")
def fence1_preview(tmp_path_factory: pytest.TempPathFactory) -> Preview:
    """``cell preview fence1`` once per session through the real pipeline (a preview plans and moves nothing); the
    run it drew is caught on its way to ``cell.preview.write_run``, the pictures and page drawn as they would be."""
    from typer.testing import CliRunner

    import cell.preview
    from cell.cli import app

    drawn: list[pipeline.WeldRun] = []
    write_run = cell.preview.write_run

    def spy(run: pipeline.WeldRun, out_dir: str | Path) -> list[Path]:
        drawn.append(run)
        return write_run(run, out_dir)

    folder = tmp_path_factory.mktemp("preview")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(cell.preview, "write_run", spy)
        result = CliRunner().invoke(app, ["preview", "fence1", "--out", str(folder)])
    assert len(drawn) == 1, result.stderr
    return Preview(folder, result.exit_code, result.stderr, drawn[0])
