"""The parts-seen check judges a part by the top its sensor has in sight (cell/perception/align/checks.py,
``part_coverage`` with ``eyes_R``): a plate whose top a standing web shadows from a low sensor is not refused for
the shadowed share, whether the sensor's place is given or read from the cloud (cell/perception/align/sight.py),
and without it it is (what the check did before it knew); a part missing from the cloud is still missing."""

from __future__ import annotations

import numpy as np
import pytest

from cell.errors import AlignmentError
from cell.geometry import make_pose
from cell.perception.align.checks import check_parts_seen, cloud_tree_of, part_coverage
from cell.perception.align.sight import places_in_evidence
from cell.scenario import PerceptionSpec, WorkspaceSpec
from cell.types import Box, Cloud, Part, WeldMap

# A 200 x 200 x 10 mm plate on the table and a 20 mm web, 300 mm tall, standing across it 30 mm from its -x edge;
# the sensor low on the -x side (15 deg up): the web's shadow covers all of the plate's top beyond it.
PLATE = Part("PLATE", Box(make_pose(p=(0.0, 0.0, 0.005)), np.array([0.2, 0.2, 0.01])))
WEB = Part("WEB", Box(make_pose(p=(-0.06, 0.0, 0.16)), np.array([0.02, 0.2, 0.3])))
EYE = np.array([[-1.5, 0.0, 0.4]])


def _cloud() -> Cloud:
    """What that sensor sees, drawn by hand: the plate's top between its -x edge and the web (2 mm grid), the
    web's top and its face towards the sensor."""
    g = np.arange(-0.1, 0.1, 0.002)
    x, y = np.meshgrid(np.arange(-0.1, -0.07, 0.002), g)
    strip = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 0.01)])
    x, y = np.meshgrid(np.arange(-0.07, -0.05, 0.002), g)
    top = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 0.31)])
    y, z = np.meshgrid(g, np.arange(0.01, 0.31, 0.004))
    face = np.column_stack([np.full(y.size, -0.07), y.ravel(), z.ravel()])
    return Cloud(np.vstack([strip, top, face]), "R")


def test_the_shadowed_top_is_left_out_of_the_share_only_when_the_sensor_is_known() -> None:
    weldmap = WeldMap((PLATE, WEB), (), "mm", "", "R")
    spec = PerceptionSpec(workspace=WorkspaceSpec(min_m=(-1.0, -1.0, -0.1), max_m=(1.0, 1.0, 1.0)))
    blind = part_coverage(weldmap, _cloud(), spec)
    seen = part_coverage(weldmap, _cloud(), spec, eyes_R=EYE)
    # Of the plate's top (less the web's footprint) 17 % lies in the open strip before the web (measured 0.167):
    # judged by all of it, the plate is hardly seen; judged by what the sensor has in sight, wholly.
    assert blind["PLATE"] == pytest.approx(0.17, abs=0.03)  # measured 0.167
    assert seen["PLATE"] > 0.95
    assert blind["WEB"] == pytest.approx(1.0, abs=0.02) and seen["WEB"] == pytest.approx(1.0, abs=0.02)
    with pytest.raises(AlignmentError):
        check_parts_seen(weldmap, _cloud(), spec, spec.coverage)
    assert check_parts_seen(weldmap, _cloud(), spec, spec.coverage, eyes_R=EYE) == {}


def test_the_sensor_side_is_read_from_the_cloud_when_no_place_is_given() -> None:
    weldmap = WeldMap((PLATE, WEB), (), "mm", "", "R")
    cloud = _cloud()
    places = places_in_evidence(weldmap, cloud_tree_of(cloud))
    assert places is not None
    # Only places on the sensor's side (-x) are kept: the others would see the web's far face or the plate behind it.
    assert np.all(places[:, 0] < -0.4) and len(places) == 2  # of 25: straight towards it, at both elevations
    spec = PerceptionSpec(workspace=WorkspaceSpec(min_m=(-1.0, -1.0, -0.1), max_m=(1.0, 1.0, 1.0)))
    assert part_coverage(weldmap, cloud, spec, eyes_R=places)["PLATE"] > 0.95
    assert check_parts_seen(weldmap, cloud, spec, spec.coverage, eyes_R=places) == {}


def test_a_part_missing_from_the_cloud_is_still_missing() -> None:
    weldmap = WeldMap((PLATE, WEB), (), "mm", "", "R")
    g = np.arange(-0.1, 0.1, 0.002)
    x, y = np.meshgrid(g, g)
    plate_only = Cloud(np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 0.01)]), "R")  # no web at all
    places = places_in_evidence(weldmap, cloud_tree_of(plate_only))
    spec = PerceptionSpec(workspace=WorkspaceSpec(min_m=(-1.0, -1.0, -0.1), max_m=(1.0, 1.0, 1.0)))
    missing = check_parts_seen(weldmap, plate_only, spec, spec.coverage, eyes_R=places)
    assert list(missing) == ["WEB"]
