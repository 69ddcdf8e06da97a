"""The UTIAS MRCLAM reader: on a tiny synthetic dataset, and on the real Dataset 6 when present."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs import ObservationKind, RobotLog, import_mrclam, load_log, read_mrclam
from tests.logs.log_helpers import MRCLAM6, assert_same_log

HEADER = "# UTIAS MRCLAM Dataset (made up)\n# produced by nobody\n# format\n# columns\n"
TINY = {
    "Barcodes.dat": HEADER + "  1 \t 5\n  2 \t 14\n  6 \t 63\n  7 \t 81\n",
    "Landmark_Groundtruth.dat": HEADER
    + "  6 \t 0.5 \t -4.0 \t 0.001 \t 0.002\n  7 \t 1.5 \t 2.0 \t 0.003 \t 0.0001\n",
    "Robot1_Measurement.dat": HEADER
    + "10.0 \t 14 \t 3.0 \t -0.25\n"  # robot 2: dropped
    + "10.0 \t 63 \t 2.0 \t 0.5\n"
    + "10.5 \t 99 \t 1.0 \t 0.0\n"  # unknown barcode: dropped
    + "11.0 \t 81 \t 4.0 \t -0.1\n"
    + "20.0 \t 63 \t 2.5 \t 0.2\n",  # after the ground truth ends: kept
    "Robot1_Odometry.dat": HEADER
    + "9.0 \t 0.1 \t 0.0\n9.5 \t 0.2 \t 0.1\n9.5 \t 0.3 \t 0.2\n12.0 \t 0.0 \t 0.0\n",
    "Robot1_Groundtruth.dat": HEADER + "8.0 \t 0.0 \t 0.0 \t 3.1\n12.0 \t 1.0 \t 0.0 \t -3.1\n",
}


def tiny_dataset(folder: Path, **changes: str | None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in {**TINY, **changes}.items():
        if text is not None:
            (folder / name).write_text(text)
    return folder


def test_tiny_dataset(tmp_path: Path) -> None:
    log = read_mrclam(tiny_dataset(tmp_path / "MRCLAM_Dataset9"), 1)
    assert [(o.time, o.landmark_id, o.range, o.bearing, o.line) for o in log.observations] == [
        (10.0, "6", 2.0, 0.5, 6),
        (11.0, "7", 4.0, -0.1, 8),
        (20.0, "6", 2.5, 0.2, 9),
    ]
    assert all(o.kind is ObservationKind.RANGE_BEARING for o in log.observations)
    assert [(lm.id, lm.x, lm.y) for lm in log.landmarks] == [("6", 0.5, -4.0), ("7", 1.5, 2.0)]
    assert [lm.position_uncertainty for lm in log.landmarks] == pytest.approx([0.006, 0.009])
    assert log.odometry is not None
    np.testing.assert_array_equal(log.odometry.time, [9.0, 9.5, 12.0])
    np.testing.assert_array_equal(log.odometry.v, [0.1, 0.3, 0.0])  # the repeated time keeps its last row
    assert log.groundtruth is not None
    assert len(log.groundtruth) == 2
    assert log.meta.name == "MRCLAM_Dataset9-robot1"
    assert log.meta.terrain == "floor"
    assert log.meta.source == (
        "UTIAS MRCLAM Dataset9 robot 1 (Leung et al., IJRR 2011); dropped 1 robot and 1 unknown-barcode "
        "measurements; dropped 1 repeated odometry time (kept the last row)"
    )


@pytest.mark.parametrize(
    ("changes", "pattern"),
    [
        (
            {"Robot1_Odometry.dat": HEADER + "9.0 0.1 0.0\n8.0 0.1 0.0\n"},
            r"Robot1_Odometry\.dat:6: expected non-decreasing times, got 8\.0 after 9\.0",
        ),
        ({"Robot1_Odometry.dat": HEADER}, r"Robot1_Odometry\.dat: expected at least one data row, got none"),
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 63 2.0\n"},
            r"Robot1_Measurement\.dat:5: expected 4 numbers \(time, barcode, range, bearing\), got 3",
        ),
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 63 two 0.5\n"},
            r"Robot1_Measurement\.dat:5: expected numbers",
        ),
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 63 nan 0.5\n"},
            r"Robot1_Measurement\.dat:5: expected finite numbers",
        ),
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 63 -2.0 0.5\n"},
            r"Robot1_Measurement\.dat:5: expected range a number in \[0, 10000\] m, got '-2\.0'",
        ),
        (
            {"Robot1_Groundtruth.dat": None},
            r"Robot1_Groundtruth\.dat: expected an MRCLAM data file \(time, x, y, heading\), got no such",
        ),
        ({"Barcodes.dat": None}, r"Barcodes\.dat: expected an MRCLAM data file"),
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 63.9 2.0 0.5\n"},  # int() would read 63
            r"Robot1_Measurement\.dat:5: expected a whole number as barcode, got '63\.9'",
        ),
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 99 2.0 0.5\n11.0 98 2.0 0.5\n"},
            r"Robot1_Measurement\.dat: expected measurements of the landmarks .*none: 2 of unknown",
        ),
        (
            {"Landmark_Groundtruth.dat": HEADER + "6 0.5 -4.0 -1e400 0.1\n"},
            r"Landmark_Groundtruth\.dat:5: expected finite numbers",
        ),
        # float() reads 0_1 as 1 and full-width digits as digits
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 63 2_0 0.5\n"},
            r"Robot1_Measurement\.dat:5: expected numbers \(time, barcode, range, bearing\), "
            r"got '10\.0 63 2_0",
        ),
        (
            {"Robot1_Measurement.dat": HEADER + "10.0 63 \uff12.0 0.5\n"},
            r"Robot1_Measurement\.dat:5: expected numbers \(time, barcode, range, bearing\)",
        ),
        # a form feed (or U+2028, NEL) in a comment counted as a line break: every later
        # line number was one too many
        (
            {"Robot1_Measurement.dat": HEADER + "# page\x0cbreak\u2028here\n10.0 63 -2.0 0.5\n"},
            r"Robot1_Measurement\.dat:6: expected range a number in \[0, 10000\] m",
        ),
        # each file continuous, the measurements 30 days after the rest
        (
            {"Robot1_Measurement.dat": HEADER + "2592010.0 63 2.0 0.5\n2592011.0 81 4.0 -0.1\n"},
            r"expected the times of Robot1_Odometry\.dat and Robot1_Measurement\.dat to overlap",
        ),
    ],
)
def test_malformed_files_are_named_with_their_line(
    tmp_path: Path, changes: dict[str, str | None], pattern: str
) -> None:
    with pytest.raises(FileFormatError, match=pattern):
        read_mrclam(tiny_dataset(tmp_path, **changes), 1)


def test_missing_folder_and_robot(tmp_path: Path) -> None:
    with pytest.raises(
        FileFormatError, match=r"/absent: expected a UTIAS MRCLAM dataset folder, got no such folder"
    ):
        read_mrclam(tmp_path / "absent", 1)
    with pytest.raises(
        FileFormatError,
        match=r"Robot3_Measurement\.dat: expected robot 3's .*no such file \(robots in this folder: Robot1\)",
    ):
        read_mrclam(tiny_dataset(tmp_path), 3)
    for robot in (0, 6, True, 1.0):
        with pytest.raises(InputError, match=r"robot: expected a robot number from 1 to 5"):
            read_mrclam(tmp_path, robot)  # type: ignore[arg-type]


def test_import_writes_a_log_that_loads_back_equal(tmp_path: Path) -> None:
    imported = import_mrclam(tiny_dataset(tmp_path / "data"), 1, tmp_path / "log")
    loaded = load_log(tmp_path / "log")
    assert_same_log(loaded, imported, lines=True)
    assert loaded.path == imported.path == tmp_path / "log"


# --- the real dataset --------------------------------------------------------------------------

needs_mrclam6 = pytest.mark.skipif(
    not (MRCLAM6 / "Robot1_Measurement.dat").is_file(),
    reason=f"UTIAS MRCLAM Dataset 6 not found at {MRCLAM6} (shared data is not part of the repository)",
)


@pytest.fixture(scope="module")
def robot1() -> RobotLog:
    return read_mrclam(MRCLAM6, 1)


@needs_mrclam6
def test_robot1_counts(robot1: RobotLog) -> None:
    assert len(robot1.observations) == 1534
    assert "dropped 407 robot and 1 unknown-barcode measurements" in robot1.meta.source
    assert robot1.meta.source.startswith("UTIAS MRCLAM Dataset6 robot 1 (Leung et al., IJRR 2011)")
    assert [lm.id for lm in robot1.landmarks] == [str(subject) for subject in range(6, 21)]
    # Every data line of the measurement file is either kept or counted as dropped.
    lines = (MRCLAM6 / "Robot1_Measurement.dat").read_text().splitlines()
    assert sum(1 for line in lines if line.strip() and not line.startswith("#")) == 1534 + 407 + 1
    assert robot1.odometry is not None
    assert len(robot1.odometry) == 61785
    assert robot1.groundtruth is not None
    assert len(robot1.groundtruth) == 49241


@needs_mrclam6
def test_robot1_values_match_the_files(robot1: RobotLog) -> None:
    lines = (MRCLAM6 / "Robot1_Measurement.dat").read_text().splitlines()
    barcode_lines = (MRCLAM6 / "Barcodes.dat").read_text().splitlines()
    pairs = [line.split() for line in barcode_lines if not line.startswith("#")]
    barcodes = {int(barcode): int(subject) for subject, barcode in pairs}
    for observation in robot1.observations[::97]:
        time, barcode, distance, bearing = (float(cell) for cell in lines[observation.line - 1].split())
        assert (observation.time, observation.range, observation.bearing) == (time, distance, bearing)
        assert observation.landmark_id == str(barcodes[int(barcode)])
    six = robot1.landmark("6")
    assert (six.x, six.y) == (0.58831396, -4.28264845)
    assert six.position_uncertainty == pytest.approx(3 * 0.00027395)
    assert all(a.time <= b.time for a, b in zip(robot1.observations, robot1.observations[1:], strict=False))


def test_a_subject_with_two_barcodes_is_refused(tmp_path: Path) -> None:
    # Accepted before: measurements of either barcode became that landmark.
    barcodes = TINY["Barcodes.dat"] + "  6 \t 99\n"
    folder = tiny_dataset(tmp_path / "MRCLAM_Dataset9", **{"Barcodes.dat": barcodes})
    with pytest.raises(FileFormatError, match=r"Barcodes\.dat:9: expected each subject once, got 6 again"):
        read_mrclam(folder, 1)


def test_measurements_out_of_time_order_are_sorted_and_said(tmp_path: Path) -> None:
    # Sorted in silence before: the log's source did not say its file was out of order.
    shuffled = HEADER + "11.0 \t 81 \t 4.0 \t -0.1\n10.0 \t 63 \t 2.0 \t 0.5\n20.0 \t 63 \t 2.5 \t 0.2\n"
    log = read_mrclam(tiny_dataset(tmp_path / "MRCLAM_Dataset9", **{"Robot1_Measurement.dat": shuffled}), 1)
    assert [o.time for o in log.observations] == [10.0, 11.0, 20.0]
    assert "sorted Robot1_Measurement.dat by time (1 row earlier than the one above)" in log.meta.source
    assert "sorted" not in read_mrclam(tiny_dataset(tmp_path / "in_order"), 1).meta.source


@needs_mrclam6
def test_robot2_drops_its_repeated_odometry_time() -> None:
    log = read_mrclam(MRCLAM6, 2)
    assert "dropped 1 repeated odometry time" in log.meta.source
    assert log.odometry is not None
    lines = (MRCLAM6 / "Robot2_Odometry.dat").read_text().splitlines()
    assert len(log.odometry) == sum(1 for line in lines if not line.startswith("#")) - 1


@needs_mrclam6
def test_robot1_import_round_trip(robot1: RobotLog, tmp_path: Path) -> None:
    imported = import_mrclam(MRCLAM6, 1, tmp_path / "robot1")
    assert_same_log(imported, robot1)
    assert_same_log(load_log(tmp_path / "robot1"), imported, lines=True)


@pytest.mark.parametrize(("kind", "said"), [("pipe", "a named pipe or socket"), ("folder", "a folder")])
@pytest.mark.parametrize("name", ["Robot1_Odometry.dat", "Robot1_Measurement.dat", "Barcodes.dat"])
def test_a_data_file_that_is_a_pipe_or_folder_is_named_as_such(
    tmp_path: Path, name: str, kind: str, said: str
) -> None:
    folder = tiny_dataset(tmp_path, **{name: None})
    if kind == "pipe":
        os.mkfifo(folder / name)  # opened, it would wait for a writer
    else:
        (folder / name).mkdir()
    with pytest.raises(FileFormatError, match=rf"{name}: expected a MRCLAM data file, got {said}$"):
        read_mrclam(folder, 1)
