"""Baseline estimators to compare the spatial uncertainty map with: an EKF, a particle filter, a Codac box.

All consume exactly what :class:`~aura_ums.uncertainty.SpatialUncertaintyMap` consumes:
:class:`~aura_ums.uncertainty.TurnAndRun` commands with
:class:`~aura_ums.uncertainty.TerrainStats` to predict, and
:class:`~aura_ums.uncertainty.BearingObservation` /
:class:`~aura_ums.uncertainty.RangeBearingObservation` with the landmark's (x, y) to
update, and describe their belief by a :class:`ConfidenceRegion` (a convex polygon and a
heading interval) for side-by-side figures. :class:`CodacLocalizer`, the set-membership
one, needs the optional ``codac`` extra (:func:`codac_available`).

This package imports only geometry, uncertainty, validation and errors.
"""

from aura_ums.baselines._codac import CodacLocalizer, codac_available
from aura_ums.baselines._ekf import ExtendedKalmanFilter
from aura_ums.baselines._moments import MotionMoments, motion_moments
from aura_ums.baselines._particle import ParticleFilter
from aura_ums.baselines._protocol import Estimator
from aura_ums.baselines._region import ConfidenceRegion, chi2_quantile, ellipse_polygon

__all__ = [
    "CodacLocalizer",
    "ConfidenceRegion",
    "Estimator",
    "ExtendedKalmanFilter",
    "MotionMoments",
    "ParticleFilter",
    "chi2_quantile",
    "codac_available",
    "ellipse_polygon",
    "motion_moments",
]
