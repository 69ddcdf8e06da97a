"""Every constant and reason code the C kernels repeat has the value of its one Python definition."""

from __future__ import annotations

import pytest

from aura_ums._native import EmptyReason
from aura_ums._native import _growth as growth
from aura_ums._native import _reduce as reduce
from aura_ums.geometry import _convex as convex
from tests._native.native_helpers import built

#: Each constant the extension exports, with its Python twin.
TWINS: dict[str, float] = {
    "ARC_STEP": convex.ARC_STEP,
    "TINY_ANGLE": convex._TINY_ANGLE,
    "PARALLEL_EPS": convex._PARALLEL_EPS,
    "NOISE_EDGE": convex._NOISE_EDGE,
    "FARTHEST_MERGE": convex._FARTHEST_MERGE,
    "EXTENDABLE": convex._EXTENDABLE,
    "SUPPORT_MARGIN": convex._SUPPORT_MARGIN,
    "SAME_POINT": convex._SAME_POINT,
    "MERGE_EPS": convex._MERGE_EPS,
    "MERGE_ROUNDING": convex._MERGE_ROUNDING,
    "COLLINEAR_EPS": convex._COLLINEAR_EPS,
    "FULL_DISK_SIDES": convex.FULL_DISK_SIDES,
    "SKITTER_SIDES": growth.SKITTER_SIDES,
    "TOLERANCE": reduce.TOLERANCE,
    "TANGENT_STEP": reduce.TANGENT_STEP,
    "SENSOR_ARC_SIDES": reduce.SENSOR_ARC_SIDES,
}


@built
@pytest.mark.parametrize("name", sorted(TWINS))
def test_c_and_python_constants_agree(name: str) -> None:
    from aura_ums._native import _kernels

    value = getattr(_kernels, name)
    assert value == TWINS[name]
    assert type(value) is type(TWINS[name])


@built
@pytest.mark.parametrize("reason", list(EmptyReason), ids=lambda reason: reason.name)
def test_c_and_python_reason_codes_agree(reason: EmptyReason) -> None:
    from aura_ums._native import _kernels

    assert getattr(_kernels, reason.name) == reason.value


@built
def test_every_exported_constant_has_a_twin() -> None:
    from aura_ums._native import _kernels

    exported = {name for name in dir(_kernels) if name.isupper()}
    assert exported == set(TWINS) | {reason.name for reason in EmptyReason}
