"""The kernels' scratch buffers (polygon.c's Work): kept by the module between calls, never shared by two.

Each call borrows the module's buffers; a kernel called while another call holds them (here
from a garbage-collector callback that an allocation inside the outer call set off) gets
buffers of its own. Either way every result is the one a call with fresh buffers gives.
"""

from __future__ import annotations

import gc
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import partial
from typing import Any

import numpy as np
import pytest

from aura_ums import _native
from aura_ums._native import _reduce as native_reduce
from aura_ums._native import _slices as native_slices
from tests._native.native_helpers import Array, kernels, random_polygon, random_wedge

pytestmark = pytest.mark.skipif(not _native.BUILT, reason="the compiled kernels are not built")


def _cone_call(rng: np.random.Generator) -> tuple[Any, ...]:
    """Arguments of reduce_cone: a random polygon seen from a landmark 3-8 m away."""
    polygon = random_polygon(rng)
    center_x, center_y = (float(c) for c in polygon.mean(axis=0))
    wedge = random_wedge(rng)
    angle = float(rng.uniform(-np.pi, np.pi))
    distance = float(rng.uniform(3.0, 8.0))
    landmark = (center_x + distance * np.cos(angle), center_y + distance * np.sin(angle))
    bearing = float(angle - wedge[0] + rng.normal(0.0, 0.05))
    return (
        polygon, center_x, center_y, *wedge, 0.1, 0.0, *landmark, 0.05,
        bearing, 0.1, 0.5 * distance, 2.0 * distance, native_reduce.CONE_PIECE, 16,
    )  # fmt: skip


def _groups(rng: np.random.Generator, count: int) -> tuple[Array, list[int]]:
    """Arguments of merge_groups: ``count`` groups of 5-40 random points each."""
    sizes = [int(size) for size in rng.integers(5, 41, count)]
    return np.ascontiguousarray(rng.normal(0.0, 3.0, (sum(sizes), 2))), sizes


class _Nesting:
    """Calls ``inner`` from every garbage collection that starts while :meth:`outer` runs.

    With its threshold at 1 the collector runs at every other allocation of a tracked object,
    such as the tuple a kernel builds for its result while it holds the buffers.
    """

    def __init__(self, inner: Callable[[], Any]) -> None:
        self.inner = inner
        self.nested: list[Any] = []
        self._inside = False

    def outer(self, kernel: Callable[[], Any]) -> Any:
        # With a threshold of 1 the collector runs when its count of new objects reaches 2:
        # leave it at 1, so that the kernel's first fresh object sets it off.
        padding: list[list[None]] = []
        while gc.get_count()[0] != 1:
            padding.append([])
        self._inside = True
        try:
            return kernel()
        finally:
            self._inside = False

    def callback(self, phase: str, info: dict[str, int]) -> None:
        if phase == "start" and self._inside:
            self._inside = False  # one nested call at a time: it allocates too
            try:
                self.nested.append(self.inner())
            finally:
                self._inside = True


@contextmanager
def _collecting_often(nesting: _Nesting) -> Iterator[None]:
    threshold = gc.get_threshold()
    gc.callbacks.append(nesting.callback)
    gc.set_threshold(1, 1, 1)
    try:
        yield
    finally:
        gc.set_threshold(*threshold)
        gc.callbacks.remove(nesting.callback)


def _fresh_tuples(size: int) -> list[tuple[int, ...]]:
    """Take every spare tuple of ``size`` items CPython keeps (at most 2,000 per size): the next
    one made is a fresh allocation, which is when the garbage collector may run."""
    return [tuple(range(start, start + size)) for start in range(2_500)]


def test_a_kernel_called_while_another_holds_the_buffers_gets_its_own() -> None:
    rng = np.random.default_rng(20261128)
    calls = [_cone_call(rng) for _ in range(20)]
    groups = _groups(rng, 30)
    compiled = native_reduce.reduce_cone_compiled
    expected = [compiled(*call) for call in calls]
    inner_expected = kernels().merge_groups(*groups, 16)
    # The nested call's hulls overwrite what the outer one is about to copy out (the kept
    # positions: reduce_cone makes its result tuple first), had it the same buffers.
    nesting = _Nesting(partial(kernels().merge_groups, *groups, 16))
    held = []
    with _collecting_often(nesting):
        outer = []
        for call in calls:
            held.append(_fresh_tuples(7))  # reduce_cone's result: 7 items
            outer.append(nesting.outer(partial(compiled, *call)))
    assert outer == expected
    assert nesting.nested, "no kernel ran while another held the buffers: the test proves nothing"
    assert all(found == inner_expected for found in nesting.nested)


def test_a_call_larger_than_the_kept_buffers_then_small_ones() -> None:
    rng = np.random.default_rng(7)
    # 200,000 points (3.2 MB of vertices alone): more than the module keeps between calls.
    angles = rng.uniform(0.0, 2.0 * np.pi, 200_000)
    radii = rng.uniform(0.5, 1.0, (200_000, 1))
    huge: Array = np.ascontiguousarray(np.column_stack([np.cos(angles), np.sin(angles)]) * radii)
    small = [np.ascontiguousarray(random_polygon(rng)) for _ in range(20)]
    for points in (small[0], huge, *small):
        counts = [len(points)]
        compiled = native_slices.merge_groups_compiled(points, counts, 24)
        reference = native_slices.merge_groups_reference(points, counts, 24)
        assert len(compiled) == 1
        np.testing.assert_allclose(compiled[0], reference[0], rtol=1e-12, atol=1e-12)
