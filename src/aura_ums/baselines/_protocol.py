"""The interface every baseline estimator offers, so replay and comparison code can drive any of them."""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from aura_ums.baselines._region import ConfidenceRegion
from aura_ums.uncertainty import BearingObservation, Pose, RangeBearingObservation, TerrainStats, TurnAndRun


@runtime_checkable
class Estimator(Protocol):
    """A pose estimator fed what :class:`~aura_ums.uncertainty.SpatialUncertaintyMap` is fed.

    :class:`ExtendedKalmanFilter` and :class:`ParticleFilter` implement it.

    Examples
    --------
    >>> import numpy as np
    >>> from aura_ums.baselines import ExtendedKalmanFilter, ParticleFilter
    >>> sds = dict(position_sd=0.1, heading_sd=0.01, bearing_sd=0.01, range_sd=0.2)
    >>> isinstance(ExtendedKalmanFilter(Pose(0, 0, 0), **sds), Estimator)
    True
    >>> isinstance(ParticleFilter(Pose(0, 0, 0), np.random.default_rng(0), **sds), Estimator)
    True
    >>> isinstance(Pose(0, 0, 0), Estimator)
    False
    """

    def predict(self, command: TurnAndRun, terrain: TerrainStats) -> None:
        """Move the belief by a turn-and-run command on a terrain."""
        ...

    def update(
        self, observation: BearingObservation | RangeBearingObservation, landmark_xy: tuple[float, float]
    ) -> bool:
        """Correct the belief with an observation of the landmark at ``landmark_xy`` (m); False: rejected."""
        ...

    def region(self, probability: float = 0.99) -> ConfidenceRegion:
        """Return the confidence region of joint ``probability``."""
        ...

    @property
    def mean(self) -> Pose:
        """The point estimate."""
        ...

    @property
    def rejected_count(self) -> int:
        """How many updates were rejected so far."""
        ...
