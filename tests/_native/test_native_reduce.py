"""The reduction kernels: compiled against their numpy reference, the vertex cap, and bad input."""

from __future__ import annotations

import math
import tracemalloc
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums import _native
from aura_ums._native import CONE_PIECE, SECTOR_PIECE, EmptyReason, RawReduction
from aura_ums._native import _reduce as native_reduce
from aura_ums._native._reduce import (
    reduce_cone_reference,
    reduce_strip_reference,
)
from aura_ums.geometry import convex_hull, polygon_area
from aura_ums.geometry._convex import convexity_defect
from tests._native.native_helpers import (
    Array,
    built,
    contains,
    kernels,
    random_polygon,
    random_wedge,
    scale_of,
)

Result = RawReduction | int


class Reduction(NamedTuple):
    """A kernel's reduction, its vertices as an array."""

    vertices: Array
    arc_lo: float
    arc_width: float
    center_x: float
    center_y: float
    area_before: float
    area_after: float


def read(found: Result) -> Reduction | EmptyReason:
    """The kernel's result with named parts: the reduction, or the reason it is empty."""
    if isinstance(found, int):
        return EmptyReason(found)
    raw, *numbers = found
    return Reduction(np.frombuffer(raw, dtype=np.float64).reshape(-1, 2), *numbers)


Reduce = Callable[..., Result]

CONES: list[Reduce] = [reduce_cone_reference] + (
    [native_reduce.reduce_cone_compiled] if _native.BUILT else []
)
STRIPS: list[Reduce] = [reduce_strip_reference] + (
    [native_reduce.reduce_strip_compiled] if _native.BUILT else []
)


class Cone(NamedTuple):
    """The arguments of reduce_cone between the vertices and the cap."""

    center_x: float
    center_y: float
    wedge_center: float
    wedge_cw: float
    wedge_ccw: float
    forward: float
    left: float
    landmark_x: float
    landmark_y: float
    widen: float
    bearing: float
    bearing_error: float
    range_min: float
    range_max: float
    piece: float


class Strip(NamedTuple):
    """The arguments of reduce_strip between the vertices and the cap."""

    center_x: float
    center_y: float
    wedge_center: float
    wedge_cw: float
    wedge_ccw: float
    forward: float
    left: float
    start_x: float
    start_y: float
    end_x: float
    end_y: float
    position_uncertainty: float
    offset: float
    offset_error: float
    angle: float
    angle_error: float


def cone_arguments(rng: np.random.Generator, vertices: Array) -> Cone:
    """Everything of reduce_cone after the vertices and before the cap: often consistent, not always."""
    center = vertices.mean(axis=0)
    wedge = random_wedge(rng)
    forward, left = (0.0, 0.0) if rng.uniform() < 0.4 else rng.uniform(-0.6, 0.6, 2).tolist()
    angle, reach = float(rng.uniform(-math.pi, math.pi)), float(rng.uniform(0.5, 30.0))
    landmark = center + reach * np.array([math.cos(angle), math.sin(angle)])
    if rng.uniform() < 0.2:  # inside the polygon's box
        landmark = center + rng.uniform(-0.5, 0.5, 2) * np.ptp(vertices, axis=0)
    widen = 0.0 if rng.uniform() < 0.4 else float(rng.uniform(0.0, 0.5))
    # The bearing from the centre at the wedge's heading, give or take.
    bearing = (
        angle - wedge[0] + float(rng.choice([0.0, rng.normal(0.0, 0.3), rng.uniform(-math.pi, math.pi)]))
    )
    error = float(rng.choice([0.0, rng.uniform(0.0, 0.3), rng.uniform(0.0, 4.0)]))
    if rng.uniform() < 0.5:
        r_min, r_max, piece = 0.0, math.inf, CONE_PIECE
    else:
        spread = float(rng.uniform(0.0, 3.0))
        r_min, r_max, piece = max(0.0, reach - spread), reach + spread, SECTOR_PIECE
    (x, y), (landmark_x, landmark_y) = center.tolist(), landmark.tolist()
    return Cone(
        x, y, *wedge, forward, left, landmark_x, landmark_y, widen, bearing, error, r_min, r_max, piece
    )


def strip_arguments(rng: np.random.Generator, vertices: Array) -> Strip:
    center = vertices.mean(axis=0)
    wedge = random_wedge(rng)
    forward, left = (0.0, 0.0) if rng.uniform() < 0.4 else rng.uniform(-0.6, 0.6, 2).tolist()
    direction = rng.uniform(-math.pi, math.pi)
    start = center + rng.uniform(-5.0, 5.0, 2)
    end = start + rng.uniform(0.5, 20.0) * np.array([math.cos(direction), math.sin(direction)])
    normal = np.array([-math.sin(direction), math.cos(direction)])
    distance = float((center - start) @ normal) + float(rng.normal(0.0, 0.5))
    (x, y), (start_x, start_y), (end_x, end_y) = center.tolist(), start.tolist(), end.tolist()
    return Strip(
        x, y, *wedge, forward, left, start_x, start_y, end_x, end_y, float(rng.choice([0.0, 0.2])), distance,
        float(rng.uniform(0.0, 1.0)), direction - wedge[0] + float(rng.normal(0.0, 0.2)),
        float(rng.uniform(0.0, 0.3)),
    )  # fmt: skip


def check_agreement(first: Result, second: Result, third: Result, prior: Array, cap: int) -> None:
    """The same verdict (and reason); the same headings; the same polygon unless the cap was at work."""
    ours, reference, uncapped = read(first), read(second), read(third)
    assert isinstance(ours, EmptyReason) == isinstance(reference, EmptyReason), (ours, reference)
    if isinstance(ours, EmptyReason) or isinstance(reference, EmptyReason):
        assert ours == reference
        return
    assert isinstance(uncapped, Reduction)
    assert (ours.arc_lo, ours.arc_width) == pytest.approx((reference.arc_lo, reference.arc_width), abs=1e-9)
    scale = scale_of(prior)
    assert ours.area_before == pytest.approx(reference.area_before, rel=1e-12, abs=1e-12 * scale**2)
    assert not ours.vertices.flags.writeable
    assert convexity_defect(ours.vertices) is None
    if len(uncapped.vertices) <= cap:
        assert ours.area_after == pytest.approx(reference.area_after, rel=1e-9, abs=1e-12 * scale**2)
        assert (ours.center_x, ours.center_y) == pytest.approx(
            (reference.center_x, reference.center_y), abs=1e-9 * scale
        )
    for result in (ours, reference):
        assert contains(result.vertices, uncapped.vertices, 1e-9 * scale)


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 5, 16, 64]))
def test_compiled_reductions_agree_with_the_reference(seed: int, cap: int) -> None:
    rng = np.random.default_rng(seed)
    prior = random_polygon(rng)
    cone = cone_arguments(rng, prior)
    check_agreement(
        native_reduce.reduce_cone_compiled(prior, *cone, cap),
        reduce_cone_reference(prior, *cone, cap),
        reduce_cone_reference(prior, *cone, 1_000_000),
        prior,
        cap,
    )
    strip = strip_arguments(rng, prior)
    check_agreement(
        native_reduce.reduce_strip_compiled(prior, *strip, cap),
        reduce_strip_reference(prior, *strip, cap),
        reduce_strip_reference(prior, *strip, 1_000_000),
        prior,
        cap,
    )


def ring_inside(rng: np.random.Generator) -> tuple[Array, Cone]:
    """A triangle to pentagon cut by an annulus round a landmark inside it, seen from an offset
    sensor: many vertices, and often no merge whose corner stays inside the prior."""
    prior = convex_hull(rng.uniform(-10.0, 10.0, (int(rng.integers(3, 6)), 2)))
    while len(prior) < 3:
        prior = convex_hull(rng.uniform(-10.0, 10.0, (5, 2)))
    center = prior.mean(axis=0)
    landmark = center + rng.uniform(-3.0, 3.0, 2)
    reach = float(np.hypot(*(landmark - center)))
    heading = float(rng.uniform(-3.0, 3.0))
    cw, ccw = rng.uniform(0.0, 1.5, 2).tolist()
    bearing = math.atan2(float(landmark[1] - center[1]), float(landmark[0] - center[0])) - heading
    (x, y), (forward, left), (landmark_x, landmark_y) = (
        center.tolist(),
        rng.uniform(-1.0, 1.0, 2).tolist(),
        landmark.tolist(),
    )
    error = float(rng.uniform(0.0, 1.0))
    r_min, r_max = max(0.0, reach - 1.0), reach + 1.0
    return prior, Cone(
        x, y, heading, cw, ccw, forward, left, landmark_x, landmark_y, 0.1, bearing, error, r_min, r_max,
        SECTOR_PIECE,
    )  # fmt: skip


@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 4, 6, 12]))
def test_the_cap_holds_inside_the_prior(seed: int, cap: int) -> None:
    """Many-vertex and small priors cut by cones, annuli (with sensor offsets) and strips."""
    rng = np.random.default_rng(seed)
    prior = random_polygon(rng, many=rng.uniform() < 0.5)
    small, ring = ring_inside(rng)
    cases: list[tuple[Array, list[Reduce], Cone | Strip]] = [
        (prior, CONES, cone_arguments(rng, prior)),
        (prior, STRIPS, strip_arguments(rng, prior)),
        (small, CONES, ring),
    ]
    for base, implementations, arguments in cases:
        scale = scale_of(base)
        uncapped = read(implementations[0](base, *arguments, 1_000_000))
        for reduce in implementations:
            found = read(reduce(base, *arguments, cap))
            if isinstance(found, EmptyReason):
                assert found == uncapped
                continue
            assert isinstance(uncapped, Reduction)
            assert len(found.vertices) <= max(cap, len(base)), (reduce.__name__, len(found.vertices))
            assert contains(base, found.vertices, 1e-9 * scale)  # inside the prior
            assert contains(found.vertices, uncapped.vertices, 1e-9 * scale)  # sound


def test_a_cut_that_cannot_be_undone_falls_back_to_the_prior() -> None:
    """A triangle cut by an annulus seen from an offset sensor: more vertices than the triangle,
    and no removal whose corner stays inside it, so a cap of 3 takes the triangle itself."""
    triangle = np.array([[0.0, 0.0], [10.0, 0.0], [5.0, 8.0]])
    arguments = Cone(5.0, 3.0, 0.0, 0.4, 0.4, 0.5, 0.3, 5.0, 3.0, 0.0, 0.0, 0.1, 1.0, 3.0, SECTOR_PIECE)
    for reduce in CONES:
        uncapped, capped = (
            read(reduce(triangle, *arguments, 1_000_000)),
            read(reduce(triangle, *arguments, 3)),
        )
        assert isinstance(uncapped, Reduction)
        assert isinstance(capped, Reduction)
        assert len(uncapped.vertices) > 3
        assert capped.vertices.tolist() == triangle.tolist()
        assert capped.area_after == polygon_area(triangle)


# --- the kernels' own input -------------------------------------------------------------

_SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_CONE_ARGS = (0.5, 0.5, 0.0, 0.01, 0.01, 0.0, 0.0, 20.0, 0.0, 0.0, 0.0, 0.001, 0.0, math.inf, 2.0)
_STRIP_ARGS = (0.5, 0.5, 0.0, 0.1, 0.1, 0.0, 0.0, 0.0, -1.0, 1.0, -1.0, 0.0, 1.5, 0.5, 0.0, 0.1)


@built
def test_kernels_return_the_reduction_or_a_reason() -> None:
    reduce_cone, reduce_strip = kernels().reduce_cone, kernels().reduce_strip
    found = reduce_cone(_SQUARE, *_CONE_ARGS, 16)
    assert isinstance(found, tuple)
    raw, _, width, x, y, area_before, area_after = found
    assert np.frombuffer(raw).reshape(-1, 2).shape[1] == 2
    # The cone keeps |y| <~ 0.22: the centre moves down to its (slightly sloping) edge.
    assert width <= 0.02
    assert (x, y) == pytest.approx((0.5, 0.22), abs=0.01)
    assert area_before == 1.0
    assert area_after == pytest.approx(y, rel=0.01)
    behind = list(_CONE_ARGS)
    behind[10] = math.pi  # the bearing
    assert reduce_cone(_SQUARE, *behind, 16) == EmptyReason.NO_POSITION
    assert isinstance(reduce_strip(_SQUARE, *_STRIP_ARGS, 16), tuple)
    away = list(_STRIP_ARGS)
    away[12] = 9.0  # the offset
    assert reduce_strip(_SQUARE, *away, 16) == EmptyReason.NO_OFFSET_POSITION


@built
@pytest.mark.parametrize(
    ("vertices", "error", "message"),
    [
        (b"abcdefghabcdefgh", ValueError, r"expected a C-contiguous \(n, 2\) float64 buffer, got format 'B'"),
        (np.zeros((3, 2), dtype=np.float32), ValueError, "got format 'f' with 4-byte items"),
        (np.zeros((3, 3)), ValueError, "got 2 dimensions with 3 in the last"),
        (np.zeros((0, 2)), ValueError, "got 0 bytes"),
        (np.zeros(3), ValueError, "got 24 bytes"),
        (np.zeros((4, 4))[:, :2], ValueError, "got a non-contiguous numpy.ndarray"),
        ([[0.0, 0.0]], TypeError, "got list"),
        (
            np.array([[0.0, 0.0], [1.0, math.nan]]),
            ValueError,
            "expected finite coordinates, got nan in row 1",
        ),
    ],
)
def test_kernels_refuse_a_malformed_buffer(vertices: object, error: type[Exception], message: str) -> None:
    reduce_cone, reduce_strip = kernels().reduce_cone, kernels().reduce_strip
    with pytest.raises(error, match=message):
        reduce_cone(vertices, *_CONE_ARGS, 16)
    with pytest.raises(error, match=message):
        reduce_strip(vertices, *_STRIP_ARGS, 16)


@built
def test_kernels_refuse_bad_numbers() -> None:
    reduce_cone, reduce_strip = kernels().reduce_cone, kernels().reduce_strip
    with pytest.raises(TypeError, match="reduce_cone: expected 17 arguments, got 16"):
        reduce_cone(_SQUARE, *_CONE_ARGS)
    with pytest.raises(TypeError, match="reduce_strip: expected 18 arguments, got 2"):
        reduce_strip(_SQUARE, 16)
    with pytest.raises(TypeError, match="bearing: expected a real number, got str"):
        reduce_cone(_SQUARE, *_CONE_ARGS[:10], "north", *_CONE_ARGS[11:], 16)
    bad = list(_CONE_ARGS)
    bad[10] = math.nan
    with pytest.raises(ValueError, match="bearing: expected a finite number, got nan"):
        reduce_cone(_SQUARE, *bad, 16)
    bad[10], bad[13] = 0.0, -math.inf
    with pytest.raises(ValueError, match="range_max: expected a finite number or inf, got -inf"):
        reduce_cone(_SQUARE, *bad, 16)
    bad = list(_STRIP_ARGS)
    bad[12] = -math.inf
    with pytest.raises(ValueError, match="offset: expected a finite number, got -inf"):
        reduce_strip(_SQUARE, *bad, 16)
    for piece in (0.0, 1e-9):
        bad = list(_CONE_ARGS)
        bad[14] = piece
        with pytest.raises(ValueError, match=r"piece: expected a positive angle of at least 2 pi / 1e6, got"):
            reduce_cone(_SQUARE, *bad, 16)
    with pytest.raises(ValueError, match="max_vertices: expected at least 3, got 2"):
        reduce_cone(_SQUARE, *_CONE_ARGS, 2)
    with pytest.raises(TypeError):
        reduce_strip(_SQUARE, *_STRIP_ARGS, 16.5)


@built
def test_kernels_release_the_buffer_and_free_their_memory() -> None:
    reduce_cone, reduce_strip = kernels().reduce_cone, kernels().reduce_strip
    view = memoryview(bytearray(_SQUARE.tobytes())).cast("d")
    assert isinstance(reduce_cone(view, *_CONE_ARGS, 16), tuple)
    assert isinstance(reduce_strip(view, *_STRIP_ARGS, 3), tuple)
    view.release()  # raises BufferError if a kernel kept its export
    raw = bytearray(b"x" * 16)
    with pytest.raises(ValueError, match="format 'B'"):
        reduce_cone(raw, *_CONE_ARGS, 16)
    raw.extend(b"y")  # a bytearray with exports cannot be resized
    rng = np.random.default_rng(3)
    prior = random_polygon(rng, many=True)
    cases = [cone_arguments(rng, prior) for _ in range(4)]

    def run() -> None:
        for arguments in cases:
            native_reduce.reduce_cone_compiled(prior, *arguments, 6)
        native_reduce.reduce_strip_compiled(prior, *strip_arguments(rng, prior), 6)
        with pytest.raises(ValueError, match="expected a finite"):
            reduce_cone(_SQUARE, *_CONE_ARGS[:-1], math.nan, 16)

    run()
    tracemalloc.start()
    try:
        run()
        before = tracemalloc.get_traced_memory()[0]
        for _ in range(300):
            run()
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert grown < 50_000  # 1,800 calls: a leak of even one small buffer per call would show


@built
@given(
    st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=16, max_size=16),
    st.floats(2 * math.pi / 1e6, 7.0),
    st.integers(3, 40),
)
def test_extreme_numbers_never_crash(numbers: list[float], piece: float, cap: int) -> None:
    reduce_cone, reduce_strip = kernels().reduce_cone, kernels().reduce_strip
    square = np.array([[0.0, 0.0], [1e300, 0.0], [1e300, 1e300], [0.0, 1e300]])
    for found in (reduce_cone(square, *numbers[:14], piece, cap), reduce_strip(square, *numbers, cap)):
        if isinstance(found, tuple):
            assert len(found[0]) // 16 <= max(cap, 4)
        else:
            assert found in set(EmptyReason)
