"""The replay builds each frame's observations without checking again what the log checked: the same ones."""

from __future__ import annotations

import numpy as np
import pytest

from aura_ums.errors import InputError
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


def test_a_factor_that_is_not_a_number_is_refused() -> None:
    # an array leaked numpy's "truth value of an array is ambiguous"
    row = LogObservation(2.5, "pole", 0.25, range=4.0)
    bounds = SensorBounds(0.05, 0.0, 0.1, 0.1)
    with pytest.raises(InputError, match=r"factor: expected a finite number, got array\(\[1\., 2\.\]\)"):
        observation_for(row, LandmarkClass.VERTICAL_LINE, bounds, factor=np.array([1.0, 2.0]))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="factor: expected a finite number, got None"):
        observation_for(row, LandmarkClass.VERTICAL_LINE, bounds, factor=None)  # type: ignore[arg-type]
