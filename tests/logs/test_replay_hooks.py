"""``after_step``: a replay hands each step on as it computes it, the same step its result holds."""

from __future__ import annotations

import numpy as np
import pytest

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.errors import InputError
from aura_ums.logs import ReplayOptions, ReplayStep, WindowRow, replay_log, replay_windows, synthetic_log
from aura_ums.manager import ManagerSettings
from aura_ums.uncertainty import LandmarkClass, TerrainTable

FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
CAMERA = Camera(CameraIntrinsics(554.26, 554.26, 319.5, 239.5, 640, 480), CameraMount(0.3))


def _same(seen: ReplayStep, kept: ReplayStep) -> None:
    assert seen.time == kept.time
    assert seen.map is kept.map
    assert seen.truth == kept.truth
    assert (seen.inside, seen.envelope_inside) == (kept.inside, kept.envelope_inside)
    assert (seen.accepted, seen.rejected, seen.excluded) == (kept.accepted, kept.rejected, kept.excluded)
    assert (seen.state, seen.relocalized, seen.update_us) == (kept.state, kept.relocalized, kept.update_us)


@pytest.mark.parametrize("sliced", [False, True])
def test_each_step_is_handed_on_as_the_result_keeps_it(sliced: bool) -> None:
    log = synthetic_log(np.random.default_rng(7), duration=20.0)
    settings = ManagerSettings(slice_width=0.1) if sliced else ManagerSettings()
    options = ReplayOptions(settings=settings, landmark_class=LandmarkClass.POINT)
    seen: list[ReplayStep] = []
    result = replay_log(log, FLOOR, options, after_step=seen.append)
    assert len(seen) == len(result.steps) > 5
    assert all(step.map.is_sliced is sliced for step in seen)
    assert any(step.inside is not None for step in seen)
    for handed, kept in zip(seen, result.steps, strict=True):
        _same(handed, kept)


def test_replay_windows_hands_on_each_steps_rows() -> None:
    log = synthetic_log(np.random.default_rng(3), duration=15.0)
    seen: list[tuple[ReplayStep, tuple[WindowRow, ...]]] = []
    result, windows = replay_windows(log, FLOOR, CAMERA, after_step=lambda s, r: seen.append((s, r)))
    assert [step.time for step, _ in seen] == [step.time for step in result.steps]
    assert tuple(row for _, rows in seen for row in rows) == windows.rows
    for step, rows in seen:
        assert all(row.time == step.time for row in rows)
    assert sum(1 for _, rows in seen if rows) > 3


def test_a_hook_that_is_not_callable_is_refused() -> None:
    log = synthetic_log(np.random.default_rng(3), duration=5.0)
    with pytest.raises(InputError, match=r"after_step: expected a callable or None, got int"):
        replay_log(log, FLOOR, after_step=3)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"after_step: expected a callable or None, got str"):
        replay_windows(log, FLOOR, CAMERA, after_step="x")  # type: ignore[arg-type]
