"""Why the map manager rejects an identified observation: one enum for every reason."""

from __future__ import annotations

from aura_ums._validate import StrChoice


class RejectReason(StrChoice):
    """Why an observation did not reduce the map.

    The first three are checks the manager makes before any reduction; the next five are
    the reductions' own: no pose of the map agrees with the observation (an *inconsistent*
    observation, most likely a misidentified landmark). :attr:`EXCLUDED` is the relaxed
    intersection's (``ManagerSettings.relaxed_q > 0``): the map kept no pose that agrees
    with it, but tolerated it as one of its wrong ones. Each value is the text the
    reductions and earlier versions wrote, so counts keyed by reason read the same in
    JSON and CSV (a ``StrEnum`` member is its value wherever a string is expected).

    Examples
    --------
    >>> RejectReason.STALE.inconsistent, RejectReason.NO_POSITION.inconsistent
    (False, True)
    >>> RejectReason.EXCLUDED.inconsistent, RejectReason.EXCLUDED.reached_reduction
    (False, True)
    >>> RejectReason("unknown landmark id")          # from its value, as saved
    <RejectReason.UNKNOWN_LANDMARK: 'unknown landmark id'>
    >>> RejectReason("no such reason")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: RejectReason: expected one of ..., got 'no such reason'
    """

    #: The observation is older than the map (the map was grown past its time).
    STALE = "observation older than the map's time"
    #: The meadow map has no landmark with the observation's id.
    UNKNOWN_LANDMARK = "unknown landmark id"
    #: The observation cannot name a landmark of that class (``LandmarkClass.observes``).
    CLASS_MISMATCH = "observation class differs from the landmark's"
    #: No position of the map is consistent with the observation (Class I and II).
    NO_POSITION = "no position of the map is consistent with the observation"
    #: No sensor position of the map is consistent with it (a camera off the robot's centre).
    NO_SENSOR_POSITION = "no sensor position of the map is consistent with the observation"
    #: No heading of the map is consistent with the observed bearing.
    NO_HEADING_FOR_BEARING = "no heading of the map is consistent with the observed bearing"
    #: No heading of the map is consistent with the observed angle of a ground line (Class III).
    NO_HEADING_FOR_LINE = "no heading of the map is consistent with the observed line angle"
    #: No position of the map is at the observed offset from a ground line (Class III).
    NO_LINE_OFFSET = "no position of the map is at the observed offset from the line"
    #: The relaxed intersection (``relaxed_q > 0``) kept no pose that agrees with it: every
    #: hypothesis the manager still holds counts it among its at most ``relaxed_q`` wrong ones.
    EXCLUDED = "excluded by the relaxed intersection: every pose kept counts it as wrong"

    @property
    def inconsistent(self) -> bool:
        """Whether it is a reduction's: no pose of the map agrees (the consistency gate).

        :attr:`EXCLUDED` is not: the relaxed intersection tolerated it as one of its wrong
        observations, the map stayed sound without a re-localization.
        """
        return self not in _NOT_INCONSISTENT

    @property
    def reached_reduction(self) -> bool:
        """Whether the observation passed the manager's checks and met the map (not a check's rejection)."""
        return self not in _CHECKS


_CHECKS = frozenset({RejectReason.STALE, RejectReason.UNKNOWN_LANDMARK, RejectReason.CLASS_MISMATCH})
_NOT_INCONSISTENT = _CHECKS | {RejectReason.EXCLUDED}
