"""Growth on maps: the documented motion bounds, and a run of growths equal to growing one by one.

The growth kernel against its numpy reference, and its vertex cap: tests/_native.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.uncertainty import (
    MotionBounds,
    Pose,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    motion_bounds,
)


def _clipped(value: float, lo: float, hi: float) -> float:
    return lo if value < lo else hi if value > hi else value


def _motion_bounds_as_documented(stats: TerrainStats, command: TurnAndRun, sigmas: float) -> MotionBounds:
    """The bounds of MotionBounds' documentation, written plainly (min, max and a clip function)."""
    turn, run = command.turn, command.run
    fraction_lo = _clipped(1.0 - stats.rotation_loss - sigmas * stats.rotation_sd, 0.0, 1.0)
    fraction_hi = _clipped(1.0 - stats.rotation_loss + sigmas * stats.rotation_sd, 0.0, 1.0)
    loss, spread = stats.translation_loss, sigmas * stats.translation_sd
    run_lo = _clipped(run * (1.0 - loss - spread) - stats.translation_inertial_loss, 0.0, run)
    run_hi = _clipped(run * (1.0 - loss + spread) - stats.translation_inertial_loss, 0.0, run)
    drift_max = stats.drift * run_hi
    if stats.drift == 0.0:
        chord_min = run_lo
    elif drift_max <= math.pi:
        chord_min = 2.0 * math.sin(stats.drift * run_lo / 2.0) / stats.drift
    else:
        chord_min = 0.0
    return MotionBounds(
        min(turn * fraction_lo, turn * fraction_hi),
        max(turn * fraction_lo, turn * fraction_hi),
        turn * _clipped(1.0 - stats.rotation_loss, 0.0, 1.0),
        run_lo,
        run_hi,
        _clipped(run * (1.0 - loss) - stats.translation_inertial_loss, 0.0, run),
        chord_min,
        abs(turn) * max(0.0, stats.skitter + sigmas * stats.skitter_sd),
        drift_max,
    )


fraction = st.floats(0.0, 0.99)
spread = st.floats(0.0, 2.0)


@given(
    st.tuples(fraction, st.floats(0.0, 0.5), spread, st.floats(0.0, 0.5), fraction, spread, spread, spread),
    st.floats(-7.0, 7.0),
    st.floats(0.0, 30.0),
    st.sampled_from([0.5, 1.0, 3.0, 5.0]),
)
def test_motion_bounds_are_exactly_the_documented_formulas(
    stats: tuple[float, ...], turn: float, run: float, sigmas: float
) -> None:
    """The clipping written out in motion_bounds gives the very same floats (any turn, zero runs)."""
    terrain, command = TerrainStats(*stats), TurnAndRun(turn, run)
    assert motion_bounds(terrain, command, sigmas) == _motion_bounds_as_documented(terrain, command, sigmas)


def _same_map(a: SpatialUncertaintyMap, b: SpatialUncertaintyMap) -> bool:
    return (
        a.polygon.vertices.tobytes() == b.polygon.vertices.tobytes()
        and a.center.tobytes() == b.center.tobytes()
        and (a.wedge.center, a.wedge.cw, a.wedge.ccw) == (b.wedge.center, b.wedge.cw, b.wedge.ccw)
    )


@given(
    st.tuples(fraction, st.floats(0.0, 0.5), spread, st.floats(0.0, 0.5), fraction, spread, spread, spread),
    st.lists(st.tuples(st.floats(-7.0, 7.0), st.floats(0.0, 30.0)), max_size=6),
    st.floats(-math.pi, math.pi),
    st.sampled_from([0.0, 0.05, 1.0, math.pi]),
    st.sampled_from([1.0, 3.0]),
    st.sampled_from([3, 8, 64]),
)
def test_a_run_of_growths_is_bit_for_bit_a_loop_of_grow(
    stats: tuple[float, ...],
    commands: list[tuple[float, float]],
    heading: float,
    halfwidth: float,
    sigmas: float,
    cap: int,
) -> None:
    """The manager's one-call growth equals growing report by report.

    Full-circle wedges, headings at the +-pi seam, zero-length commands and the vertex
    cap included: the polygon, the centre and the wedge are the very same floats.
    """
    terrain = TerrainStats(*stats)
    start = SpatialUncertaintyMap.from_pose(Pose(3.0, -2.0, heading), 0.3, halfwidth)
    runs = [TurnAndRun(turn, run) for turn, run in commands]
    expected = start
    for command in runs:
        expected = expected.grow(command, terrain, sigmas=sigmas, max_vertices=cap)
    grown = start._grow_many(runs, terrain, sigmas, cap)
    assert _same_map(grown, expected)
    assert not grown.polygon.vertices.flags.writeable


def test_no_commands_keep_the_very_map() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 3.0), 0.1, 0.05)
    assert start._grow_many([], TerrainTable.default()["grass"], 3.0) is start


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        (
            (TerrainTable.default()["tile"], TurnAndRun(0.1, 1.0), math.nan),
            "sigmas: expected a finite number, got nan",
        ),
        (
            (TerrainTable.default()["tile"], TurnAndRun(0.1, 1.0), math.inf),
            "sigmas: expected a finite number, got inf",
        ),
        ((TerrainTable.default()["tile"], TurnAndRun(0.1, 1.0), -math.inf), "sigmas: expected a finite"),
        (
            (TerrainTable.default()["tile"], TurnAndRun(0.1, 1.0), -1.0),
            r"sigmas: expected a number in \[0\.1, 100\]",
        ),
        (
            (TerrainTable.default()["tile"], TurnAndRun(0.1, 1.0), None),
            "sigmas: expected a finite number, got None",
        ),
        ((TerrainTable.default()["tile"], None, 3.0), "command: expected a TurnAndRun, got NoneType"),
        ((None, TurnAndRun(0.1, 1.0), 3.0), "stats: expected a TerrainStats, got NoneType"),
    ],
)
def test_motion_bounds_refuses_bad_arguments(arguments: tuple[object, object, object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        motion_bounds(*arguments)  # type: ignore[arg-type]
