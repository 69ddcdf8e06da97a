from __future__ import annotations

import math

import numpy as np
import pytest

from aura_ums.errors import InputError, UnknownTerrainError
from aura_ums.geometry import ConvexPolygon
from aura_ums.sim import SimulatedRobot
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TerrainStats, TerrainTable, TurnAndRun
from aura_ums.world import Meadow, MeadowMap, grow_through, make_grid_world


def _strip(terrains: tuple[str, ...], length: float = 10.0) -> MeadowMap:
    meadows = [
        Meadow(
            f"m{i}",
            ConvexPolygon(
                [(i * length, -5.0), ((i + 1) * length, -5.0), ((i + 1) * length, 5.0), (i * length, 5.0)]
            ),
            terrain,
        )
        for i, terrain in enumerate(terrains)
    ]
    return MeadowMap(meadows)


def _drive(world: MeadowMap, seed: int, commands: list[TurnAndRun], start: Pose) -> list[Pose]:
    robot = SimulatedRobot(world, TerrainTable.default(), start, np.random.default_rng(seed))
    return [robot.execute(command) for command in commands]


COMMANDS = [TurnAndRun(0.3, 4.0), TurnAndRun(-0.5, 6.0), TurnAndRun(0.2, 0.0), TurnAndRun(0.1, 3.0)]


def test_motion_is_deterministic_per_seed() -> None:
    world = make_grid_world(3, 3)
    start = Pose(2.5, 2.5, 0.2)
    assert _drive(world, 7, COMMANDS, start) == _drive(world, 7, COMMANDS, start)
    assert _drive(world, 7, COMMANDS, start) != _drive(world, 8, COMMANDS, start)


def test_sample_motion_is_called_once_per_meadow_piece(monkeypatch: pytest.MonkeyPatch) -> None:
    world = make_grid_world(1, 3)  # concrete, grass, gravel, 5 m each
    table = TerrainTable.default()
    names = {id(stats): name for name, stats in table.items()}
    calls: list[tuple[TurnAndRun, str]] = []
    original = TerrainStats.sample_motion

    def recording(
        self: TerrainStats,
        pose: Pose,
        command: TurnAndRun,
        rng: np.random.Generator,
        *,
        truncate: float | None = None,
    ) -> Pose:
        calls.append((command, names[id(self)]))
        return original(self, pose, command, rng, truncate=truncate)

    monkeypatch.setattr(TerrainStats, "sample_motion", recording)
    robot = SimulatedRobot(world, table, Pose(2.5, 2.5, 0.0), np.random.default_rng(0))
    robot.execute(TurnAndRun(0.0, 10.0))
    assert [name for _, name in calls] == ["concrete", "concrete", "grass", "gravel"]
    assert calls[0][0] == TurnAndRun(0.0, 0.0)
    assert [command.run for command, _ in calls[1:]] == pytest.approx([2.5, 5.0, 2.5])
    assert list(robot.last_steps) == calls


def test_turn_uses_the_start_meadow_and_run_pieces_follow_the_true_heading() -> None:
    world = make_grid_world(1, 3)
    robot = SimulatedRobot(world, TerrainTable.default(), Pose(7.5, 2.5, math.pi), np.random.default_rng(3))
    robot.execute(TurnAndRun(math.pi, 6.0))  # turn on grass, then run east into gravel
    terrains = [terrain for _, terrain in robot.last_steps]
    assert terrains[0] == "grass"
    assert terrains[-1] == "gravel"
    assert robot.meadow.terrain == "gravel"


def test_a_run_across_two_terrains_differs_from_a_single_terrain_run() -> None:
    table = TerrainTable.default()
    mixed = _strip(("concrete", "grass"))
    plain = _strip(("concrete", "concrete"))
    start, command, n = Pose(2.5, 0.0, 0.0), TurnAndRun(0.0, 15.0), 300
    advance_mixed = np.array([_drive(mixed, s, [command], start)[0].x - start.x for s in range(n)])
    advance_plain = np.array([_drive(plain, s, [command], start)[0].x - start.x for s in range(n)])
    concrete, grass = table["concrete"], table["grass"]

    def mean_run(stats: TerrainStats, run: float) -> float:
        return run * (1.0 - stats.translation_loss) - stats.translation_inertial_loss

    expected_mixed = mean_run(concrete, 7.5) + mean_run(grass, 7.5)
    expected_plain = mean_run(concrete, 7.5) + mean_run(concrete, 7.5)
    assert advance_mixed.mean() == pytest.approx(expected_mixed, abs=0.05)
    assert advance_plain.mean() == pytest.approx(expected_plain, abs=0.05)
    assert advance_plain.mean() - advance_mixed.mean() > 0.4
    assert advance_mixed.std() > advance_plain.std()  # grass is noisier than concrete


def test_truncated_truth_stays_inside_the_map_grown_meadow_by_meadow() -> None:
    world = make_grid_world(1, 4, cell=5.0)
    table = TerrainTable.default()
    start = Pose(1.0, 2.5, 0.0)
    grown = grow_through(
        SpatialUncertaintyMap.from_pose(start, 0.0, 0.0), world, TurnAndRun(0.0, 17.0), table
    )
    for seed in range(200):
        robot = SimulatedRobot(world, table, start, np.random.default_rng(seed), truncate=3.0)
        truth = robot.execute(TurnAndRun(0.0, 17.0))
        assert grown.contains(truth.x, truth.y, truth.heading)


def test_leaving_the_map_keeps_the_last_terrain() -> None:
    world = make_grid_world(1, 1)  # one concrete cell [0, 5] x [0, 5]
    robot = SimulatedRobot(world, TerrainTable.default(), Pose(2.5, 2.5, 0.0), np.random.default_rng(0))
    robot.execute(TurnAndRun(0.0, 10.0))  # runs off the east side
    assert robot.pose.x > 5.0
    robot.execute(TurnAndRun(0.0, 3.0))  # starts outside every meadow, heads away from them
    assert [terrain for _, terrain in robot.last_steps] == ["concrete", "concrete"]
    assert robot.commanded_distance == 13.0


def test_start_outside_every_meadow_is_refused() -> None:
    with pytest.raises(InputError, match=r"pose: expected a start inside a meadow, got \(-1\.0, 0\.0\)"):
        SimulatedRobot(
            make_grid_world(1, 1), TerrainTable.default(), Pose(-1.0, 0.0, 0.0), np.random.default_rng(0)
        )


def test_unknown_terrain_is_refused() -> None:
    table = TerrainTable({"concrete": TerrainTable.default()["concrete"]})
    with pytest.raises(UnknownTerrainError, match="got 'grass'"):
        SimulatedRobot(make_grid_world(1, 2), table, Pose(1.0, 1.0, 0.0), np.random.default_rng(0))


def test_bad_arguments_are_refused() -> None:
    world, table = make_grid_world(1, 1), TerrainTable.default()
    with pytest.raises(InputError, match=r"rng: expected a numpy\.random\.Generator"):
        SimulatedRobot(world, table, Pose(1.0, 1.0, 0.0), 42)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="truncate: expected a positive number"):
        SimulatedRobot(world, table, Pose(1.0, 1.0, 0.0), np.random.default_rng(0), truncate=0.0)
    robot = SimulatedRobot(world, table, Pose(1.0, 1.0, 0.0), np.random.default_rng(0))
    with pytest.raises(InputError, match="command: expected a TurnAndRun"):
        robot.execute((0.0, 1.0))  # type: ignore[arg-type]
