"""``replay_log`` and ``compare_on_log`` report progress through a callback; a replay saves and resumes."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs import (
    ReplayOptions,
    ReplayState,
    ReverseMotion,
    SensorBounds,
    compare_on_log,
    replay_log,
    synthetic_log,
)
from aura_ums.manager import ManagerSettings
from aura_ums.uncertainty import LandmarkClass, TerrainTable

TABLE = TerrainTable({"floor": TerrainTable.default()["tile"]})


def test_replay_and_compare_report_progress_to_the_total() -> None:
    log = synthetic_log(np.random.default_rng(11), duration=15.0)
    seen: list[tuple[int, int]] = []
    result = replay_log(log, TABLE, progress=lambda done, total: seen.append((done, total)))
    frames = len(result.steps)
    assert seen == [(k, frames) for k in range(1, frames + 1)]
    compared: list[tuple[int, int]] = []
    compare_on_log(
        log,
        TABLE,
        bearing_sd=0.006,
        range_sd_fraction=0.012,
        rng=np.random.default_rng(0),
        particles=50,
        progress=lambda done, total: compared.append((done, total)),
    )
    assert compared[-1] == (3 * frames, 3 * frames)
    assert [done for done, _ in compared] == sorted(done for done, _ in compared)
    with pytest.raises(InputError, match="progress: expected a callable or None, got int"):
        replay_log(log, TABLE, progress=3)  # type: ignore[arg-type]


def test_until_stops_and_the_state_resumes_bit_for_bit() -> None:
    log = synthetic_log(np.random.default_rng(12), duration=30.0)
    whole = replay_log(log, TABLE, save_state=True)
    half = replay_log(log, TABLE, until=12.0, save_state=True)
    assert half.steps[-1].time <= 12.0 < whole.steps[len(half.steps)].time
    assert half.state is not None
    assert whole.state is not None
    saved = ReplayState.from_json(half.state.to_json())
    assert saved.to_json() == half.state.to_json()
    rest = replay_log(log, TABLE, resume=saved, save_state=True)
    assert len(half.steps) + len(rest.steps) == len(whole.steps)
    for ours, theirs in zip(rest.steps, whole.steps[len(half.steps) :], strict=True):
        assert ours.map.polygon.vertices.tobytes() == theirs.map.polygon.vertices.tobytes()
        assert ours.map.wedge == theirs.map.wedge
    assert rest.state is not None
    assert json.loads(rest.state.manager_json) == json.loads(whole.state.manager_json)


def test_a_resumed_replay_runs_and_reports_the_saved_settings() -> None:
    # Saved with the relaxed intersection and no envelope; resumed with the default options.
    log = synthetic_log(np.random.default_rng(12), duration=30.0)
    saved_settings = ManagerSettings(
        robust=False, relaxed_q=1, relaxed_window=5, slice_width=math.radians(4.0)
    )
    options = ReplayOptions(settings=saved_settings)
    whole = replay_log(log, TABLE, options, save_state=True)
    half = replay_log(log, TABLE, options, until=12.0, save_state=True)
    assert half.state is not None
    assert whole.state is not None
    rest = replay_log(log, TABLE, ReplayOptions(), resume=half.state, save_state=True)
    assert rest.options.settings == saved_settings
    metrics = rest.metrics()
    assert (metrics["relaxed_q"], metrics["relaxed_window"], metrics["robust"]) == (1, 5, False)
    assert metrics["slice_width_rad"] == saved_settings.slice_width
    assert replay_log(log, TABLE).metrics()["slice_width_rad"] is None  # the product map
    assert rest.state is not None
    assert json.loads(rest.state.manager_json) == json.loads(whole.state.manager_json)


def test_a_state_before_any_frame_and_bad_states() -> None:
    log = synthetic_log(np.random.default_rng(12), duration=10.0)
    empty = replay_log(log, TABLE, until=-1.0, save_state=True)
    assert empty.steps == ()
    # without a state to save, a replay of no frame is refused (it exited 0 with no figures)
    with pytest.raises(
        InputError, match=r"^until: expected a time at or after the replay's start \(.* s\), got -1\.0$"
    ):
        replay_log(log, TABLE, until=-1.0)
    assert empty.state is not None
    assert math.isnan(empty.state.last_time)
    assert math.isnan(ReplayState.from_json(empty.state.to_json()).last_time)
    other = synthetic_log(np.random.default_rng(13), duration=10.0)
    state = replay_log(log, TABLE, until=5.0, save_state=True).state
    with pytest.raises(InputError, match="resume: expected a state saved from a replay of log 'synthetic'"):
        replay_log(other, TABLE, resume=state)
    with pytest.raises(
        InputError, match=r"until: expected a time at or after the resumed state's last frame"
    ):
        replay_log(log, TABLE, resume=state, until=1.0)
    with pytest.raises(FileFormatError, match="log_digest: expected a string"):
        ReplayState.from_json(
            '{"format": "aura_ums.ReplayState", "version": 2, "log": "x", "frames_done": 0, '
            '"reports_posted": 0, "last_time": null, "log_digest": 1, "manager": {}, "blackboard": {}}'
        )
    with pytest.raises(FileFormatError, match="expected a key 'log', got none"):
        ReplayState.from_json('{"format": "aura_ums.ReplayState", "version": 2}')


def test_a_refused_state_says_what_does_not_fit() -> None:
    # It said which log the state was from and how far, but not what did not fit (a state
    # claiming 10^12 position reports named the same log twice and nothing else).
    log = synthetic_log(np.random.default_rng(12), duration=10.0)
    state = replay_log(log, TABLE, until=5.0, save_state=True).state
    assert state is not None
    other = synthetic_log(np.random.default_rng(13), duration=10.0)
    with pytest.raises(
        InputError, match=r"with a digest of other observations than those of the log's first \d+ frames$"
    ):
        replay_log(other, TABLE, resume=state)
    with pytest.raises(
        InputError, match=r"with reports_posted 1000000000000, more than the log's \d+ position reports$"
    ):
        replay_log(log, TABLE, resume=dataclasses.replace(state, reports_posted=10**12))
    with pytest.raises(InputError, match=r"with another log's name, 'elsewhere'$"):
        replay_log(log, TABLE, resume=dataclasses.replace(state, log_name="elsewhere"))


def test_a_state_resumes_only_with_the_inputs_it_was_saved_with() -> None:
    # The manager's JSON holds its settings, not what the replay feeds it: a state saved
    # with points resumed with bearings only (or other bounds, another terrain table) ran
    # on silently as a mix of two replays.
    log = synthetic_log(np.random.default_rng(14), duration=10.0)
    points = ReplayOptions(landmark_class=LandmarkClass.POINT)
    state = replay_log(log, TABLE, points, until=5.0, save_state=True).state
    assert state is not None
    assert ReplayState.from_json(state.to_json()).inputs == state.inputs
    lines = ReplayOptions(landmark_class=LandmarkClass.VERTICAL_LINE)
    with pytest.raises(
        InputError, match=r"^resume: expected landmark_class 'II', as the state was saved with, got 'I'$"
    ):
        replay_log(log, TABLE, lines, resume=state)
    flip = dataclasses.replace(points, reverse=ReverseMotion.FLIP)
    with pytest.raises(
        InputError, match=r"^resume: expected reverse 'error', as the state was saved with, got 'flip'$"
    ):
        replay_log(log, TABLE, flip, resume=state)
    wider = dataclasses.replace(points, working=SensorBounds(0.2, 0.3))
    with pytest.raises(
        InputError, match=r"^resume: expected the sensor bounds the state was saved with \(SHA-256 "
    ):
        replay_log(log, TABLE, wider, resume=state)
    grass = TerrainTable({"floor": TerrainTable.default()["grass"]})
    with pytest.raises(InputError, match=r"^resume: expected the terrain table the state was saved with"):
        replay_log(log, grass, points, resume=state)
    whole = replay_log(log, TABLE, points)
    rest = replay_log(log, TABLE, points, resume=state)
    assert rest.steps[-1].map.polygon.vertices.tobytes() == whole.steps[-1].map.polygon.vertices.tobytes()


def test_a_version_2_state_still_resumes_with_nothing_to_check() -> None:
    log = synthetic_log(np.random.default_rng(15), duration=10.0)
    state = replay_log(log, TABLE, until=5.0, save_state=True).state
    assert state is not None
    body = json.loads(state.to_json())
    del body["inputs"]
    body["version"] = 2
    older = ReplayState.from_json(json.dumps(body))
    assert dict(older.inputs) == {}
    lines = ReplayOptions(landmark_class=LandmarkClass.POINT)
    assert replay_log(log, TABLE, lines, resume=older).steps  # not recorded: not checked
    body["inputs"] = {}
    with pytest.raises(FileFormatError, match=r"expected only the keys \[.*'blackboard'\], got 'inputs'"):
        ReplayState.from_json(json.dumps(body))


def test_a_resumed_replay_counts_rejections_and_relocalizations_of_its_own_frames() -> None:
    # The manager's counters run from the log's first frame: a resumed replay reported them
    # whole beside figures of its own frames (3 relocalizations where its steps had none).
    log = synthetic_log(np.random.default_rng(16), duration=40.0, bearing_noise=0.05)
    log = dataclasses.replace(log, meta=dataclasses.replace(log.meta, bearing_error=0.01))  # understated
    whole = replay_log(log, TABLE)
    first = replay_log(log, TABLE, until=20.0, save_state=True)
    assert first.state is not None
    rest = replay_log(log, TABLE, resume=first.state)
    assert first.inconsistent_observations > 0
    assert first.relocalizations > 0
    for part in (first, rest):
        assert part.inconsistent_observations == int(part.trace.rejected.sum())
        assert part.relocalizations == int(part.trace.relocalized.sum())
    assert first.inconsistent_observations + rest.inconsistent_observations == whole.inconsistent_observations
    assert first.relocalizations + rest.relocalizations == whole.relocalizations
    for reason, count in whole.rejected_counts.items():
        assert first.rejected_counts.get(reason, 0) + rest.rejected_counts.get(reason, 0) == count


def test_a_replay_growing_from_anchors_saves_no_state() -> None:
    log = synthetic_log(np.random.default_rng(17), duration=10.0)
    anchored = ReplayOptions(settings=ManagerSettings(anchor_growth=True))
    with pytest.raises(
        InputError, match=r"^save_state: expected a replay without anchor_growth \(a saved state"
    ):
        replay_log(log, TABLE, anchored, until=5.0, save_state=True)
