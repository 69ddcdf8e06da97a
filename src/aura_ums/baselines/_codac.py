"""A contractor-based set-membership localizer on Codac 2: a box in (x, y, heading).

The method a user of set-membership tools would write with Codac (codac.io), fed exactly
what the map is fed, for :func:`~aura_ums.logs.compare_on_log`'s ``codac`` row. Codac is
an optional extra (``pip install aura-ums[codac]``); without it, building a
:class:`CodacLocalizer` raises :class:`~aura_ums.errors.MissingDependencyError`.

Prediction
----------
The state is a box ``[x] x [y] x [h]``. A command's bounds at ``sigmas`` standard
deviations (:func:`~aura_ums.uncertainty.motion_bounds`, the bounds the map grows by) move
it by interval arithmetic (Codac's outward-rounded ``Interval``)::

    h1 = h + [turn_min, turn_max]
    psi = h1 + [-drift_max, drift_max] / 2          (the chord's direction)
    (x, y) += [-k, k]^2 + [chord_min, run_max] (cos psi, sin psi)
    h = h1 + [-drift_max, drift_max]

with ``k`` the skitter radius. A box forgets the coupling of heading and position (and
of the chord's direction and the new heading), so it grows faster than the map's polygon
and wedge: that is the method's price, not a choice made here.

Contraction
-----------
An observation of the landmark at ``l`` seen from the sensor at ``s = p + R(h) o``
(``o`` the sensor offset) says ``l - s = rho (cos(h + b), sin(h + b))`` for a bearing
``b`` in ``bearing +- bearing_error`` and a range ``rho`` in ``[range_min, range_max]``
(``[0, oo]`` for a bearing alone): Codac's ``CtcPolar`` (which handles the angle modulo
2 pi) through ``CtcInverse``. Each of the latest ``window`` observations stays a
contractor of the *current* box through the displacement ``D`` since it was made, a box
``(dx, dy, dh)`` in the robot's frame of that time, grown by every later command exactly
as the state is (starting from the point 0): the pose then was ``h_i = h - dh``,
``p_i = p - R(h_i) (dx, dy)``. Every update contracts the box with ``CtcQInter(q, ...)``
over the window: the hull of the intersections of all but ``q`` of them, so the truth
stays inside while at most ``q`` of any ``window`` consecutive observations are wrong (as
the map's relaxed intersection with ``relaxed_q = q``, ``relaxed_window = window``).

Rounding mode
-------------
Codac's interval arithmetic rounds outward by setting the processor's rounding mode to
upward once, when it is imported, and leaves it so (Codac 2.1.2): every float operation of the process
after ``import codac`` (numpy's, Python's) then rounds upward (``0.1 + 0.2`` changes in its
last bit), and an arithmetic operation of Codac's made after someone restored the
default (to nearest) no longer rounds outward (``Interval(0.1) + Interval(0.2)`` shrinks
to a point). So every call into Codac here runs inside :func:`codac_rounding`, which sets
Codac's mode on entry and gives the caller's back on exit.

Re-initialisation
-----------------
When the contraction empties the box (more than ``q`` wrong observations in the window,
or bounds the data broke), the window restarts from the new observation alone, which
contracts the predicted box; if even that is empty, the box is re-initialised from the
observation alone: a range and bearing give the box ``l +- (range_max + |o|)`` with any
heading, a bearing alone the predicted box's position with any heading. Either counts
in :attr:`CodacLocalizer.reinitialisations` (the ``rejected`` figure of the comparison).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import importlib
import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from aura_ums._validate import SIGMAS, nonnegative_float
from aura_ums.baselines._ekf import check_observation
from aura_ums.baselines._moments import check_motion
from aura_ums.baselines._region import ConfidenceRegion, check_probability
from aura_ums.errors import InputError, MissingDependencyError
from aura_ums.geometry import ConvexPolygon
from aura_ums.uncertainty import (
    BearingObservation,
    MotionBounds,
    Pose,
    RangeBearingObservation,
    TerrainStats,
    TurnAndRun,
    motion_bounds,
)

_TWO_PI = 2.0 * math.pi

# Components of the extended box one contractor works on: the state (3), the displacement
# since the observation (3), the range and bearing seen, the landmark (2), the sensor offset (2).
_EXTENDED = 12


def codac_available() -> bool:
    """Return True when Codac 2 can be imported (the ``codac`` extra is installed).

    Examples
    --------
    >>> codac_available()
    True
    """
    try:
        load_codac()
    except MissingDependencyError:
        return False
    return True


# The C library's fegetround/fesetround (libm's, or the process's own symbols).
_FENV = ctypes.CDLL(ctypes.util.find_library("m") or None)


# FE_UPWARD of the C libraries Codac ships wheels for: x86 (0x800), arm64 (0x400000), others.
_UPWARD_CANDIDATES = (0x800, 0x400000, 0x2, 0x1, 0x3)


def _rounds_up(one: float, tiny: float) -> bool:
    """Return whether ``one + tiny`` rounds up now (arguments, so nothing is folded at compile time)."""
    return one + tiny > one


@functools.cache
def _upward_mode() -> int:
    """Return this C library's FE_UPWARD, found by trying the known values (the caller's mode kept)."""
    before = _FENV.fegetround()
    try:
        for mode in _UPWARD_CANDIDATES:
            if _FENV.fesetround(mode) == 0 and _rounds_up(1.0, 2.0**-60):
                return mode
    finally:
        _FENV.fesetround(before)
    raise MissingDependencyError("the Codac localizer needs a C library that rounds upward on request")


def load_codac(name: str = "codac") -> Any:
    """Import the module ``name`` (Codac), the caller's rounding mode kept, or raise naming the extra.

    Raises
    ------
    MissingDependencyError
        When it is not installed (``pip install aura-ums[codac]``).
    """
    before = _FENV.fegetround()
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        raise MissingDependencyError(
            f"the Codac localizer needs the optional package 'codac' (import of {name} failed: {exc}); "
            "install aura-ums[codac]"
        ) from exc
    finally:
        _FENV.fesetround(before)


def codac_module() -> Any:
    """Return the imported ``codac`` module (the caller's rounding mode kept), or raise.

    Call into it only inside :func:`codac_rounding` (module docstring: Rounding mode).

    Raises
    ------
    MissingDependencyError
        When Codac 2 is not installed (``pip install aura-ums[codac]``).

    Examples
    --------
    >>> codac = codac_module()
    >>> with codac_rounding():
    ...     total = codac.Interval(0.1) + codac.Interval(0.2)
    >>> total.lb() < total.ub(), 0.1 + 0.2 == 0.30000000000000004    # outward inside, nearest outside
    (True, True)
    """
    return load_codac()


@contextmanager
def codac_rounding() -> Iterator[None]:
    """Run the block rounding upward, as Codac's outward rounding needs, then restore the caller's mode.

    Raises
    ------
    MissingDependencyError
        When the C library offers no upward rounding.
    """
    mode = _upward_mode()
    before = _FENV.fegetround()
    _FENV.fesetround(mode)
    try:
        yield
    finally:
        _FENV.fesetround(before)


def _polar_contractor(codac: Any) -> Any:
    """Build the contractor of the extended box (module docstring: Contraction)."""
    z = codac.VectorVar(_EXTENDED)
    x, y, h, dx, dy, dh, rho, bearing, lx, ly, forward, left = (z[i] for i in range(_EXTENDED))
    then = h - dh
    c, s = codac.cos(then), codac.sin(then)
    px = x - c * dx + s * dy
    py = y - s * dx - c * dy
    sensor_x = px + c * forward - s * left
    sensor_y = py + s * forward + c * left
    seen = codac.AnalyticFunction([z], codac.vec(lx - sensor_x, ly - sensor_y, rho, then + bearing))
    # The centred form costs twice the time per contraction and narrowed nothing in trials.
    return codac.CtcInverse(seen, codac.CtcPolar(), False)


def _move(codac: Any, box: list[Any], bounds: MotionBounds) -> list[Any]:
    """Return the box ``[x, y, h]`` (codac Intervals) moved by a command's bounds (docstring: Prediction)."""
    interval = codac.Interval
    x, y, h = box
    h1 = h + interval(bounds.turn_min, bounds.turn_max)
    drift = interval(-bounds.drift_max, bounds.drift_max)
    if bounds.run_max > 0.0:
        psi = h1 + 0.5 * drift
        run = interval(bounds.chord_min, bounds.run_max)
        x = x + run * codac.cos(psi)
        y = y + run * codac.sin(psi)
    if bounds.skitter_radius > 0.0:
        skitter = interval(-bounds.skitter_radius, bounds.skitter_radius)
        x, y = x + skitter, y + skitter
    return [x, y, _any_turn(codac, h1 + drift)]


def _any_turn(codac: Any, heading: Any) -> Any:
    """Return ``heading`` with its middle near [-pi, pi], and no wider than the full circle.

    Every function of the heading here is 2 pi periodic, so a shift by whole turns (an
    enclosure of 2 k pi) keeps the box's meaning; an interval of 2 pi or more is any heading.
    """
    pi = codac.Interval.pi()
    if heading.diam() >= _TWO_PI:
        return codac.Interval(round(heading.mid() / _TWO_PI) * _TWO_PI) + codac.Interval(-pi.ub(), pi.ub())
    turns = round(heading.mid() / _TWO_PI)
    return heading - 2.0 * turns * pi if turns else heading


class _Sighting:
    """One observation of the window: its fixed components and its displacement box since."""

    __slots__ = ("displacement", "fixed")

    def __init__(self, fixed: list[Any], codac: Any) -> None:
        self.fixed = fixed
        zero = codac.Interval(0.0)
        self.displacement = [zero, zero, zero]


class CodacLocalizer:
    """A box localizer on Codac 2 contractors, with a q-relaxed intersection over recent observations.

    Set-membership, like the map: the box holds the truth as long as the command bounds
    hold at ``sigmas`` standard deviations, the observations' bounds hold, and at most
    ``q`` of any ``window`` consecutive observations are wrong. See the module docstring
    for the equations and for what it does when the box empties.

    Parameters
    ----------
    initial : Pose
        The start pose.
    position_halfwidth : float
        Half-width of the start box in x and in y, metres, >= 0.
    heading_halfwidth : float
        Half-width of the start heading interval, radians, >= 0.
    sigmas : float
        Standard deviations of the terrain model the command bounds cover, in [0.1, 100] (the
        map's ``ManagerSettings.sigmas``).
    q : int
        Wrong observations tolerated among ``window`` consecutive ones, >= 0
        (``ManagerSettings.relaxed_q``).
    window : int
        Observations the relaxed intersection runs over, > ``q``
        (``ManagerSettings.relaxed_window``).

    Raises
    ------
    MissingDependencyError
        When Codac is not installed.
    InputError
        For a non-Pose start, negative or non-finite half-widths, a non-positive
        ``sigmas``, or ``q``, ``window`` that are not integers with ``0 <= q < window``.

    Examples
    --------
    >>> import math
    >>> from aura_ums.uncertainty import TerrainTable
    >>> box = CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.01)
    >>> box.predict(TurnAndRun(0.0, 10.0), TerrainTable.default()["grass"])
    >>> round(box.region().area, 2)
    7.58
    >>> seen = RangeBearingObservation("corner", 1.0, math.atan2(4.0, 3.1), 0.03, 4.9, 5.2)
    >>> box.update(seen, (12.0, 4.0)), round(box.region().area, 2), box.reinitialisations
    (True, 4.81, 0)
    >>> behind = BearingObservation("corner", 2.0, math.pi, 0.03)    # contradicts the box
    >>> box.update(behind, (12.0, 4.0)), box.reinitialisations
    (False, 1)
    >>> CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.01, q=2, window=2)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: window: expected an integer > q (2), got 2
    """

    __slots__ = (
        "_box",
        "_codac",
        "_ctc",
        "_pool",
        "_q",
        "_reinitialisations",
        "_sigmas",
        "_window",
        "_windowed",
    )

    def __init__(
        self,
        initial: Pose,
        *,
        position_halfwidth: float,
        heading_halfwidth: float,
        sigmas: float = 3.0,
        q: int = 0,
        window: int = 10,
    ) -> None:
        if not isinstance(initial, Pose):
            raise InputError(f"initial: expected a Pose, got {type(initial).__name__}")
        radius = nonnegative_float(position_halfwidth, "position_halfwidth")
        spread = nonnegative_float(heading_halfwidth, "heading_halfwidth")
        self._sigmas = SIGMAS.check(sigmas, "sigmas")
        if isinstance(q, bool) or not isinstance(q, int) or q < 0:
            raise InputError(f"q: expected an integer >= 0, got {q!r}")
        if isinstance(window, bool) or not isinstance(window, int) or window <= q:
            raise InputError(f"window: expected an integer > q ({q}), got {window!r}")
        self._q, self._window = q, window
        self._codac = codac_module()
        with codac_rounding():
            self._ctc = _polar_contractor(self._codac)
            interval = self._codac.Interval
            self._box = [
                interval(initial.x) + interval(-radius, radius),
                interval(initial.y) + interval(-radius, radius),
                _any_turn(self._codac, interval(initial.heading) + interval(-spread, spread)),
            ]
        self._windowed: list[_Sighting] = []
        self._reinitialisations = 0
        # One contractor per place in the window, loaded with a sighting at each contraction:
        # a Python contractor handed to Codac is never freed (about 1 kB each), so one built
        # per sighting and update grew a 250,000-observation comparison to 2.8 GB.
        contractor = _contractor_class(self._codac)
        self._pool = [contractor(self._ctc) for _ in range(window)]

    @property
    def box(self) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
        """The box: (x_lo, x_hi), (y_lo, y_hi) in metres, (heading_lo, heading_hi) in radians, unwrapped."""
        x, y, h = self._box
        return (x.lb(), x.ub()), (y.lb(), y.ub()), (h.lb(), h.ub())

    @property
    def mean(self) -> Pose:
        """The box's centre (x, y in metres, heading in radians)."""
        x, y, h = self._box
        with codac_rounding():
            return Pose(x.mid(), y.mid(), h.mid())

    @property
    def reinitialisations(self) -> int:
        """How many times the contraction emptied the box (module docstring: Re-initialisation)."""
        return self._reinitialisations

    @property
    def rejected_count(self) -> int:
        """The :class:`~aura_ums.baselines.Estimator` figure: :attr:`reinitialisations`."""
        return self._reinitialisations

    def predict(self, command: TurnAndRun, terrain: TerrainStats) -> None:
        """Move the box, and every window observation's displacement, by a command on a terrain.

        Parameters
        ----------
        command : TurnAndRun
            The commanded motion.
        terrain : TerrainStats
            Statistics of the terrain it happens on.
        """
        check_motion(command, terrain)
        bounds = motion_bounds(terrain, command, self._sigmas)
        with codac_rounding():
            self._box = _move(self._codac, self._box, bounds)
            for sighting in self._windowed:
                sighting.displacement = _move(self._codac, sighting.displacement, bounds)

    def update(
        self, observation: BearingObservation | RangeBearingObservation, landmark_xy: tuple[float, float]
    ) -> bool:
        """Contract the box with the window's observations, this one at ``landmark_xy`` (m) included.

        Returns
        -------
        bool
            True when the relaxed intersection over the window was not empty; False when
            the box had to be re-initialised (counted in :attr:`reinitialisations`).
        """
        check_observation(observation)
        if len(landmark_xy) != 2 or not all(math.isfinite(v) for v in landmark_xy):
            raise InputError(
                f"landmark_xy: expected (x, y), two finite numbers in metres, got {landmark_xy!r}"
            )
        with codac_rounding():
            sighting = _Sighting(self._fixed(observation, landmark_xy), self._codac)
            self._windowed = [*self._windowed, sighting][-self._window :]
            contracted = self._contract(self._box, self._windowed, self._q)
            if contracted is not None:
                self._box = contracted
                return True
            self._reinitialisations += 1
            self._windowed = [sighting]
            alone = self._contract(self._box, self._windowed, 0)
            if alone is None:
                alone = self._restart(observation, landmark_xy, sighting)
            self._box = alone
            return False

    def _fixed(
        self, observation: BearingObservation | RangeBearingObservation, landmark_xy: tuple[float, float]
    ) -> list[Any]:
        """Return the observation's polar, landmark and offset components of the extended box."""
        interval = self._codac.Interval
        error = observation.bearing_error
        bearing = interval(observation.bearing) + interval(-error, error)
        if isinstance(observation, RangeBearingObservation):
            ranges = interval(observation.range_min, observation.range_max)
        else:
            ranges = interval(0.0, math.inf)
        forward, left = observation.sensor_offset
        lx, ly = float(landmark_xy[0]), float(landmark_xy[1])
        return [ranges, bearing, interval(lx), interval(ly), interval(forward), interval(left)]

    def _contract(self, box: list[Any], sightings: list[_Sighting], q: int) -> list[Any] | None:
        """Return ``box`` contracted by the q-relaxed intersection of the sightings; None when empty."""
        codac = self._codac
        contractors = [
            contractor.load(sighting) for contractor, sighting in zip(self._pool, sightings, strict=False)
        ]
        relaxed = codac.CtcFixpoint(codac.CtcQInter(q, contractors), 0.1)
        result = relaxed.contract(codac.IntervalVector(box))
        if result.is_empty():
            return None
        x, y, h = result[0], result[1], result[2]
        return [x, y, _any_turn(codac, h)]

    def _restart(
        self,
        observation: BearingObservation | RangeBearingObservation,
        landmark_xy: tuple[float, float],
        sighting: _Sighting,
    ) -> list[Any]:
        """Return the box re-initialised from one observation (module docstring: Re-initialisation)."""
        interval = self._codac.Interval
        heading = interval(-math.pi, math.pi)
        if isinstance(observation, RangeBearingObservation):
            reach = interval(-1.0, 1.0) * (observation.range_max + math.hypot(*observation.sensor_offset))
            lx, ly = landmark_xy
            start = [interval(lx) + reach, interval(ly) + reach, heading]
        else:
            start = [self._box[0], self._box[1], heading]
        contracted = self._contract(start, [sighting], 0)
        return start if contracted is None else contracted

    def region(self, probability: float = 0.99) -> ConfidenceRegion:
        """Return the box as a region: its x-y rectangle and its heading interval.

        A guaranteed set has no probability: ``probability`` (in (0, 1)) is only carried
        into the :class:`ConfidenceRegion`, which needs one.

        Examples
        --------
        >>> r = CodacLocalizer(Pose(1, 2, 3), position_halfwidth=0.5, heading_halfwidth=0.0).region()
        >>> r.area, round(r.heading_center, 6), r.heading_halfwidth, r.contains(1.4, 2.4, 3.0)
        (1.0, 3.0, 0.0, True)
        """
        chance = check_probability(probability)
        x, y, h = self._box
        with codac_rounding():
            corners = [(x.lb(), y.lb()), (x.ub(), y.lb()), (x.ub(), y.ub()), (x.lb(), y.ub())]
            center, halfwidth = h.mid(), h.rad()
        return ConfidenceRegion(ConvexPolygon(corners), center, halfwidth, chance)

    def __repr__(self) -> str:
        (x0, x1), (y0, y1), (h0, h1) = self.box
        return (
            f"CodacLocalizer(box=([{x0:.4g}, {x1:.4g}], [{y0:.4g}, {y1:.4g}], [{h0:.4g}, {h1:.4g}]), "
            f"window={len(self._windowed)}, reinitialisations={self._reinitialisations})"
        )


@functools.cache
@functools.cache
def _contractor_class(codac: Any) -> Any:
    """Return the Codac contractor subclass one window observation is (built once per module)."""

    class Contractor(codac.Ctc_IntervalVector):  # type: ignore[misc]
        """The extended contractor seen as one on the state box, for one observation."""

        def __init__(self, ctc: Any) -> None:
            codac.Ctc_IntervalVector.__init__(self, 3)
            self._ctc = ctc
            self._fixed = codac.IntervalVector(9)

        def load(self, sighting: _Sighting) -> Contractor:
            """Hold ``sighting``'s displacement and fixed components; return self."""
            self._fixed = codac.IntervalVector([*sighting.displacement, *sighting.fixed])
            return self

        def contract(self, box: Any) -> Any:
            extended = self._ctc.contract(codac.cart_prod(box, self._fixed))
            return extended.subvector(0, 2)

    return Contractor
