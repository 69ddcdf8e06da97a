"""An extended Kalman filter on (x, y, heading) with the turn-and-run terrain model.

The 3x3 algebra is written out on Python floats: numpy's per-call overhead (about a
microsecond per tiny operation) would otherwise dominate, and the benchmark compares
microseconds per update against the map's reductions.

Prediction (derivation)
-----------------------
The state is ``s = (x, y, h)``. With the outcome's moments from :func:`motion_moments`
(turn ``a``, run ``r``, drift ``e`` and skitter ``k``, all independent), the motion is,
to first order in the drift,

    h' = h + a + e,
    (x', y') = (x, y) + k + r (cos psi, sin psi),   psi = h + a + e/2

(the arc of the run ends on the chord at its mean heading; ``sinc(e/2) ~ 1``). The mean
moves with ``a = E[a]``, ``r = E[r]``, ``e = 0``, ``k = 0``. With ``C, S = cos, sin(h + E[a])``
and ``m = E[r]``, the Jacobians are

    F = dh'/ds = [[1, 0, -m S], [0, 1, m C], [0, 0, 1]],
    J_a = (-m S, m C, 1),  J_r = (C, S, 0),  J_e = (-m S / 2, m C / 2, 1),

and the process noise is ``Q = Var[a] J_a J_a' + Var[r] J_r J_r' + Var[e] J_e J_e' +
diag(Var[k_x], Var[k_y], 0)``, then ``P' = F P F' + process_noise_scale * Q``. Here
``Var[e] = drift^2 E[r^2] / 3`` (uniform drift) and ``Var[k_x] = Var[k_y] = E[|k|^2] / 2``
(uniform direction); the clipped normals of the turn, run and skitter lengths are moment
matched exactly. Second-order effects (the mean's shrinkage ``E[cos]`` under heading
spread, ``sinc``) are left out, as in any EKF.

Update
------
The sensor sits at ``o = R(h) (forward, left)`` from the robot; with ``d = landmark -
(x, y) - o`` and ``q = |d|^2``, the bearing is ``atan2(d_y, d_x) - h`` with gradient
``(d_y/q, -d_x/q, -(d . o)/q - 1)`` and the range ``sqrt(q)`` with gradient
``(-d_x, -d_y, d_x o_y - d_y o_x)/sqrt(q)``. The bearing innovation is wrapped to
(-pi, pi]; the covariance update is the Joseph form ``A P A' + K R K'``, ``A = I - K H``,
evaluated as the product ``(A P) A'`` (it does not rely on K being the optimal gain).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import ANGLE_ERROR, FACTOR, LENGTH, START_RADIUS, Range, finite_float
from aura_ums.baselines._moments import check_motion, motion_moments
from aura_ums.baselines._region import ConfidenceRegion, check_probability, chi2_quantile, gaussian_region
from aura_ums.errors import InputError
from aura_ums.uncertainty import BearingObservation, Pose, RangeBearingObservation, TerrainStats, TurnAndRun

_PI = math.pi
_TWO_PI = 2.0 * math.pi

_ZERO3 = (0.0, 0.0, 0.0)

#: Landmarks closer than this (m) to the predicted sensor position give no usable direction.
_MIN_LANDMARK_DISTANCE = 1e-9

# The ranges of the filters' standard deviations (the EKF's and the particle filter's): 1e300
# overflowed their squares, and the particles of a 1e300 m cloud left the coordinate range.
#: Initial standard deviation of x and y, metres: a start's uncertainty (10 km).
POSITION_SD = START_RADIUS
#: Initial standard deviation of the heading, radians: an angle's error, or none.
HEADING_SD = Range(0.0, ANGLE_ERROR.high, "rad")
#: Bearing measurement standard deviation, radians: as a sensor calibration's ``bearing_sd``.
BEARING_SD = ANGLE_ERROR
#: Range measurement standard deviation, metres: from a micrometre (no sensor measures closer;
#: the square of a smaller one underflows) to a length a sensor measures.
RANGE_SD = Range(1e-6, LENGTH.high, "m")
#: Extra range standard deviation per metre of range: as a sensor calibration's
#: ``range_sd_fraction``, or none.
RANGE_SD_FRACTION = Range(0.0, 10.0)


def measurement_variances(
    bearing_sd: object, range_sd: object, range_sd_fraction: object
) -> tuple[float, float, float]:
    """Return the variances of a bearing and a range, and the squared fraction, checked in their ranges."""
    return (
        BEARING_SD.check(bearing_sd, "bearing_sd") ** 2,
        RANGE_SD.check(range_sd, "range_sd") ** 2,
        RANGE_SD_FRACTION.check(range_sd_fraction, "range_sd_fraction") ** 2,
    )


def _wrap(angle: float) -> float:
    result = _PI - (_PI - angle) % _TWO_PI
    return result + _TWO_PI if result <= -_PI else result


def _gate_threshold(gate_probability: float | None, dof: int) -> float:
    if gate_probability is None:
        return math.inf
    return chi2_quantile(check_probability(gate_probability, "gate_probability"), dof)


def landmark_position(landmark_xy: object) -> tuple[float, float]:
    """Return ``landmark_xy`` as two finite floats (metres), or raise InputError."""
    values: tuple[object, ...]
    if isinstance(landmark_xy, tuple):
        values = landmark_xy
    else:
        try:
            values = tuple(landmark_xy)  # type: ignore[arg-type]
        except TypeError:
            values = ()
    if len(values) != 2:
        raise InputError(f"landmark_xy: expected (x, y) in metres, got {landmark_xy!r}")
    return (finite_float(values[0], "landmark_xy[0]"), finite_float(values[1], "landmark_xy[1]"))


def check_observation(observation: object) -> BearingObservation | RangeBearingObservation:
    """Return ``observation`` if it is a bearing or range-bearing observation, else raise InputError."""
    if not isinstance(observation, (BearingObservation, RangeBearingObservation)):
        raise InputError(
            "observation: expected a BearingObservation or RangeBearingObservation, "
            f"got {type(observation).__name__}"
        )
    return observation


class ExtendedKalmanFilter:
    """An EKF on (x, y, heading) driven by turn-and-run commands and landmark bearings/ranges.

    The estimator users would pick instead of the spatial uncertainty map, fed exactly
    what the map is fed. Prediction uses the exact first two moments of the terrain model
    (clipped normals included) and analytic Jacobians; updates take a bearing (1-D) or a
    range and bearing (2-D), with a Mahalanobis gate. See the module docstring for the
    equations.

    Measurement model: the measured bearing is ``observation.bearing`` with standard
    deviation ``bearing_sd``; the measured range is the middle of ``[range_min, range_max]``
    with variance ``range_sd**2 + (range_sd_fraction * range)**2``. The observations'
    error *bounds* are not used: a Gaussian filter needs standard deviations.

    Parameters
    ----------
    initial : Pose
        Initial mean pose.
    position_sd : float
        Initial standard deviation of x and of y, metres, in [0, 10000] (uncorrelated).
    heading_sd : float
        Initial standard deviation of the heading, radians, in [0, 1000].
    bearing_sd : float
        Bearing measurement standard deviation, radians, in [1e-6, 1000].
    range_sd : float
        Range measurement standard deviation, metres, in [1e-6, 10000].
    range_sd_fraction : float
        Extra range standard deviation per metre of range, in [0, 10] (added in quadrature).
    gate_probability : float or None
        Reject an update whose squared Mahalanobis innovation exceeds the chi-square
        quantile of this probability (1 or 2 degrees of freedom); None accepts all.
    process_noise_scale : float
        Multiplier of the process noise covariance Q, in (0, 100] (1 is the model as
        derived; larger values are the usual tuning against unmodelled error).

    Raises
    ------
    InputError
        For a non-Pose initial state, standard deviations outside their ranges above, a
        ``process_noise_scale`` outside (0, 100], or a gate probability outside (0, 1).

    Examples
    --------
    >>> import math
    >>> from aura_ums.uncertainty import TerrainTable
    >>> ekf = ExtendedKalmanFilter(Pose(0, 0, 0), position_sd=0.1, heading_sd=0.01,
    ...                            bearing_sd=0.01, range_sd=0.2)
    >>> ekf.predict(TurnAndRun(0.0, 10.0), TerrainTable.default()["grass"])
    >>> round(ekf.mean.x, 2)
    8.97
    >>> seen = RangeBearingObservation("corner", 1.0, math.atan2(5, 1.0), 0.03, 5.0, 5.2)
    >>> ekf.update(seen, (10.0, 5.0)), ekf.rejected_count
    (True, 0)
    >>> ekf.update(BearingObservation("corner", 2.0, math.pi, 0.03), (10.0, 5.0))  # behind: gated out
    False
    >>> ekf.rejected_count
    1
    >>> ExtendedKalmanFilter(Pose(0, 0, 0), position_sd=0.1, heading_sd=0.01, bearing_sd=0.0, range_sd=0.2)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: bearing_sd: expected a number in [1e-06, 1000] rad, got 0.0
    """

    __slots__ = (
        "_bearing_gate",
        "_bearing_var",
        "_h",
        "_p",
        "_range_bearing_gate",
        "_range_fraction_sq",
        "_range_var",
        "_rejected",
        "_scale",
        "_x",
        "_y",
    )

    def __init__(
        self,
        initial: Pose,
        *,
        position_sd: float,
        heading_sd: float,
        bearing_sd: float,
        range_sd: float,
        range_sd_fraction: float = 0.0,
        gate_probability: float | None = 0.999,
        process_noise_scale: float = 1.0,
    ) -> None:
        if not isinstance(initial, Pose):
            raise InputError(f"initial: expected a Pose, got {type(initial).__name__}")
        position_var = POSITION_SD.check(position_sd, "position_sd") ** 2
        heading_var = HEADING_SD.check(heading_sd, "heading_sd") ** 2
        self._bearing_var, self._range_var, self._range_fraction_sq = measurement_variances(
            bearing_sd, range_sd, range_sd_fraction
        )
        self._bearing_gate = _gate_threshold(gate_probability, 1)
        self._range_bearing_gate = _gate_threshold(gate_probability, 2)
        # Beyond FACTOR's 100 the covariance is no estimate (1e300 gave 1e296 m^2 after three steps).
        self._scale = FACTOR.check(process_noise_scale, "process_noise_scale")
        self._x, self._y, self._h = initial.x, initial.y, initial.heading
        # Upper triangle of P: xx, xy, xh, yy, yh, hh.
        self._p = (position_var, 0.0, 0.0, position_var, 0.0, heading_var)
        self._rejected = 0

    @property
    def mean(self) -> Pose:
        """The mean pose (x, y in metres, heading in radians)."""
        return Pose(self._x, self._y, self._h)

    @property
    def covariance(self) -> NDArray[np.float64]:
        """The covariance of (x, y, heading), shape (3, 3): m^2, m*rad, rad^2. A read-only copy."""
        xx, xy, xh, yy, yh, hh = self._p
        matrix = np.array([[xx, xy, xh], [xy, yy, yh], [xh, yh, hh]])
        matrix.setflags(write=False)
        return matrix

    @property
    def rejected_count(self) -> int:
        """How many updates the gate has rejected so far."""
        return self._rejected

    def predict(self, command: TurnAndRun, terrain: TerrainStats) -> None:
        """Move the belief by a turn-and-run command on a terrain (module docstring: derivation).

        Parameters
        ----------
        command : TurnAndRun
            The commanded motion.
        terrain : TerrainStats
            Statistics of the terrain it happens on.
        """
        check_motion(command, terrain)
        turn_mean, turn_var, m, run_var, drift_var, skitter_var = motion_moments(terrain, command)
        psi = self._h + turn_mean
        c, s = math.cos(psi), math.sin(psi)
        f13, f23 = -m * s, m * c
        xx, xy, xh, yy, yh, hh = self._p
        # F P F' for F = I + (f13, f23, 0) e_h'.
        xh_new = xh + f13 * hh
        yh_new = yh + f23 * hh
        xx_new = xx + f13 * xh + f13 * xh_new
        xy_new = xy + f13 * yh + f23 * xh_new
        yy_new = yy + f23 * yh + f23 * yh_new
        # Q: turn along J_a = (f13, f23, 1), run along (c, s, 0), drift along (f13/2, f23/2, 1).
        k = self._scale
        va, vr, ve, vk = k * turn_var, k * run_var, k * drift_var, k * skitter_var
        along = va + 0.25 * ve
        mixed = va + 0.5 * ve
        self._p = (
            xx_new + along * f13 * f13 + vr * c * c + vk,
            xy_new + along * f13 * f23 + vr * c * s,
            xh_new + mixed * f13,
            yy_new + along * f23 * f23 + vr * s * s + vk,
            yh_new + mixed * f23,
            hh + va + ve,
        )
        self._x += m * c
        self._y += m * s
        self._h = _wrap(psi)

    def update(
        self, observation: BearingObservation | RangeBearingObservation, landmark_xy: tuple[float, float]
    ) -> bool:
        """Correct the belief with an observation of a landmark at ``landmark_xy``.

        Parameters
        ----------
        observation : BearingObservation or RangeBearingObservation
            The bearing (rad) or range (m) and bearing, with the sensor's offset on the robot.
        landmark_xy : tuple of float
            The landmark's (x, y), metres.

        Returns
        -------
        bool
            True when applied; False when gated out (counted in :attr:`rejected_count`)
            or when the landmark sits at the predicted sensor position (no direction).
        """
        obs = check_observation(observation)
        lx, ly = landmark_position(landmark_xy)
        h = self._h
        c, s = math.cos(h), math.sin(h)
        forward, left = obs.sensor_offset
        ox, oy = forward * c - left * s, forward * s + left * c
        dx = lx - self._x - ox
        dy = ly - self._y - oy
        q = dx * dx + dy * dy
        if q <= _MIN_LANDMARK_DISTANCE * _MIN_LANDMARK_DISTANCE:
            self._rejected += 1
            return False
        bearing_innovation = _wrap(obs.bearing - (math.atan2(dy, dx) - h))
        b0, b1, b2 = dy / q, -dx / q, -(dx * ox + dy * oy) / q - 1.0
        xx, xy, xh, yy, yh, hh = self._p
        # v = P b'.
        v0 = xx * b0 + xy * b1 + xh * b2
        v1 = xy * b0 + yy * b1 + yh * b2
        v2 = xh * b0 + yh * b1 + hh * b2
        rb = self._bearing_var
        if isinstance(obs, BearingObservation):
            s_bb = b0 * v0 + b1 * v1 + b2 * v2 + rb
            if bearing_innovation * bearing_innovation > self._bearing_gate * s_bb:
                self._rejected += 1
                return False
            k0, k1, k2 = v0 / s_bb, v1 / s_bb, v2 / s_bb
            self._apply(
                _ZERO3,
                (v0, v1, v2),
                _ZERO3,
                (k0, k1, k2),
                _ZERO3,
                (b0, b1, b2),
                0.0,
                rb,
                k0 * bearing_innovation,
                k1 * bearing_innovation,
                k2 * bearing_innovation,
            )
            return True
        distance = math.sqrt(q)
        measured = 0.5 * (obs.range_min + obs.range_max)
        rr = self._range_var + self._range_fraction_sq * measured * measured
        r0, r1, r2 = -dx / distance, -dy / distance, (dx * oy - dy * ox) / distance
        u0 = xx * r0 + xy * r1 + xh * r2
        u1 = xy * r0 + yy * r1 + yh * r2
        u2 = xh * r0 + yh * r1 + hh * r2
        s_rr = r0 * u0 + r1 * u1 + r2 * u2 + rr
        s_rb = r0 * v0 + r1 * v1 + r2 * v2
        s_bb = b0 * v0 + b1 * v1 + b2 * v2 + rb
        det = s_rr * s_bb - s_rb * s_rb
        i_rr, i_rb, i_bb = s_bb / det, -s_rb / det, s_rr / det
        range_innovation = measured - distance
        mahalanobis = (
            i_rr * range_innovation * range_innovation
            + 2.0 * i_rb * range_innovation * bearing_innovation
            + i_bb * bearing_innovation * bearing_innovation
        )
        if mahalanobis > self._range_bearing_gate:
            self._rejected += 1
            return False
        # K = P H' S^-1: column for range, column for bearing.
        kr0, kr1, kr2 = u0 * i_rr + v0 * i_rb, u1 * i_rr + v1 * i_rb, u2 * i_rr + v2 * i_rb
        kb0, kb1, kb2 = u0 * i_rb + v0 * i_bb, u1 * i_rb + v1 * i_bb, u2 * i_rb + v2 * i_bb
        self._apply(
            (u0, u1, u2),
            (v0, v1, v2),
            (kr0, kr1, kr2),
            (kb0, kb1, kb2),
            (r0, r1, r2),
            (b0, b1, b2),
            rr,
            rb,
            kr0 * range_innovation + kb0 * bearing_innovation,
            kr1 * range_innovation + kb1 * bearing_innovation,
            kr2 * range_innovation + kb2 * bearing_innovation,
        )
        return True

    def _apply(
        self,
        u: tuple[float, float, float],
        v: tuple[float, float, float],
        kr: tuple[float, float, float],
        kb: tuple[float, float, float],
        hr: tuple[float, float, float],
        hb: tuple[float, float, float],
        rr: float,
        rb: float,
        dx: float,
        dy: float,
        dh: float,
    ) -> None:
        """Apply a correction and the Joseph update ``A P A' + K R K'``, ``A = I - kr hr' - kb hb'``.

        ``u = P hr'`` and ``v = P hb'`` (so ``A P = P - kr u' - kb v'``); a bearing-only
        update passes zeros for the range row. Written out on floats for speed.
        """
        xx, xy, xh, yy, yh, hh = self._p
        u0, u1, u2 = u
        v0, v1, v2 = v
        kr0, kr1, kr2 = kr
        kb0, kb1, kb2 = kb
        hr0, hr1, hr2 = hr
        hb0, hb1, hb2 = hb
        # M = A P.
        m00 = xx - kr0 * u0 - kb0 * v0
        m01 = xy - kr0 * u1 - kb0 * v1
        m02 = xh - kr0 * u2 - kb0 * v2
        m10 = xy - kr1 * u0 - kb1 * v0
        m11 = yy - kr1 * u1 - kb1 * v1
        m12 = yh - kr1 * u2 - kb1 * v2
        m20 = xh - kr2 * u0 - kb2 * v0
        m21 = yh - kr2 * u1 - kb2 * v1
        m22 = hh - kr2 * u2 - kb2 * v2
        # M A' = M - (M hr') kr' - (M hb') kb'.
        zr0 = m00 * hr0 + m01 * hr1 + m02 * hr2
        zr1 = m10 * hr0 + m11 * hr1 + m12 * hr2
        zr2 = m20 * hr0 + m21 * hr1 + m22 * hr2
        zb0 = m00 * hb0 + m01 * hb1 + m02 * hb2
        zb1 = m10 * hb0 + m11 * hb1 + m12 * hb2
        zb2 = m20 * hb0 + m21 * hb1 + m22 * hb2
        # Upper triangle of M A' + rr kr kr' + rb kb kb'.
        rkr0, rkr1, rkr2 = rr * kr0, rr * kr1, rr * kr2
        rkb0, rkb1, rkb2 = rb * kb0, rb * kb1, rb * kb2
        self._p = (
            m00 - zr0 * kr0 - zb0 * kb0 + rkr0 * kr0 + rkb0 * kb0,
            m01 - zr0 * kr1 - zb0 * kb1 + rkr0 * kr1 + rkb0 * kb1,
            m02 - zr0 * kr2 - zb0 * kb2 + rkr0 * kr2 + rkb0 * kb2,
            m11 - zr1 * kr1 - zb1 * kb1 + rkr1 * kr1 + rkb1 * kb1,
            m12 - zr1 * kr2 - zb1 * kb2 + rkr1 * kr2 + rkb1 * kb2,
            m22 - zr2 * kr2 - zb2 * kb2 + rkr2 * kr2 + rkb2 * kb2,
        )
        self._x += dx
        self._y += dy
        self._h = _wrap(self._h + dh)

    def region(self, probability: float = 0.99) -> ConfidenceRegion:
        """Return the Gaussian confidence region of ``probability`` (joint, see below).

        Position: the ellipse of ``sqrt(probability)`` (chi-square, 2 degrees of freedom)
        of the (x, y) marginal, as a circumscribed 64-gon. Heading: the mean +- the normal
        quantile of ``sqrt(probability)`` times the heading standard deviation. Their
        product holds at least ``probability`` of any Gaussian (exactly, when position and
        heading are uncorrelated); see :mod:`aura_ums.baselines._region`.

        Parameters
        ----------
        probability : float
            Joint probability, in (0, 1).

        Examples
        --------
        >>> ekf = ExtendedKalmanFilter(Pose(1, 2, 3), position_sd=0.0, heading_sd=0.0,
        ...                            bearing_sd=0.01, range_sd=0.1)
        >>> r = ekf.region()
        >>> r.area, r.heading_halfwidth, r.contains(1.0, 2.0, 3.0)     # a point, known heading
        (0.0, 0.0, True)
        """
        xx, xy, _, yy, _, hh = self._p
        return gaussian_region(self._x, self._y, self._h, xx, xy, yy, hh, probability)

    def __repr__(self) -> str:
        return (
            f"ExtendedKalmanFilter(mean=({self._x:.4g}, {self._y:.4g}, {self._h:.4g}), "
            f"sd=({math.sqrt(self._p[0]):.3g}, {math.sqrt(self._p[3]):.3g}, {math.sqrt(self._p[5]):.3g}), "
            f"rejected={self._rejected})"
        )
