"""Mean and variance of one turn-and-run outcome under the terrain model (DESIGN §3).

These are the first two moments an EKF needs of :meth:`TerrainStats.sample_motion`'s
generative model. The model's clipped normals (the turn never exceeds the command, the
run never exceeds it nor goes backwards, the skitter is never negative) are moment
matched exactly, with the closed forms of a clipped (censored) normal; everything else
is the model as written.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from aura_ums.errors import InputError
from aura_ums.uncertainty import TerrainStats, TurnAndRun

_SQRT_HALF = math.sqrt(0.5)
_INV_SQRT_TWO_PI = 1.0 / math.sqrt(2.0 * math.pi)


def _cdf(z: float) -> float:
    return 0.5 * math.erfc(-z * _SQRT_HALF)


def _pdf(z: float) -> float:
    return _INV_SQRT_TWO_PI * math.exp(-0.5 * z * z) if math.isfinite(z) else 0.0


def clipped_normal_moments(mu: float, sigma: float, lo: float, hi: float) -> tuple[float, float]:
    """Return the mean and variance of ``clip(mu + sigma*Z, lo, hi)`` for a standard normal Z.

    Parameters
    ----------
    mu, sigma : float
        Mean and standard deviation (>= 0) of the normal before clipping.
    lo, hi : float
        Clip bounds, ``lo <= hi``; either may be infinite.

    Returns
    -------
    mean, variance : float
        In the units of ``mu`` and their square.

    Examples
    --------
    >>> clipped_normal_moments(1.0, 0.0, 0.0, 0.5)          # no spread: the clipped value
    (0.5, 0.0)
    >>> m, v = clipped_normal_moments(0.0, 1.0, 0.0, math.inf)   # max(0, Z)
    >>> round(m, 6), round(v, 6)                            # 1/sqrt(2 pi), 1/2 - 1/(2 pi)
    (0.398942, 0.340845)
    """
    if sigma <= 0.0:
        return (min(max(mu, lo), hi), 0.0)
    a = (lo - mu) / sigma
    b = (hi - mu) / sigma
    below, above = _cdf(a), 1.0 - _cdf(b)
    pdf_a, pdf_b = _pdf(a), _pdf(b)
    # Y = clip(Z, a, b); terms a*P(Z<a) and b*P(Z>b) vanish for infinite bounds.
    a_below = a * below if below > 0.0 else 0.0
    b_above = b * above if above > 0.0 else 0.0
    aa_below = a * a_below if below > 0.0 else 0.0
    bb_above = b * b_above if above > 0.0 else 0.0
    a_pdf = a * pdf_a if pdf_a > 0.0 else 0.0
    b_pdf = b * pdf_b if pdf_b > 0.0 else 0.0
    first = a_below + b_above + pdf_a - pdf_b
    second = aa_below + bb_above + (1.0 - below - above) + a_pdf - b_pdf
    return (mu + sigma * first, sigma * sigma * max(second - first * first, 0.0))


class MotionMoments(NamedTuple):
    """First two moments of one turn-and-run outcome (DESIGN §3 model).

    Attributes
    ----------
    turn_mean, turn_var : float
        Actual turn, rad and rad^2.
    run_mean, run_var : float
        Actual run length, m and m^2.
    drift_var : float
        Heading change during the run, rad^2 (its mean is zero).
    skitter_var : float
        Skitter displacement per axis, m^2 (its mean is zero; x and y uncorrelated).

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> grass = TerrainTable.default()["grass"]
    >>> moments = motion_moments(grass, TurnAndRun(0.5, 1.0))
    >>> round(moments.turn_mean, 4), round(moments.run_mean, 4)     # short of the command: losses
    (0.4675, 0.87)
    >>> turn_mean, turn_var, *_ = moments                           # a tuple, in field order
    >>> turn_mean == moments.turn_mean
    True
    >>> in_place = motion_moments(grass, TurnAndRun(0.5, 0.0))      # a turn without a run
    >>> in_place.run_mean, in_place.run_var, in_place.drift_var
    (0.0, 0.0, 0.0)
    """

    turn_mean: float
    turn_var: float
    run_mean: float
    run_var: float
    drift_var: float
    skitter_var: float


def check_motion(command: object, terrain: object) -> tuple[TurnAndRun, TerrainStats]:
    """Return ``(command, terrain)`` if they are a TurnAndRun and TerrainStats, else raise InputError."""
    if not isinstance(command, TurnAndRun):
        raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
    if not isinstance(terrain, TerrainStats):
        raise InputError(f"terrain: expected TerrainStats, got {type(terrain).__name__}")
    return command, terrain


def motion_moments(terrain: TerrainStats, command: TurnAndRun) -> MotionMoments:
    """Return the mean and variance of each part of ``command``'s outcome on ``terrain``.

    - turn ``T*c`` with ``c = clip(1 - rotation_loss + rotation_sd*Z, 0, 1)``: ``T*E[c]``, ``T^2 Var[c]``;
    - run ``clip(D*(1 - translation_loss + translation_sd*Z) - translation_inertial_loss, 0, D)``;
    - drift ``drift * run * U``, U uniform on [-1, 1]: mean 0, variance ``drift^2 E[run^2] / 3``;
    - skitter ``|T| * max(0, skitter + skitter_sd*Z)`` in a uniform direction: mean 0,
      variance ``E[length^2] / 2`` along each axis.

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> m = motion_moments(TerrainTable.default()["grass"], TurnAndRun(0.0, 10.0))
    >>> round(m.run_mean, 3), round(math.sqrt(m.run_var), 3), m.turn_var   # 8.97 +- 0.4, clipped at 10
    (8.969, 0.398, 0.0)
    >>> motion_moments(TerrainTable.default()["grass"], TurnAndRun(0.0, 0.0))   # no motion at all
    MotionMoments(turn_mean=0.0, turn_var=0.0, run_mean=0.0, run_var=0.0, drift_var=0.0, skitter_var=0.0)
    """
    if not isinstance(terrain, TerrainStats):
        raise InputError(f"terrain: expected TerrainStats, got {type(terrain).__name__}")
    if not isinstance(command, TurnAndRun):
        raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
    turn, run = command.turn, command.run
    if turn != 0.0:
        fraction_mean, fraction_var = clipped_normal_moments(
            1.0 - terrain.rotation_loss, terrain.rotation_sd, 0.0, 1.0
        )
        length_mean, length_var = clipped_normal_moments(terrain.skitter, terrain.skitter_sd, 0.0, math.inf)
        turn_mean, turn_var = turn * fraction_mean, turn * turn * fraction_var
        skitter_var = 0.5 * turn * turn * (length_var + length_mean * length_mean)
    else:
        turn_mean = turn_var = skitter_var = 0.0
    if run > 0.0:
        run_mean, run_var = clipped_normal_moments(
            run * (1.0 - terrain.translation_loss) - terrain.translation_inertial_loss,
            run * terrain.translation_sd,
            0.0,
            run,
        )
        drift_var = terrain.drift * terrain.drift * (run_var + run_mean * run_mean) / 3.0
    else:
        run_mean = run_var = drift_var = 0.0
    return MotionMoments(turn_mean, turn_var, run_mean, run_var, drift_var, skitter_var)
