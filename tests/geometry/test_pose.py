"""The pose: a geometric value that uncertainty and the top level re-export."""

from __future__ import annotations

import math

import numpy as np
import pytest

import aura_ums
from aura_ums import uncertainty
from aura_ums.errors import InputError
from aura_ums.geometry import Pose


def test_pose_wraps_heading_and_converts() -> None:
    pose = Pose(1, 2, -3 * math.pi / 2)
    assert pose.heading == pytest.approx(math.pi / 2)
    assert pose.as_array().tolist() == pytest.approx([1.0, 2.0, math.pi / 2])
    assert isinstance(pose.x, float)


def test_bad_pose_is_refused() -> None:
    with pytest.raises(InputError, match=r"Pose.y: expected a finite number, got nan"):
        Pose(0.0, float("nan"), 0.0)
    with pytest.raises(ValueError, match=r"Pose.heading"):
        Pose(0.0, 0.0, np.inf)


def test_uncertainty_and_the_top_level_export_the_same_pose() -> None:
    assert uncertainty.Pose is Pose
    assert aura_ums.Pose is Pose
