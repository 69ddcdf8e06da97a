"""The growth kernel: compiled against its numpy reference, the vertex cap, and bad input."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums import _native
from aura_ums._native._growth import (
    Grown,
    MotionModel,
    grow_commands_compiled,
    grow_commands_reference,
    grow_polygon,
    motion_bounds,
)
from aura_ums.geometry import polygon_area
from aura_ums.geometry._convex import convexity_defect
from aura_ums.uncertainty import TerrainStats
from tests._native.native_helpers import (
    Array,
    built,
    contains,
    kernels,
    random_commands,
    random_polygon,
    random_terrain,
    random_wedge,
    scale_of,
)

#: The implementations to hold to the cap: the reference always, the kernel when built.
IMPLEMENTATIONS: list[Callable[..., Grown]] = [grow_commands_reference] + (
    [grow_commands_compiled] if _native.BUILT else []
)

UNCAPPED = 1_000_000

#: A terrain on which commands move exactly as told.
STILL = TerrainStats(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def grow(
    implementation: Callable[..., Grown],
    vertices: Array,
    wedge: tuple[float, float, float],
    terrain: MotionModel,
    commands: list[float],
    cap: int,
    sigmas: float = 3.0,
) -> Grown:
    return implementation(vertices, 1.0, -2.0, *wedge, terrain, sigmas, commands, cap)


def moves(terrain: TerrainStats, commands: list[float], sigmas: float) -> bool:
    """Whether some command grows the polygon (else growth keeps the very input)."""
    for index in range(0, len(commands), 2):
        bounds = motion_bounds(terrain, commands[index], commands[index + 1], sigmas)
        if bounds.run_max > 0.0 or bounds.skitter_radius > 0.0:
            return True
    return False


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 4, 8, 16, 64]), st.integers(1, 6))
def test_compiled_growth_agrees_with_the_reference(seed: int, cap: int, count: int) -> None:
    rng = np.random.default_rng(seed)
    vertices, wedge, terrain = random_polygon(rng), random_wedge(rng), random_terrain(rng)
    commands, sigmas = random_commands(rng, count), float(rng.choice([1.0, 3.0]))
    ours = grow(grow_commands_compiled, vertices, wedge, terrain, commands, cap, sigmas)
    reference = grow(grow_commands_reference, vertices, wedge, terrain, commands, cap, sigmas)
    exact = grow(grow_commands_reference, vertices, wedge, terrain, commands, UNCAPPED, sigmas)
    # The wedge and the centre: the same scalar operations, the very same floats.
    assert ours[1:] == reference[1:]
    assert not ours.vertices.flags.writeable
    assert convexity_defect(ours.vertices) is None
    scale = scale_of(vertices, exact.vertices)
    if len(exact.vertices) <= cap:
        # No cap at work (a Minkowski sum never loses directions): the same polygon up to rounding.
        assert polygon_area(ours.vertices) == pytest.approx(
            polygon_area(reference.vertices), rel=1e-9, abs=1e-9 * scale**2
        )
    for polygon in (ours.vertices, reference.vertices):
        assert contains(polygon, exact.vertices, 1e-9 * scale)


@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 4, 5, 8, 16]), st.integers(1, 8))
def test_the_cap_always_holds_and_stays_sound(seed: int, cap: int, count: int) -> None:
    """Starting above the cap, with polygons too fine or too thin to merge edges: single and batch."""
    rng = np.random.default_rng(seed)
    vertices = random_polygon(rng, many=True)
    wedge, terrain, sigmas = random_wedge(rng), random_terrain(rng), 3.0
    commands = random_commands(rng, count)
    exact = grow(grow_commands_reference, vertices, wedge, terrain, commands, UNCAPPED)
    scale = scale_of(vertices, exact.vertices)
    for implementation in IMPLEMENTATIONS:
        for run in (commands[:2], commands):  # one growth, and a batch
            grown = grow(implementation, vertices, wedge, terrain, run, cap, sigmas)
            limit = cap if moves(terrain, run, sigmas) else len(vertices)
            assert len(grown.vertices) <= limit, (implementation.__name__, len(grown.vertices), limit)
            assert convexity_defect(grown.vertices) is None
            if run is commands:
                assert contains(grown.vertices, exact.vertices, 1e-9 * scale)


@pytest.mark.parametrize("implementation", IMPLEMENTATIONS, ids=lambda f: f.__name__)
def test_a_long_run_that_merges_nothing_keeps_the_cap(implementation: Callable[..., Grown]) -> None:
    """The crash of issue 17: translation spread only, tiny steps, a fine polygon far out.

    Nothing can be merged (every edge is below 1e-6 of the coordinates), so only the support
    polygon keeps the cap; the compiled kernel wrote past its buffers here before.
    """
    terrain = TerrainStats(0.0, 0.0, 0.05, 0.0, 0.0, 0.0, 0.0, 0.0)  # translation_sd only
    rng = np.random.default_rng(17)
    start = np.array([[5e3, -2e3]])
    commands: list[float] = []
    for _ in range(3000):
        commands += (float(rng.normal(0.0, 0.02)), float(rng.uniform(0.0, 0.01)))
    for cap in (3, 8, 64):
        grown = grow(implementation, start, (0.3, 0.0, 0.0), terrain, commands, cap)
        assert 1 <= len(grown.vertices) <= cap
        assert convexity_defect(grown.vertices) is None
        # Sound: it holds every position the uncapped growth of the first 200 steps reaches.
        early = grow(grow_commands_reference, start, (0.3, 0.0, 0.0), terrain, commands[:400], UNCAPPED)
        assert len(early.vertices) > cap or cap == 64
        assert contains(
            grow(implementation, start, (0.3, 0.0, 0.0), terrain, commands[:400], cap).vertices,
            early.vertices,
            1e-6,
        )


def test_no_motion_keeps_the_polygon_and_the_cap_applies_only_to_growth() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    still = motion_bounds(STILL, 0.0, 0.0, 3.0)
    assert grow_polygon(square, 0.0, 0.0, still, 3) is square
    for implementation in IMPLEMENTATIONS:
        grown = grow(implementation, square, (0.0, 0.0, 0.0), STILL, [0.0, 0.0], 3)
        assert grown.vertices.tolist() == square.tolist()


@built
def test_the_kernel_refuses_bad_input() -> None:
    grow_commands = kernels().grow_commands
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    stats = (0.5, 0.5, 0.0, 0.1, 0.1, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 3.0)
    with pytest.raises(ValueError, match=r"commands: expected \(turn, run\) pairs, got 3 numbers"):
        grow_commands(square, *stats, [0.0, 1.0, 2.0], 16)
    with pytest.raises(ValueError, match=r"commands: expected finite numbers, got 0.0, nan at pair 1"):
        grow_commands(square, *stats, [0.0, 1.0, 0.0, math.nan], 16)
    with pytest.raises(TypeError, match="commands: expected a sequence of numbers, got int"):
        grow_commands(square, *stats, 5, 16)
    with pytest.raises(TypeError, match="must be real number, not str"):
        grow_commands(square, *stats, ["left", 1.0], 16)
    with pytest.raises(ValueError, match="max_vertices: expected at least 3, got 2"):
        grow_commands(square, *stats, [], 2)
    with pytest.raises(ValueError, match=r"vertices: expected finite coordinates, got inf in row 1"):
        grow_commands(np.array([[0.0, 0.0], [math.inf, 0.0]]), *stats, [0.0, 1.0], 16)
    with pytest.raises(ValueError, match=r"vertices: expected a C-contiguous \(n, 2\) float64 buffer"):
        grow_commands(b"abc", *stats, [], 16)
    with pytest.raises(TypeError, match="grow_commands: expected 17 arguments, got 2"):
        grow_commands(square, 1.0)
    with pytest.raises(ValueError, match=r"commands: expected \(turn, run\) pairs, got 1 numbers"):
        grow_commands_reference(square, 0.0, 0.0, 0.0, 0.0, 0.0, STILL, 3.0, [1.0], 16)


class _Shrinking:
    """A number whose conversion empties the list of commands it sits in."""

    def __init__(self, owner: list[object]) -> None:
        self.owner = owner

    def __float__(self) -> float:
        self.owner.clear()
        return 0.5


@built
def test_commands_that_change_while_read_cannot_crash() -> None:
    grow_commands = kernels().grow_commands
    commands: list[object] = []
    commands += [_Shrinking(commands), 1.0, 0.2, 1.0]
    stats = (0.0, 0.0, 0.0, 0.1, 0.1, 0.0, 0.1, 0.0, 0.05, 0.0, 0.1, 0.0, 0.0, 3.0)
    raw, *_ = grow_commands(np.array([[0.0, 0.0]]), *stats, commands, 16)
    assert len(raw) % 16 == 0
    assert not commands


@built
@given(
    st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=14, max_size=14),
    st.lists(st.floats(allow_nan=False, allow_infinity=False), max_size=8).filter(lambda v: len(v) % 2 == 0),
    st.integers(3, 40),
)
def test_extreme_numbers_never_crash(numbers: list[float], commands: list[float], cap: int) -> None:
    grow_commands = kernels().grow_commands
    square = np.array([[0.0, 0.0], [1e300, 0.0], [1e300, 1e300], [0.0, 1e300]])
    raw, *_ = grow_commands(square, *numbers, commands, cap)
    count = len(raw) // 16
    assert count <= max(cap, 4)
