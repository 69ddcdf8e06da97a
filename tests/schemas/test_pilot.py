"""The pilot: one find-landmark schema per landmark of the leg's short-term memory."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aura_ums.camera import CalibrationBounds, Camera, CameraIntrinsics, CameraMount
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter, PerceptualStrategy, margin_pixels
from aura_ums.manager import IdentifiedLandmarkBuffer
from aura_ums.perception import FastLineFinder, MoravecOperator
from aura_ums.schemas import FindLandmarkSchema, Frame, Pilot, SchemaManager, SchemaState
from aura_ums.uncertainty import LandmarkClass, Pose, SpatialUncertaintyMap
from aura_ums.world import ShortTermMemory, plan_route, sample_world
from tests.schemas.schema_scenes import CAMERA


@pytest.fixture(scope="module")
def sidewalk_stm() -> ShortTermMemory:
    world = sample_world("paper_sidewalk")
    route = plan_route(world, (0.0, 0.0), (12.192, 0.0))
    assert len(route.legs) >= 1
    start, end = route.legs[0]
    return ShortTermMemory.for_leg(world, start, end)


def test_pilot_builds_one_schema_per_stm_landmark(sidewalk_stm: ShortTermMemory) -> None:
    schemas = Pilot(CAMERA).schemas_for_leg(sidewalk_stm)
    assert [s.landmark_id for s in schemas] == list(sidewalk_stm.landmark_ids)
    assert len(schemas) == len(sidewalk_stm.landmarks) >= 5
    for schema, record in zip(schemas, sidewalk_stm.landmarks, strict=True):
        assert isinstance(schema, FindLandmarkSchema)
        assert schema.record is record
        assert schema.confirm_frames == record.confirm_frames
        assert schema.recognition_threshold == record.recognition_threshold
        assert schema.activation_range == record.activation_range
        assert schema.margin == margin_pixels(record.strategy)
        params = record.parameters
        if record.landmark_class is LandmarkClass.VERTICAL_LINE:
            assert record.strategy is PerceptualStrategy.LINE_FINDER
            assert isinstance(schema.detector, FastLineFinder)
            # "filters and/or buckets will be tuned to specific line orientations"
            assert schema.detector.orientation == pytest.approx(params["orientation"] % math.pi)
            assert schema.detector.orientation == pytest.approx(math.pi / 2)
            assert schema.detector.tolerance == pytest.approx(params["tolerance"])
            assert schema.detector.min_length == pytest.approx(params["min_length"])
        elif record.landmark_class is LandmarkClass.POINT:
            assert record.strategy is PerceptualStrategy.INTEREST_OPERATOR
            assert schema.detector == MoravecOperator(
                size=int(params["window"]), threshold=params["min_interest"]
            )
        else:
            assert record.strategy is PerceptualStrategy.LINE_FINDER
            assert isinstance(schema.detector, FastLineFinder)
            assert schema.detector.orientation is None  # tuned each frame to the predicted image direction
            assert schema.detector.tolerance == pytest.approx(params["tolerance"])
            assert schema.detector.min_length == pytest.approx(params["min_length"])
    by_id = {s.landmark_id: s for s in schemas}
    assert by_id["lamppost_107"].detector.tolerance == pytest.approx(math.radians(8.0))  # type: ignore[union-attr]
    assert by_id["telephone_pole_12"].detector.tolerance == pytest.approx(math.radians(10.0))  # type: ignore[union-attr]
    assert isinstance(by_id["east_engineering_corner"].detector, MoravecOperator)


def test_start_leg_instantiates_the_schemas_hibernating(sidewalk_stm: ShortTermMemory) -> None:
    buffer = IdentifiedLandmarkBuffer()
    pilot = Pilot(
        CAMERA, lost_frames=3, tracking_margin=10.0, pixel_error=1.0, bounds=CalibrationBounds(fx=1.0)
    )
    manager = pilot.start_leg(sidewalk_stm, buffer=buffer)
    assert isinstance(manager, SchemaManager)
    assert manager.buffer is buffer
    assert [s.landmark_id for s in manager.schemas] == list(sidewalk_stm.landmark_ids)
    assert set(manager.states.values()) == {SchemaState.HIBERNATING}
    for schema in manager.schemas:
        assert (schema.lost_frames, schema.tracking_margin, schema.pixel_error) == (3, 10.0, 1.0)
        assert schema.bounds == CalibrationBounds(fx=1.0)
        assert schema.expecter is pilot.expecter
    # at the start of the leg, the activation criteria wake the landmarks in range
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.3, math.radians(3))
    step = manager.step(Frame(0.0, np.full((480, 640), 100, dtype=np.uint8), start))
    awake = {r.landmark_id for r in step.schemas if r.state is not SchemaState.HIBERNATING}
    assert awake == set(sidewalk_stm.landmark_ids)  # all within their ranges from (0, 0)
    far = SpatialUncertaintyMap.from_pose(Pose(-60.0, 0.0, 0.0), 0.3, math.radians(3))
    step = manager.step(Frame(0.1, np.full((480, 640), 100, dtype=np.uint8), far))
    assert {r.state for r in step.schemas} == {SchemaState.HIBERNATING}


def test_pilot_uses_or_builds_its_expecter() -> None:
    assert Pilot(CAMERA).expecter == Expecter(CAMERA)
    mine = Expecter(CAMERA)
    assert Pilot(CAMERA, expecter=mine).expecter is mine
    # The calibration bounds its observations allow for, its windows allow for too.
    bounds = CalibrationBounds(cx=2.0, pan=0.01)
    assert Pilot(CAMERA, bounds=bounds).expecter == Expecter(CAMERA, bounds)


def test_pilot_validates_its_inputs(sidewalk_stm: ShortTermMemory) -> None:
    other = Camera(CameraIntrinsics(400, 400, 320, 240, 640, 480), CameraMount(height=1.5))
    with pytest.raises(
        InputError, match="expecter: expected an Expecter for the pilot's camera, got one for"
    ):
        Pilot(CAMERA, expecter=Expecter(other))
    with pytest.raises(InputError, match="expecter: expected an Expecter or None, got Camera"):
        Pilot(CAMERA, expecter=other)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="camera: expected a Camera, got Expecter"):
        Pilot(Expecter(CAMERA))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="lost_frames: expected an integer >= 1, got 0"):
        Pilot(CAMERA, lost_frames=0)
    with pytest.raises(InputError, match=r"tracking_margin: expected a non-negative number, got -2\.0"):
        Pilot(CAMERA, tracking_margin=-2.0)
    with pytest.raises(InputError, match=r"pixel_error: expected a non-negative number, got -0\.5"):
        Pilot(CAMERA, pixel_error=-0.5)
    with pytest.raises(InputError, match="bounds: expected CalibrationBounds or None, got float"):
        Pilot(CAMERA, bounds=0.5)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="stm: expected a ShortTermMemory, got tuple"):
        Pilot(CAMERA).schemas_for_leg(sidewalk_stm.landmarks)  # type: ignore[arg-type]


def test_pilot_on_the_indoor_corridor() -> None:
    world = sample_world("indoor_corridor")
    stm = ShortTermMemory.for_leg(
        world,
        *plan_route(world, world.meadows[0].polygon.centroid, world.meadows[1].polygon.centroid).legs[0],
    )
    schemas = Pilot(CAMERA).schemas_for_leg(stm)
    assert [s.landmark_id for s in schemas] == list(stm.landmark_ids)
