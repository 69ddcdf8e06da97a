"""The fields every observation has: checked once, in the class's own construction."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Observation,
    RangeBearingObservation,
)

MAKERS: list[Callable[[Any, Any, Any], Observation]] = [
    lambda ident, time, offset: BearingObservation(ident, time, 0.1, 0.01, offset),
    lambda ident, time, offset: RangeBearingObservation(ident, time, 0.1, 0.01, 2.0, 3.0, offset),
    lambda ident, time, offset: GroundLineObservation(ident, time, 1.0, 0.1, 0.2, 0.02, offset),
]


@pytest.mark.parametrize("make", MAKERS)
def test_common_fields_are_stored_as_checked_values(make: Callable[[Any, Any, Any], Observation]) -> None:
    observation = make("pole", np.float64(2.5), np.array([0.4, -0.1]))
    assert observation.landmark_id == "pole"
    assert observation.time == 2.5
    assert type(observation.time) is float
    assert observation.sensor_offset == (0.4, -0.1)
    assert all(type(value) is float for value in observation.sensor_offset)


@pytest.mark.parametrize("make", MAKERS)
@pytest.mark.parametrize(
    ("ident", "time", "offset", "match"),
    [
        ("", 0.0, (0.0, 0.0), "landmark_id: expected a non-empty string, got ''"),
        (3, 0.0, (0.0, 0.0), "landmark_id: expected a non-empty string, got 3"),
        ("pole", math.nan, (0.0, 0.0), "time: expected a finite number, got nan"),
        ("pole", 0.0, (0.0, 0.0, 0.0), r"sensor_offset: expected"),
        ("pole", 0.0, [(0.0, 0.0), (1.0, 1.0)], r"sensor_offset: expected \(forward, left\) metres"),
    ],
)
def test_bad_common_fields_are_refused(
    make: Callable[[Any, Any, Any], Observation], ident: object, time: object, offset: object, match: str
) -> None:
    with pytest.raises(InputError, match=match):
        make(ident, time, offset)


def test_a_point_of_three_numbers_is_named_as_such() -> None:
    """Not as an (n, 2) array: the message says what one point is."""
    with pytest.raises(
        InputError, match=r"^e\.start: expected an \(x, y\) point in metres, got shape \(3,\)$"
    ):
        GroundLineLandmark("e", (1.0, 1.0, 2.0), (1.0, 1.0))
    with pytest.raises(
        InputError, match=r"^sensor_offset: expected \(forward, left\) metres, got shape \(3,\)$"
    ):
        BearingObservation("p", 0.0, 0.1, 0.01, sensor_offset=(1.0, 2.0, 3.0))  # type: ignore[arg-type]
    assert GroundLineLandmark("e", [[0.0, 0.0]], (1.0, 0.0)).start.tolist() == [
        0.0,
        0.0,
    ]  # (1, 2) still works
