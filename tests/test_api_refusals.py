"""Bad arguments to the library's public API: an AuraUmsError naming the argument, never from inside.

Each case was found by a sweep of every public class and function with wrong-typed and
out-of-range values, and raised a TypeError, AttributeError or numpy error from deep inside
(or was accepted) before.
"""

# mypy: disable-error-code="arg-type"
# (the arguments are wrong on purpose)

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from aura_ums.baselines import chi2_quantile, motion_moments
from aura_ums.campaign import LoadLog, batches
from aura_ums.errors import AuraUmsError, InputError
from aura_ums.logs import (
    LogObservation,
    ReplayOptions,
    SensorBounds,
    calibrate_logs,
    compare_on_log,
    filter_settings,
    load_log,
    log_meadow_map,
    observation_for,
    open_log,
    replay_log,
    synthetic_log,
)
from aura_ums.manager import IdentifiedLandmarkBuffer, MapProfile, RejectReason
from aura_ums.plot import experiment_table, run_down_path
from aura_ums.schemas import SchemaManager
from aura_ums.sim import Scene, ground_texture, landmark_points, random_clutter, waypoints_array
from aura_ums.uncertainty import (
    Composite,
    GroundLineLandmark,
    LandmarkClass,
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    TerrainTable,
    TurnAndRun,
    anchor_bounds,
    intersect_maps,
    union_of_maps,
)
from aura_ums.world import MeadowMap, Route, commands_for, grow_through, make_grid_world

LOG = synthetic_log(np.random.default_rng(1), duration=5.0)
FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
ROW = LogObservation(2.5, "pole", 0.25, range=4.0)
BOUNDS = SensorBounds(0.05, 0.0, 0.1, 0.1)
RNG = np.random.default_rng(0)
WORLD = make_grid_world(1, 2)
START = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
TILE = TerrainTable.default()["tile"]

CASES: list[tuple[str, Callable[[], Any], str]] = [
    ("symbol", lambda: PointLandmark("c", 5.0, 2.0, 3.5, symbol=object()), r"^c\.symbol: expected a string"),
    (
        "symbol",
        lambda: GroundLineLandmark("e", (0, 0), (1, 0), symbol=None),
        r"^e\.symbol: expected a string",
    ),
    ("meadows", lambda: MeadowMap(None, ()), r"^meadows: expected a sequence of Meadow, got NoneType$"),
    ("observations", lambda: IdentifiedLandmarkBuffer(5), r"^observations: expected an iterable"),
    ("schemas", lambda: SchemaManager(None), r"^schemas: expected an iterable of FindLandmarkSchema"),
    ("meadow_ids", lambda: Route([[0, 0], [1, 1]], None), r"^meadow_ids: expected a sequence of meadow ids"),
    ("folder", lambda: load_log(None), r"^folder: expected a path \(str or os\.PathLike\), got NoneType$"),
    ("folder", lambda: open_log(0), r"^folder: expected a path \(str or os\.PathLike\), got int$"),
    ("before_frame", lambda: replay_log(LOG, FLOOR, before_frame="x"), r"^before_frame: expected a callable"),
    ("steps_csv", lambda: replay_log(LOG, FLOOR, steps_csv=0), r"^steps_csv: expected a path"),
    (
        "max_truth_gap",
        lambda: LoadLog(max_truth_gap=-1.0),
        r"^LoadLog\.max_truth_gap: expected a positive number of seconds \(or inf\), got -1\.0$",
    ),
    ("logs", lambda: calibrate_logs(None), r"^logs: expected a sequence of RobotLog, got NoneType$"),
    (
        "anchor",
        lambda: calibrate_logs([LOG], anchor=float("nan")),
        r"^anchor: expected True or False, got nan$",
    ),
    ("horizons", lambda: calibrate_logs([LOG], horizons=None), r"^horizons: expected a sequence of seconds"),
    (
        "log",
        lambda: filter_settings("x", bearing_sd=0.01, range_sd_fraction=0.01),
        r"^log: expected a RobotLog",
    ),
    (
        "bearing_sd",
        lambda: filter_settings(LOG, bearing_sd=float("nan"), range_sd_fraction=0.01),
        r"^bearing_sd: expected a finite number, got nan$",
    ),
    (
        "options",
        lambda: compare_on_log(LOG, FLOOR, "x", bearing_sd=0.01, range_sd_fraction=0.01, rng=RNG),
        r"^options: expected ReplayOptions or None",
    ),
    ("log", lambda: log_meadow_map("x", LandmarkClass.POINT), r"^log: expected a RobotLog, got str$"),
    ("row", lambda: observation_for("x", LandmarkClass.POINT, BOUNDS), r"^row: expected a LogObservation"),
    ("bounds", lambda: observation_for(ROW, LandmarkClass.POINT, None), r"^bounds: expected SensorBounds"),
    (
        "factor",
        lambda: observation_for(ROW, LandmarkClass.POINT, BOUNDS, factor=None),
        r"^factor: expected a",
    ),
    ("landmark_class", lambda: ReplayOptions(landmark_class="II"), r"landmark_class: expected .*, got 'II'"),
    (
        "table",
        lambda: commands_for(WORLD, Pose(2.5, 2.5, 0.0), TurnAndRun(0.0, 1.0), None),
        r"^table: expected a",
    ),
    (
        "table",
        lambda: grow_through(START, WORLD, TurnAndRun(0.0, 1.0), None),
        r"^table: expected a TerrainTable",
    ),
    ("rng", lambda: make_grid_world(1, 2, rng="x"), r"^rng: expected a numpy\.random\.Generator, got str$"),
    (
        "remove",
        lambda: make_grid_world(1, 2, remove=5),
        r"^remove: expected a sequence of \(row, col\) cells",
    ),
    ("maps", lambda: union_of_maps(None), r"^maps: expected a sequence of SpatialUncertaintyMap"),
    (
        "others",
        lambda: intersect_maps(START, None, 64),
        r"^others: expected a sequence of SpatialUncertaintyMap",
    ),
    ("max_vertices", lambda: intersect_maps(START, [START], object()), r"^max_vertices: expected an integer"),
    (
        "terrain",
        lambda: anchor_bounds(None, Composite(), 3.0),
        r"^terrain: expected TerrainStats, got NoneType$",
    ),
    ("sigmas", lambda: anchor_bounds(TILE, Composite(), float("nan")), r"^sigmas: expected a finite number"),
    ("rng", lambda: ground_texture(None), r"^rng: expected a numpy\.random\.Generator, got NoneType$"),
    (
        "rng",
        lambda: random_clutter((0.0, 0.0, 1.0, 1.0), 2, None),
        r"^rng: expected a numpy\.random\.Generator",
    ),
    (
        "landmark",
        lambda: landmark_points(None),
        r"^landmark: expected a VerticalLineLandmark or PointLandmark",
    ),
    ("scenario", lambda: waypoints_array(None), r"^scenario: expected a Scenario, got NoneType$"),
    ("terrain", lambda: motion_moments(None, TurnAndRun(0.0, 1.0)), r"^terrain: expected TerrainStats"),
    ("steps", lambda: run_down_path(RNG, steps=None), r"^steps: expected an integer >= 0, got None$"),
    ("scenario", lambda: experiment_table(None, None), r"^scenario: expected a Scenario, got NoneType$"),
    ("poles", lambda: Scene(poles=None), r"^Scene\.poles: expected a sequence of Pole, got NoneType$"),
    ("count", lambda: batches((1, 2), None), r"^count: expected an integer >= 1, got None$"),
    (
        "probability",
        lambda: chi2_quantile(float("nan"), 2),
        r"^probability: expected a finite number, got nan$",
    ),
    (
        "LandmarkClass",
        lambda: LandmarkClass("x"),
        r"^LandmarkClass: expected one of 'I', 'II', 'III', got 'x'$",
    ),
    (
        "MapProfile",
        lambda: MapProfile("fast"),
        r"^MapProfile: expected one of 'product', 'sliced', 'relaxed'",
    ),
    ("RejectReason", lambda: RejectReason("stale"), r"^RejectReason: expected one of .*, got 'stale'$"),
]


@pytest.mark.parametrize(("name", "call", "message"), CASES, ids=[f"{i}-{c[0]}" for i, c in enumerate(CASES)])
def test_a_bad_argument_is_refused_by_name(name: str, call: Callable[[], Any], message: str) -> None:
    with pytest.raises(InputError, match=message) as raised:
        call()
    assert isinstance(raised.value, (AuraUmsError, ValueError))
    assert name in str(raised.value)
