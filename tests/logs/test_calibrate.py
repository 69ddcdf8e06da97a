"""Calibration of terrain statistics, motion and sensor bounds from logs with ground truth."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs import (
    Calibration,
    GroundTruth,
    LogMeta,
    MotionCalibration,
    Odometry,
    RobotLog,
    SensorBounds,
    calibrate_logs,
    fitted_for_anchor,
    horizon_checks,
    load_noise,
    load_sensors,
    observation_errors,
    synthetic_log,
)
from aura_ums.uncertainty import Pose, TerrainTable
from tests.logs.log_helpers import LOSSLESS, MRCLAM6, steady_arc_log

MRCLAM = MRCLAM6


def test_calibration_recovers_the_synthetic_sensor_bounds() -> None:
    log = synthetic_log(np.random.default_rng(0), duration=120.0, bearing_noise=0.02, range_noise=0.05)
    calibration = calibrate_logs([log], quantile=0.99)
    bearing, ranges = observation_errors([log])
    assert np.abs(bearing).max() <= 0.02 + 1e-9
    assert 0.015 < calibration.working.bearing_error <= 0.02
    assert calibration.envelope.bearing_error >= calibration.working.bearing_error
    assert 0.03 < calibration.working.range_fraction_low < 0.06
    assert 0.03 < calibration.working.range_fraction_high < 0.06
    assert calibration.motion.delay_s == 0.0  # the synthetic commands are not delayed
    assert ranges.size == bearing.size


def test_the_envelope_covers_a_range_read_far_short_of_the_truth(tmp_path: Path) -> None:
    # capped at 0.95, the envelope said the truth was at most 1.95 times the measured range,
    # and a landmark 7 m away read at 0.3 m left the envelope map without the truth
    log = synthetic_log(np.random.default_rng(0), duration=120.0, bearing_noise=0.02, range_noise=0.05)
    first = next(index for index, seen in enumerate(log.observations) if seen.range is not None)
    seen = log.observations[first]
    assert seen.range is not None
    short = dataclasses.replace(seen, range=seen.range / 20.0)
    observations = (*log.observations[:first], short, *log.observations[first + 1 :])
    calibration = calibrate_logs([dataclasses.replace(log, observations=observations)])
    envelope = calibration.envelope
    assert envelope.range_fraction_low > 19.0 * 1.25 * 0.99
    _, upper = envelope.range_interval(short.range or 0.0)
    assert upper >= seen.range * 0.99
    assert calibration.working.range_fraction_low < 0.06  # one outlier: not in the 0.99 quantile
    path = tmp_path / "sensors.toml"
    path.write_text(calibration.sensors_toml())
    assert load_sensors(path)[2] == envelope
    with pytest.raises(
        InputError, match=r"SensorBounds\.range_fraction_low: expected a number in \[0, 100\]"
    ):
        SensorBounds(0.1, 0.0, 101.0, 0.0)
    with pytest.raises(InputError, match=r"SensorBounds\.range_fraction_high: expected a number in \[0, 1\)"):
        SensorBounds(0.1, 0.0, 0.0, 1.0)


def test_a_steady_turn_rate_reveals_no_delay() -> None:
    # Every delay aligns a constant turn rate alike; the search took the one float noise
    # favoured (0.75 s), and the replay then lagged the truth by 0.75 s of motion throughout.
    assert calibrate_logs([steady_arc_log()]).motion.delay_s == 0.0


def test_a_delay_the_turns_reveal_is_found() -> None:
    log = synthetic_log(np.random.default_rng(3), duration=120.0)
    assert log.commands is not None
    # Commands recorded 0.3 s before the robot carried them out.
    early = tuple(dataclasses.replace(report, time=report.time - 0.3) for report in log.commands)
    delayed = dataclasses.replace(log, commands=early)
    assert calibrate_logs([delayed]).motion.delay_s == pytest.approx(0.3)


def test_sensor_file_round_trips(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(1), duration=60.0)
    calibration = calibrate_logs([log])
    path = tmp_path / "sensors.toml"
    path.write_text(calibration.sensors_toml())
    motion, working, envelope = load_sensors(path)
    assert (motion, working, envelope) == (calibration.motion, calibration.working, calibration.envelope)
    table = TerrainTable.from_toml(_write(tmp_path / "terrain.toml", calibration.terrain_table().to_toml()))
    assert table["floor"] == calibration.stats


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_the_sensor_file_says_which_growth_its_statistics_are_for(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(1), duration=60.0)
    for anchor in (False, True):
        text = calibrate_logs([log], anchor=anchor).sensors_toml()
        path = _write(tmp_path / f"{anchor}.toml", text)
        assert fitted_for_anchor(path) is anchor
        assert load_sensors(path)  # the key is read by both readers
    older = _write(tmp_path / "older.toml", text.replace('growth = "anchor"\n', ""))
    assert fitted_for_anchor(older) is None  # written before the files said
    wrong = _write(tmp_path / "wrong.toml", text.replace('growth = "anchor"', 'growth = "sometimes"'))
    with pytest.raises(
        FileFormatError, match=r"wrong\.toml: growth: expected 'move' or 'anchor', got 'sometimes'"
    ):
        load_sensors(wrong)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('format = "aura-ums/sensor-calibration"\n', "expected keys"),
        ("format = [", r"bad\.toml:1:11: expected valid TOML, got Invalid value"),
        (
            'format = "aura-ums/sensor-calibration"\nmotion = 1\nworking = 2\nenvelope = 3\n',
            r"\[motion\]: expected a table, got 1",
        ),
        (
            'format = "aura-ums/sensor-calibration"\n[motion]\ndelay_s = "0"\nrun_scale = 1\nturn_scale = 1\n'
            "[working]\n[envelope]\n",
            r"bad\.toml: \[motion\] delay_s: expected a finite number, got '0'",
        ),
        (
            'format = "x"\n[motion]\n[working]\n[envelope]\n',
            "format: expected 'aura-ums/sensor-calibration'",
        ),
    ],
)
def test_bad_sensor_files_name_the_file(tmp_path: Path, text: str, match: str) -> None:
    path = _write(tmp_path / "bad.toml", text)
    with pytest.raises(FileFormatError, match=match):
        load_sensors(path)


def test_missing_sensor_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(
        FileFormatError, match=r"nothere.toml: expected an existing sensor calibration TOML file"
    ):
        load_sensors(tmp_path / "nothere.toml")


def test_out_of_range_sensor_value_is_named(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(1), duration=60.0)
    text = (
        calibrate_logs([log])
        .sensors_toml()
        .replace("[working]\nbearing_error = ", "[working]\nbearing_error = -")
    )
    with pytest.raises(
        FileFormatError,
        match=r"neg\.toml: \[working\] bearing_error: expected a number in \[1e-06, 1000\] rad",
    ):
        load_sensors(_write(tmp_path / "neg.toml", text))


def test_an_envelope_narrower_than_the_working_bounds_is_refused(tmp_path: Path) -> None:
    calibration = calibrate_logs([synthetic_log(np.random.default_rng(1), duration=60.0)])
    narrow = calibration.working.bearing_error / 2.0
    text = re.sub(
        r"(\[envelope\]\nbearing_error = )[^\n]+",
        lambda m: f"{m.group(1)}{narrow!r}",
        calibration.sensors_toml(),
    )
    with pytest.raises(
        FileFormatError,
        match=r"narrow\.toml: \[envelope\] bearing_error: expected at least \[working\] bearing_error",
    ):
        load_sensors(_write(tmp_path / "narrow.toml", text))


@pytest.mark.parametrize(("key", "value"), [("run_scale", "1e-300"), ("turn_scale", "1e4")])
def test_an_odometry_scale_beyond_any_units_is_refused(tmp_path: Path, key: str, value: str) -> None:
    text = re.sub(
        rf"(\n{key} = )[^\n]+",
        lambda m: f"{m.group(1)}{value}",
        calibrate_logs([synthetic_log(np.random.default_rng(1), duration=60.0)]).sensors_toml(),
    )
    with pytest.raises(FileFormatError, match=rf"\[motion\] {key}: expected a number in \[0\.001, 1000\]"):
        load_sensors(_write(tmp_path / "scale.toml", text))


def test_calibration_input_errors() -> None:
    log = synthetic_log(np.random.default_rng(1), duration=30.0)
    with pytest.raises(InputError, match="expected at least one log"):
        calibrate_logs([])
    with pytest.raises(InputError, match="expected logs with ground truth"):
        calibrate_logs([dataclasses.replace(log, groundtruth=None)])
    with pytest.raises(InputError, match="quantile: expected a number in"):
        calibrate_logs([log], quantile=1.0)
    other = dataclasses.replace(log, meta=dataclasses.replace(log.meta, terrain="grass"))
    with pytest.raises(InputError, match="expected logs on one terrain"):
        calibrate_logs([log, other])


def test_sensor_bounds_range_interval_is_sound_for_relative_errors() -> None:
    bounds = SensorBounds(0.01, 0.0, 0.1, 0.05)
    rng = np.random.default_rng(3)
    true = rng.uniform(0.5, 10.0, 1000)
    error = rng.uniform(-0.1, 0.05, 1000)  # (measured - true) / measured in [-low, high]
    measured = true / (1.0 - error)
    for m, t in zip(measured, true, strict=True):
        low, high = bounds.range_interval(float(m))
        assert low - 1e-9 <= t <= high + 1e-9


@pytest.mark.skipif(not MRCLAM.is_dir(), reason=f"MRCLAM data not found at {MRCLAM}")
def test_mrclam_calibration_finds_the_command_delay_and_heavy_tails(
    mrclam6_robot1_calibration: Calibration,
) -> None:
    calibration = mrclam6_robot1_calibration
    assert 0.1 <= calibration.motion.delay_s <= 0.3  # commanded velocities lead the robot
    assert calibration.motion.run_scale > 1.0  # the robot sometimes outruns its command
    assert calibration.envelope.bearing_error > 1.5 * calibration.working.bearing_error


def test_sensor_file_with_a_byte_order_mark_reads_the_same(tmp_path: Path) -> None:
    text = calibrate_logs([synthetic_log(np.random.default_rng(1), duration=60.0)]).sensors_toml()
    plain = load_sensors(_write(tmp_path / "plain.toml", text))
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + text.encode())
    assert load_sensors(tmp_path / "bom.toml") == plain


def test_latin1_sensor_file_is_refused_naming_it(tmp_path: Path) -> None:
    (tmp_path / "latin.toml").write_bytes('format = "x"\n# \u00b0\n'.encode("latin-1"))
    with pytest.raises(
        FileFormatError, match=r"latin\.toml:2: byte 15: expected UTF-8 text, got the byte 0xb0"
    ):
        load_sensors(tmp_path / "latin.toml")


def test_sensor_file_carries_the_filters_noise(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(1), duration=60.0)
    calibration = calibrate_logs([log])
    path = _write(tmp_path / "sensors.toml", calibration.sensors_toml())
    assert load_noise(path) == calibration.noise
    bearing, _ = observation_errors([log])
    assert calibration.noise.bearing_sd == pytest.approx(float(np.std(bearing)))
    # A file written before the [noise] table existed still reads, without noise.
    older = calibration.sensors_toml().split("\n[noise]")[0] + "\n"
    assert load_noise(_write(tmp_path / "older.toml", older)) is None
    assert load_sensors(tmp_path / "older.toml") == load_sensors(path)


def test_range_bounds_are_absolute_plus_relative() -> None:
    log = synthetic_log(np.random.default_rng(0), duration=120.0, range_noise=0.05)
    working = calibrate_logs([log]).working
    assert working.range_error > 0.0
    low, high = working.range_interval(0.0)
    assert high - low > 0.0  # a zero range still gets a bound of some width


@pytest.mark.skipif(not MRCLAM.is_dir(), reason=f"MRCLAM data not found at {MRCLAM}")
def test_mrclam_growth_bound_holds_over_the_horizons_it_is_used(
    mrclam6_robot1_calibration: Calibration,
) -> None:
    calibration = mrclam6_robot1_calibration
    checks = {check.horizon: check for check in calibration.checks}
    assert sorted(checks) == [1.0, 2.0, 5.0, 10.0, 30.0]
    for horizon in (5.0, 10.0, 30.0):
        assert checks[horizon].containment >= 0.99
        assert checks[horizon].heading_bound >= checks[horizon].heading_error
    # The bound still grows faster than the error: the report shows by how much.
    assert (
        checks[30.0].heading_bound / checks[30.0].heading_error
        > checks[5.0].heading_bound / checks[5.0].heading_error
    )
    assert "horizon s" in calibration.report()


def test_horizons_shorter_than_a_move_are_refused() -> None:
    log = synthetic_log(np.random.default_rng(0), duration=30.0)
    with pytest.raises(InputError, match=r"horizons: expected seconds, each >= move \(0\.5\)"):
        calibrate_logs([log], horizons=(0.25, 1.0))


def test_anchor_calibration_scales_by_the_mean_and_says_what_it_is_for() -> None:
    log = synthetic_log(np.random.default_rng(0), duration=120.0)
    calibration = calibrate_logs([log], anchor=True)
    stats = calibration.stats
    assert calibration.anchor
    assert (stats.translation_loss, stats.rotation_loss, stats.skitter) == (0.0, 0.0, 0.0)
    assert "growth from an anchor" in calibration.sensors_toml()
    assert "growth move by move" in calibrate_logs([log]).sensors_toml()
    # The bound was fitted to cover the quantile at every horizon; the check grows the same way.
    for check in calibration.checks:
        assert check.containment >= 0.97


@pytest.mark.skipif(not MRCLAM.is_dir(), reason=f"MRCLAM data not found at {MRCLAM}")
def test_mrclam_anchor_bound_holds_at_every_horizon_and_grows_sublinearly(
    mrclam6_robot1: RobotLog, mrclam6_robot1_calibration: Calibration
) -> None:
    anchored = {c.horizon: c for c in calibrate_logs([mrclam6_robot1], anchor=True).checks}
    per_move = {c.horizon: c for c in mrclam6_robot1_calibration.checks}
    for check in anchored.values():
        # A point start: the truth's own millimetres count; the fit covers 0.99 of the windows.
        assert check.containment >= 0.98
    for horizon in (10.0, 30.0):
        assert anchored[horizon].heading_bound < 0.5 * per_move[horizon].heading_bound
        assert anchored[horizon].position_bound < 0.6 * per_move[horizon].position_bound


def _shuttle_log(*, v: float = 0.3, omega: float = 0.1, leg: float = 4.0, duration: float = 40.0) -> RobotLog:
    """A robot running ``leg`` s forward, then as long backing up, turning steadily; exact odometry, truth."""
    rate, truth_rate = 50.0, 20.0
    time = np.arange(0.0, duration + 1e-9, 1.0 / rate)
    speed = np.where(np.floor(time / leg) % 2 == 0, v, -v)
    truth_time = np.arange(0.0, duration + 1e-9, 1.0 / truth_rate)
    x, y, heading, at = [0.0], [0.0], [0.0], 0.0
    # Closed form within each leg (constant speed and turn rate), leg by leg.
    for when in truth_time[1:]:
        signed = v if math.floor(at / leg) % 2 == 0 else -v
        h0, h1 = heading[-1], heading[-1] + omega * (when - at)
        x.append(x[-1] + signed / omega * (math.sin(h1) - math.sin(h0)))
        y.append(y[-1] - signed / omega * (math.cos(h1) - math.cos(h0)))
        heading.append(h1)
        at = when
    meta = LogMeta("shuttle", terrain="lossless", start=Pose(0.0, 0.0, 0.0))
    return RobotLog(
        meta,
        (),
        (),
        odometry=Odometry(time, speed, np.full(len(time), omega)),
        groundtruth=GroundTruth(truth_time, np.array(x), np.array(y), np.array(heading)),
    )


@pytest.mark.parametrize("move", [0.5, 0.3])
def test_the_bound_check_grows_a_move_backing_up_as_a_flipped_replay_does(move: float) -> None:
    # Backing up was grown as a forward run, so the check judged every window that backs up
    # against a truth on the far side of its start: containment 0.35 at 30 s on a real log
    # whose replay (--reverse flip) kept the truth. Legs of 4 s: with 0.3 s moves, some
    # moves both run and back up.
    log = _shuttle_log()
    assert bool((log.odometry is not None) and (log.odometry.v < 0).any())
    checks = horizon_checks([log], LOSSLESS, MotionCalibration(), horizons=(1.0, 2.0, 10.0), move=move)
    assert [c.windows > 0 for c in checks] == [True, True, True]
    assert [c.containment for c in checks] == [1.0, 1.0, 1.0]


def test_no_log_is_refused_where_it_gave_nan_checks() -> None:
    with pytest.raises(InputError, match="logs: expected at least one RobotLog, got none"):
        horizon_checks([], TerrainTable.default()["tile"], MotionCalibration())
    with pytest.raises(InputError, match=r"logs\[0\]: expected a RobotLog, got NoneType"):
        horizon_checks([None], TerrainTable.default()["tile"], MotionCalibration())  # type: ignore[list-item]


def test_observation_errors_refuses_what_is_not_logs() -> None:
    # a TypeError and an AttributeError before
    nothing: Any = None
    with pytest.raises(InputError, match="logs: expected a sequence of RobotLog, got NoneType"):
        observation_errors(nothing)
    with pytest.raises(InputError, match=r"logs\[0\]: expected a RobotLog, got NoneType"):
        observation_errors([nothing])
