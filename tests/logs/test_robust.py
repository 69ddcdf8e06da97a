"""Outliers injected into a clean synthetic log: the map survives, the truth comes back, rejections count."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.logs import (
    EnvelopeLocalizer,
    LogObservation,
    ReplayOptions,
    RobotLog,
    replay_log,
    synthetic_log,
)
from aura_ums.uncertainty import LandmarkClass, Pose, SpatialUncertaintyMap, TerrainTable
from aura_ums.world import make_grid_world

FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})


@pytest.fixture(scope="module")
def clean_log() -> RobotLog:
    return synthetic_log(np.random.default_rng(5), duration=60.0)


def inject(
    log: RobotLog, start: float, end: float, change: Callable[[LogObservation], LogObservation]
) -> RobotLog:
    rows = tuple(change(o) if start <= o.time < end else o for o in log.observations)
    return dataclasses.replace(log, observations=rows)


@pytest.mark.parametrize("landmark_class", [LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT])
def test_gross_outliers_are_rejected_counted_and_never_applied(
    clean_log: RobotLog, landmark_class: LandmarkClass
) -> None:
    wrong = inject(clean_log, 20.0, 23.0, lambda o: dataclasses.replace(o, bearing=o.bearing + 2.0))
    injected = sum(1 for o in wrong.observations if 20.0 <= o.time < 23.0)
    result = replay_log(wrong, FLOOR, ReplayOptions(landmark_class=landmark_class))
    assert 1 <= result.inconsistent_observations <= injected
    assert result.relocalizations >= 1
    assert result.containment_rate == 1.0
    assert all(step.map.area > 0.0 for step in result.steps)


def test_consistent_but_wrong_observations_mislead_only_briefly(clean_log: RobotLog) -> None:
    # A 3.5% range bias for 3 s on top of the 2% noise: beyond the working bounds (2%),
    # within the envelope's (three times them).
    biased = inject(clean_log, 20.0, 23.0, lambda o: dataclasses.replace(o, range=(o.range or 0.0) * 0.965))
    options = ReplayOptions(landmark_class=LandmarkClass.POINT, envelope_factor=3.0)
    result = replay_log(biased, FLOOR, options)
    outside = [step.time for step in result.steps if step.inside is False]
    assert outside, "the bias was expected to mislead the working map for a while"
    assert max(outside) < 23.0 + 5.0  # never wrong for long
    assert all(step.envelope_inside for step in result.steps)  # the envelope stays sound
    assert result.steps[-1].inside
    assert result.containment_rate > 0.9
    # Re-localization from the envelope shortens the misled stretch against the gate alone.
    gate_only = replay_log(biased, FLOOR, dataclasses.replace(options, robust=False))
    assert len(outside) <= sum(1 for step in gate_only.steps if step.inside is False)


def test_localizer_arguments_are_checked() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
    world = make_grid_world(1, 1)
    with pytest.raises(InputError, match="relocalize_after: expected an integer >= 1"):
        EnvelopeLocalizer(start, world, FLOOR, relocalize_after=0)
    with pytest.raises(InputError, match="relocalize_window: expected >= relocalize_after"):
        EnvelopeLocalizer(start, world, FLOOR, relocalize_after=3, relocalize_window=2)
    with pytest.raises(InputError, match="envelope_max_vertices: expected an integer >= 3, got 2"):
        EnvelopeLocalizer(start, world, FLOOR, envelope=False, envelope_max_vertices=2)
    with pytest.raises(InputError, match="max_vertices: expected an integer >= 3, got 0"):
        EnvelopeLocalizer(start, world, FLOOR, max_vertices=0)


def test_a_coarse_envelope_stays_sound_and_re_seeds_within_the_working_cap(clean_log: RobotLog) -> None:
    wrong = inject(clean_log, 20.0, 23.0, lambda o: dataclasses.replace(o, bearing=o.bearing + 2.0))
    options = ReplayOptions(landmark_class=LandmarkClass.POINT, max_vertices=24, envelope_max_vertices=6)
    steps = replay_log(wrong, FLOOR, options).steps
    assert any(step.relocalized for step in steps)
    assert all(step.envelope_inside for step in steps)
    assert all(len(step.map.polygon.vertices) <= 24 for step in steps[1:])
    assert sum(step.inside is True for step in steps) == len(steps)
