"""Frames and find-landmark schemas: validation at entry, parameterization from records."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from aura_ums.camera import CalibrationBounds
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter, ImageWindow, PerceptualStrategy, margin_pixels
from aura_ums.perception import FastLineFinder, LineSegments, MoravecOperator, RegionSegmenter
from aura_ums.schemas import FindLandmarkSchema, Frame, SchemaStatus
from aura_ums.uncertainty import GroundLineLandmark, PointLandmark, Pose, VerticalLineLandmark
from aura_ums.world import LandmarkRecord
from tests.schemas.schema_scenes import CAMERA, map_around, pole_record

EXPECTER = Expecter(CAMERA)
POLE = VerticalLineLandmark("pole", 10.0, 0.0, 0.0, 4.0)
CORNER = PointLandmark("corner", 12.0, 2.0, 3.0)
EDGE = GroundLineLandmark("edge", (0.0, -1.0), (20.0, -1.0))
SNAPSHOT = map_around(Pose(0.0, 0.0, 0.0))


def test_frame_keeps_a_read_only_copy_of_the_image() -> None:
    image = np.zeros((480, 640), dtype=np.uint8)
    frame = Frame(1, image, SNAPSHOT)
    assert frame.time == 1.0
    assert isinstance(frame.time, float)
    assert frame.image is not image
    assert image.flags.writeable
    assert not frame.image.flags.writeable
    image[0, 0] = 9
    assert frame.image[0, 0] == 0
    frozen = np.zeros((4, 5))
    frozen.setflags(write=False)
    assert Frame(0.0, frozen, SNAPSHOT).image is frozen  # already read-only: not copied
    assert (frame.width, frame.height) == (640, 480)
    assert "640x480" in repr(frame)
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign"):
        frame.time = 2.0  # type: ignore[misc]


def test_frame_validates_its_inputs() -> None:
    with pytest.raises(InputError, match="time: expected a finite number, got inf"):
        Frame(math.inf, np.zeros((4, 4)), SNAPSHOT)
    with pytest.raises(
        InputError, match=r"image: expected a 2-D grayscale array \(h, w\), got shape \(4, 4, 3\)"
    ):
        Frame(0.0, np.zeros((4, 4, 3)), SNAPSHOT)
    with pytest.raises(
        InputError, match="image: expected a non-empty array of integers or floats, got dtype <U1"
    ):
        Frame(0.0, np.array([["a"]]), SNAPSHOT)
    with pytest.raises(InputError, match=r"non-empty array.*shape \(0, 4\)"):
        Frame(0.0, np.zeros((0, 4)), SNAPSHOT)
    nan = np.zeros((4, 5))
    nan[2, 3] = math.nan
    with pytest.raises(InputError, match=r"image: expected finite gray levels, got nan at pixel \(u=3, v=2"):
        Frame(0.0, nan, SNAPSHOT)
    with pytest.raises(InputError, match=r"image: expected finite gray levels, got inf at pixel \(u=0, v=0"):
        Frame(0.0, np.full((2, 2), np.inf, dtype=np.float32), SNAPSHOT)
    with pytest.raises(InputError, match="map: expected a SpatialUncertaintyMap, got Pose"):
        Frame(0.0, np.zeros((4, 4)), Pose(0, 0, 0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="focus: expected a SpatialUncertaintyMap or None, got Pose"):
        Frame(0.0, np.zeros((4, 4)), SNAPSHOT, focus=Pose(0, 0, 0))  # type: ignore[arg-type]
    # The map itself as its focus: nothing to search first.
    assert Frame(0.0, np.zeros((4, 4)), SNAPSHOT, focus=SNAPSHOT).focus is None


def test_line_finder_is_tuned_from_the_record() -> None:
    record = LandmarkRecord(
        POLE,
        PerceptualStrategy.LINE_FINDER,
        {"orientation": 1.5, "tolerance": 0.1, "min_length": 25.0, "min_gradient": 6.0, "buckets": 16.0},
        20.0,
        400.0,
        4,
    )
    schema = FindLandmarkSchema(record, EXPECTER)
    assert schema.detector == FastLineFinder(
        orientation=1.5, tolerance=0.1, min_length=25.0, min_gradient=6.0, buckets=16
    )
    assert schema.margin == margin_pixels(PerceptualStrategy.LINE_FINDER)
    assert (schema.confirm_frames, schema.recognition_threshold, schema.activation_range) == (4, 400.0, 20.0)
    assert schema.landmark_id == "pole"
    default = FindLandmarkSchema(
        LandmarkRecord(POLE, PerceptualStrategy.LINE_FINDER, {}, 20.0, 1.0), EXPECTER
    )
    assert isinstance(default.detector, FastLineFinder)
    assert default.detector.orientation == pytest.approx(math.pi / 2)  # a vertical line by default


def test_interest_operator_and_region_segmenter_are_parameterized() -> None:
    corner = LandmarkRecord(
        CORNER,
        PerceptualStrategy.INTEREST_OPERATOR,
        {"window": 7.0, "min_interest": 150.0, "suppression": 2.0},
        30.0,
        1.0,
    )
    assert FindLandmarkSchema(corner, EXPECTER).detector == MoravecOperator(
        size=7, threshold=150.0, suppression=2
    )
    region = LandmarkRecord(
        POLE, PerceptualStrategy.REGION_SEGMENTER, {"threshold": 120.0, "min_area": 30.0}, 30.0, 1.0
    )
    schema = FindLandmarkSchema(region, EXPECTER)
    assert schema.detector == RegionSegmenter(threshold=120.0, min_area=30)
    assert schema.margin == margin_pixels(PerceptualStrategy.REGION_SEGMENTER)


@pytest.mark.parametrize(
    ("record", "message"),
    [
        (
            LandmarkRecord(CORNER, PerceptualStrategy.INTEREST_OPERATOR, {"window": 5.5}, 30.0, 1.0),
            "corner.parameters.window: expected an integer, got 5.5",
        ),
        (
            LandmarkRecord(CORNER, PerceptualStrategy.INTEREST_OPERATOR, {"window": 4.0}, 30.0, 1.0),
            r"\.parameters\.window: expected an odd integer, got 4",
        ),
        (
            LandmarkRecord(POLE, PerceptualStrategy.REGION_SEGMENTER, {"min_aspect": 0.0}, 30.0, 1.0),
            "pole.parameters.min_aspect: expected a positive number, got 0.0",
        ),
    ],
)
def test_schema_refuses_what_it_cannot_parameterize(record: LandmarkRecord, message: str) -> None:
    with pytest.raises(InputError, match=message):
        FindLandmarkSchema(record, EXPECTER)


def test_schema_validates_its_arguments() -> None:
    record = pole_record(POLE)
    with pytest.raises(InputError, match="record: expected a LandmarkRecord, got VerticalLineLandmark"):
        FindLandmarkSchema(POLE, EXPECTER)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="expecter: expected an Expecter, got Camera"):
        FindLandmarkSchema(record, CAMERA)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="lost_frames: expected an integer >= 1, got 0"):
        FindLandmarkSchema(record, EXPECTER, lost_frames=0)
    with pytest.raises(InputError, match="lost_frames: expected an integer >= 1, got True"):
        FindLandmarkSchema(record, EXPECTER, lost_frames=True)
    with pytest.raises(InputError, match=r"tracking_margin: expected a non-negative number, got -1\.0"):
        FindLandmarkSchema(record, EXPECTER, tracking_margin=-1.0)
    with pytest.raises(InputError, match="pixel_error: expected a finite number, got nan"):
        FindLandmarkSchema(record, EXPECTER, pixel_error=math.nan)
    with pytest.raises(InputError, match="bounds: expected CalibrationBounds or None, got dict"):
        FindLandmarkSchema(record, EXPECTER, bounds={})  # type: ignore[arg-type]
    schema = FindLandmarkSchema(record, EXPECTER, bounds=CalibrationBounds(fx=2.0))
    frame = Frame(0.0, np.zeros((480, 640), dtype=np.uint8), SNAPSHOT)
    with pytest.raises(InputError, match="frame: expected a Frame, got ndarray"):
        schema.step(frame.image)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="status: expected a SchemaStatus or None, got str"):
        schema.step(frame, "tracking")  # type: ignore[arg-type]
    assert schema.step(frame, SchemaStatus()).value == 0.0  # a blank image: nothing fits


def test_frame_lines_runs_each_finder_once_per_window(monkeypatch: pytest.MonkeyPatch) -> None:
    image = np.zeros((60, 80), dtype=np.uint8)
    image[:, 40:] = 200
    frame = Frame(0.0, image, SNAPSHOT)
    calls: list[tuple[FastLineFinder, ImageWindow]] = []
    original = FastLineFinder.find_detailed

    def counted(self: FastLineFinder, pixels: object, window: ImageWindow | None = None) -> LineSegments:
        assert window is not None
        calls.append((self, window))
        return original(self, pixels, window)  # type: ignore[arg-type]

    monkeypatch.setattr(FastLineFinder, "find_detailed", counted)
    whole, left = ImageWindow(-0.5, -0.5, 79.5, 59.5), ImageWindow(-0.5, -0.5, 30.5, 59.5)
    vertical = FastLineFinder(orientation=math.pi / 2)
    first = frame.lines(vertical, whole)
    again = frame.lines(FastLineFinder(orientation=math.pi / 2), whole)  # equal, not the same object
    assert again is first
    assert len(calls) == 1
    assert first.segments.tolist() == original(vertical, image, whole).segments.tolist()
    assert first.segments.shape == (1, 4)
    assert not first.segments.flags.writeable  # shared: nobody may change it
    # Another window, or another finder, is another search.
    assert frame.lines(vertical, left).segments.shape == (0, 4)
    assert frame.lines(dataclasses.replace(vertical, min_length=70.0), whole).segments.shape == (0, 4)
    assert len(calls) == 3
    # Another frame of the same image searches again: nothing is shared across frames.
    Frame(0.1, image, SNAPSHOT).lines(vertical, whole)
    assert len(calls) == 4
