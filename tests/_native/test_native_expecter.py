"""The Expecter kernel: compiled against its numpy reference, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums._native._expecter import ExpectedPoints, expecter_points_compiled, expecter_points_reference
from aura_ums.camera import CameraMount
from tests._native.native_helpers import built, random_polygon, random_wedge

#: Boxes far from the image axis (points near the cut plane, divided by a tiny depth) come
#: from different but equally sound roundings; within this many units they must agree.
NEAR_AXIS = 1e3


def random_case(rng: np.random.Generator) -> tuple[object, ...]:
    """Arguments of expecter_points: a map, a landmark of any class, a mount."""
    vertices = random_polygon(rng)
    if float(np.abs(vertices).max()) > 100.0:  # keep the landmark within sight of the map
        vertices = vertices - vertices.mean(axis=0)
    center, cw, ccw = random_wedge(rng)
    full = cw + ccw >= 2.0 * math.pi
    angle = rng.uniform(-math.pi, math.pi)
    place = vertices.mean(axis=0) + rng.uniform(0.0, 20.0) * np.array([math.cos(angle), math.sin(angle)])
    kind = int(rng.integers(0, 3))
    if kind == 2:  # a ground line
        other = place + rng.uniform(0.5, 10.0, 2) * rng.choice([-1.0, 1.0], 2)
        ends: tuple[tuple[float, float], ...] = (
            (float(place[0]), float(place[1])),
            (float(other[0]), float(other[1])),
        )
        heights: tuple[float, ...] = (0.0,)
    else:
        ends = ((float(place[0]), float(place[1])),)
        bottom = float(rng.uniform(0.0, 2.0))
        heights = (bottom,) if kind == 1 else (bottom, bottom + float(rng.uniform(0.0, 3.0)))
    mount = CameraMount(
        height=float(rng.uniform(0.3, 2.0)),
        forward=float(rng.uniform(-0.3, 0.5)),
        left=float(rng.uniform(-0.3, 0.3)),
        pan=float(rng.uniform(-0.5, 0.5)),
        tilt=float(rng.uniform(-0.2, 0.4)),
    )
    rotation = tuple(float(value) for value in mount.rotation().ravel())
    radius = 0.0 if rng.uniform() < 0.3 else float(rng.uniform(0.0, 0.5))
    return (
        vertices, ends, radius, 64, full, 0.0 if full else center - cw, 0.0 if full else min(cw + ccw, 6.0),
        math.pi / 64, rotation, mount.forward, mount.left, tuple(h - mount.height for h in heights), 5e-7,
    )  # fmt: skip


def boxes_agree(first: ExpectedPoints, second: ExpectedPoints) -> bool:
    for a, b in zip(first[1:], second[1:], strict=True):
        if abs(b) < NEAR_AXIS and abs(a - b) > 1e-9 * max(1.0, abs(b)):
            return False
    return True


@built
@given(st.integers(0, 2**32 - 1))
def test_compiled_points_agree_with_the_reference(seed: int) -> None:
    arguments = random_case(np.random.default_rng(seed))
    ours = expecter_points_compiled(*arguments)  # type: ignore[arg-type]
    reference = expecter_points_reference(*arguments)  # type: ignore[arg-type]
    assert (ours is None) == (reference is None)
    if ours is None or reference is None:
        return
    assert boxes_agree(ours, reference), (ours[1:], reference[1:])
    assert not ours.points.flags.writeable


@built
def test_both_outcomes_are_exercised() -> None:
    rng = np.random.default_rng(7)
    outcomes = [expecter_points_compiled(*random_case(rng)) is None for _ in range(300)]  # type: ignore[arg-type]
    assert 10 < sum(outcomes) < 290


@built
@pytest.mark.parametrize(
    ("change", "error", "match"),
    [
        ({"vertices": np.zeros((3, 3))}, ValueError, r"vertices: expected a C-contiguous \(n, 2\) float64"),
        ({"vertices": np.zeros((3, 2), dtype=np.float32)}, ValueError, "got format 'f'"),
        ({"vertices": "abc"}, TypeError, "vertices: expected"),
        (
            {"vertices": np.array([[0.0, math.inf]])},
            ValueError,
            "expected finite coordinates, got inf in row 0",
        ),
        ({"base_count": 3}, ValueError, r"base_count: expected an integer in \[1, 2\], got 3"),
        ({"level_count": 0}, ValueError, r"level_count: expected an integer in \[1, 2\], got 0"),
        ({"disk_sides": 1 << 21}, ValueError, r"disk_sides: expected an integer in \[3, 1048576\]"),
        ({"radius": math.nan}, ValueError, "radius: expected a finite number"),
        ({"radius": -1.0}, ValueError, "expected radius >= 0"),
        ({"arc_step": 0.0}, ValueError, r"2 pi / 2\^20 <= arc_step <= 2 pi / 3"),
        ({"arc_step": 1e-300}, ValueError, r"2 pi / 2\^20 <= arc_step"),
        ({"arc_step": 3.0}, ValueError, r"arc_step <= 2 pi / 3"),
        ({"heading_width": 7.0}, ValueError, r"0 <= heading_width < 2 pi \(unless full_circle\)"),
        ({"dz_lo": 3.0}, ValueError, "dz_lo <= dz_hi"),
        ({"forward": "x"}, TypeError, "forward: expected a real number, got str"),
    ],
)
def test_the_kernel_refuses_bad_arguments(
    change: dict[str, object], error: type[Exception], match: str
) -> None:
    from aura_ums._native._kernels import expecter_points

    arguments: dict[str, object] = {
        "vertices": np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        "base_count": 1,
        "disk_sides": 64,
        "full_circle": 0,
        "level_count": 2,
        "base_ax": 5.0,
        "base_ay": 0.0,
        "base_bx": 5.0,
        "base_by": 0.0,
        "radius": 0.1,
        "heading_lo": -0.1,
        "heading_width": 0.2,
        "arc_step": math.pi / 64,
    }
    names = [f"r{i}{j}" for i in range(3) for j in range(3)]
    rotation = dict(zip(names, CameraMount(height=1.0).rotation().ravel().tolist(), strict=True))
    arguments |= rotation | {"forward": 0.0, "left": 0.0, "dz_lo": -1.0, "dz_hi": 2.0, "cut_plane": 5e-7}
    assert expecter_points(*arguments.values()) is not None  # type: ignore[arg-type]  # the unchanged call works
    arguments |= change
    with pytest.raises(error, match=match):
        expecter_points(*arguments.values())  # type: ignore[arg-type]


@built
@given(
    st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=22, max_size=22),
    st.booleans(),
    st.integers(3, 200),
)
def test_extreme_numbers_never_crash(numbers: list[float], full: bool, sides: int) -> None:
    from aura_ums._native._kernels import expecter_points

    numbers[4] = abs(numbers[4])  # radius
    numbers[6] = abs(numbers[6]) % 6.0  # heading width
    numbers[7] = math.pi / 64  # arc step
    numbers[19], numbers[20] = sorted(numbers[19:21])  # dz
    square = np.array([[0.0, 0.0], [1e300, 0.0], [1e300, 1e300], [0.0, 1e300]])
    found = expecter_points(square, 2, sides, int(full), 2, *numbers)
    assert found is None or len(found[0]) % 16 == 0
