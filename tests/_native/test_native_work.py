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
from tests._native.native_helpers import Array, random_polygon, random_wedge

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


def _reduced(call: tuple[Any, ...]) -> Any:
    """reduce_cone's result for ``call``, comparable with ==."""
    return _as_values(native_reduce.reduce_cone_compiled(*call))


def _as_values(found: Any) -> Any:
    """A kernel's result with its bytes as bytes and its numbers as they are (comparable with ==)."""
    return found if isinstance(found, int) else tuple(found)


class _Nesting:
    """Calls ``inner`` from every garbage collection that starts while :meth:`outer` runs.

    The collector runs at (almost) every allocation of a tracked object once its threshold
    is 1, such as the tuple a kernel builds for its result while it holds the buffers.
    """

    def __init__(self, inner: Callable[[], Any]) -> None:
        self.inner = inner
        self.nested: list[Any] = []
        self._inside = False

    def outer(self, kernel: Callable[[], Any]) -> Any:
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


def test_a_kernel_called_while_another_holds_the_buffers_gets_its_own() -> None:
    rng = np.random.default_rng(20261128)
    calls = [_cone_call(rng) for _ in range(40)]
    compiled = native_reduce.reduce_cone_compiled
    expected = [_as_values(compiled(*call)) for call in calls]
    nesting = _Nesting(partial(_reduced, calls[-1]))
    with _collecting_often(nesting):
        outer = [nesting.outer(partial(_reduced, call)) for call in calls]
    assert outer == expected
    assert nesting.nested, "no kernel ran while another held the buffers: the test proves nothing"
    assert all(found == expected[-1] for found in nesting.nested)


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
