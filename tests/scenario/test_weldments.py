"""The bracket scenario (a plate weldment drawn as MESH bodies: a base plate with a hole, a 12 mm upright, a 12 mm
triangular gusset, an 8 mm lap plate): ``pipeline.detect`` once for the module, our locator's figures against the
truth (realistic noise). Measured (2026-12, scenarios/bracket.yaml): 6 of the 9 visible seams found, mean lateral
0.15 mm, mean endpoint 0.68 mm (the gusset's ends at the upright: it stands 0.4 mm off it as built); the lap plate's
+x, -x and +y sides are not (too few points on an 8 mm side face seen from 1.5 m, or no base plate beside it), each
with its reason; a close-up finds the -x side (the last test, on the module's running station)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cell import pipeline
from cell import scenario as sc
from cell.pipeline.geometry import open_cell
from cell.station import Station
from cell.types import SeamStatus

GUSSET = ("GUSSET>BASE:-y", "GUSSET>BASE:+y", "GUSSET>UPRIGHT:-y", "GUSSET>UPRIGHT:+y")


@pytest.fixture(scope="module")
def bracket_cell() -> Iterator[tuple[Station, pipeline.Detection]]:
    """``cell detect bracket`` once for this module, its station kept running for a close-up."""
    scenario = sc.load("bracket")
    weldmap = pipeline.read_weldmap(scenario)
    with open_cell(scenario, weldmap) as station:
        yield station, pipeline.detect(scenario, None, station=station, weldmap=weldmap)


@pytest.fixture(scope="module")
def bracket(bracket_cell: tuple[Station, pipeline.Detection]) -> pipeline.Detection:
    return bracket_cell[1]


def test_every_camera_kept_and_the_thin_plates_found(bracket: pipeline.Detection) -> None:
    assert bracket.lost_cameras == ()  # the eye-in-hand camera sees part of the scene: kept, not "disagreeing"
    found = {e.id for e in bracket.estimates if e.status is SeamStatus.FOUND}
    # The lap plate's seams lie on an 8 mm face the fixed cameras see at grazing incidence: with the tilt the points
    # leave unknown in their sigma they are too uncertain here (confidence <= 0.04) and left to the close-up.
    assert {"UPRIGHT>BASE:+x", *GUSSET} <= found
    assert bracket.summary.visible == 9 and bracket.summary.found >= 5
    for e in bracket.estimates:  # the others refused with their one-line reason
        assert e.status is SeamStatus.FOUND or (e.code is not None and e.reason and "\n" not in e.reason), e


def test_bracket_accuracy(bracket: pipeline.Detection) -> None:
    s = bracket.summary
    assert s.lateral_mean_mm < 0.25  # measured 0.15
    assert s.endpoint_mean_mm < 0.9  # measured 0.68
    assert bracket.metrics["UPRIGHT>BASE:+x"].lateral_mm < 0.15  # 0.04: no splice correction shifts cam_right


def test_a_gusset_end_against_another_part_comes_from_that_parts_face(bracket: pipeline.Detection) -> None:
    by_id = {e.id: e for e in bracket.estimates}
    for sid in GUSSET:  # the back on the upright, the foot on the base: hidden faces, ends from their neighbours
        assert by_id[sid].reason.startswith("ends from side face / side face"), by_id[sid].reason
        assert bracket.metrics[sid].endpoint_mm < 1.0  # measured 0.64-0.75
        assert bracket.metrics[sid].lateral_mm < 0.3  # 0.12-0.18: only points over the triangle support its face


def test_the_lap_plates_side_by_the_upright_is_found_up_close(bracket_cell: tuple[Station, pipeline.Detection]) -> None:
    # The lap plate's -x side runs 67 mm from the 168 mm upright: the fixed cameras see its 8 mm face past the
    # upright (face offset +-1.1 mm: confidence 0.01, refused), and no pose of the close-up grid sees the seam over
    # the upright at 72 deg; the fallback grid's grazing view does (measured: 75 deg, 0.04 mm lateral, 0.13 mm ends).
    station, det = bracket_cell
    sid = "LAP>BASE:-x"
    assert next(e for e in det.estimates if e.id == sid).status is SeamStatus.NOT_FOUND
    rs, after = pipeline.rescan_detection(station, det, "low", seam_ids=[sid])
    (r,) = rs.seams
    assert r.used and r.viewpoint is not None and max(r.viewpoint.incidence_deg) > 72.0, r.reason
    assert after.metrics[sid].lateral_mm < 0.1  # 0.042
    assert after.metrics[sid].endpoint_mm < 0.3  # 0.127
