"""The replay builds each frame's observations without checking again what the log checked: the same ones."""

from __future__ import annotations

import numpy as np
import pytest

from aura_ums.logs import LogObservation, SensorBounds, observation_for, synthetic_log
from aura_ums.logs._replay import _observations, _row_of
from aura_ums.uncertainty import LandmarkClass

BOUNDS = (SensorBounds(0.02), SensorBounds(0.05, 0.1, 0.02, 0.03))


@pytest.mark.parametrize("landmark_class", [LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT])
@pytest.mark.parametrize("bounds", BOUNDS)
def test_the_replays_observations_are_observation_for_of_each_row(
    landmark_class: LandmarkClass, bounds: SensorBounds
) -> None:
    log = synthetic_log(np.random.default_rng(5), duration=20.0)
    # Rows with their own bounds and without a range too.
    rows = [
        *log.observations,
        LogObservation(3.0, "L1", 0.5, range=2.0, bearing_error=0.01, range_error=0.3),
        LogObservation(3.0, "L2", -0.5, range=0.1, range_error=0.3),
        LogObservation(3.0, "L3", 0.25),
    ]
    offset = (0.25, -0.125)
    expected = [observation_for(row, landmark_class, bounds, sensor_offset=offset) for row in rows]
    found = _observations(
        [_row_of(row) for row in rows], landmark_class is LandmarkClass.VERTICAL_LINE, bounds, offset
    )
    assert found == expected
    assert [type(o) for o in found] == [type(o) for o in expected]
