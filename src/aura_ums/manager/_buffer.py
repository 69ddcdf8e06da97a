"""The identified landmark buffer: time-stamped landmark observations waiting for the map manager."""

from __future__ import annotations

import bisect
import operator
from collections.abc import Iterable, Mapping, Sequence

from aura_ums._validate import finite_float, items_of
from aura_ums.errors import InputError
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineObservation,
    Observation,
    RangeBearingObservation,
)

_OBSERVATION_TYPES = (BearingObservation, RangeBearingObservation, GroundLineObservation)


# The sort key of the buffer: attrgetter runs in C, cheaper than a function per comparison.
_time = operator.attrgetter("time")


class IdentifiedLandmarkBuffer:
    """A time-ordered buffer of identified-landmark observations (the paper's identified landmark buffer).

    Find-landmark schemas :meth:`post` an observation each time they identify a landmark
    (on the frame that confirms a discovery and on every tracking frame); the uncertainty
    map manager :meth:`drain` s them in time order, after growing the map to their time.

    The buffer is mutable on purpose: it is the one place where producers (schemas) and
    the consumer (the map manager) meet, so it must change as they post and drain. What
    it holds and returns are immutable observations. It is not thread-safe: guard it with
    a lock if schemas and the manager run in different threads.

    Observations posted out of time order are allowed (frames from several cameras, or a
    schema that reports late) and are inserted in their place; observations with equal
    times stay in the order they were posted.

    Parameters
    ----------
    observations : iterable of BearingObservation, RangeBearingObservation or GroundLineObservation
        Observations to start with, posted in turn.

    Raises
    ------
    InputError
        When something other than an observation is posted.

    Examples
    --------
    >>> from aura_ums.uncertainty import BearingObservation
    >>> buffer = IdentifiedLandmarkBuffer()
    >>> buffer.post(BearingObservation("lamppost_107", 2.0, 0.1, 0.01))
    >>> buffer.post(BearingObservation("telephone_pole_12", 1.0, 0.5, 0.01))   # late: sorted in
    >>> len(buffer), [o.landmark_id for o in buffer.peek()]
    (2, ['telephone_pole_12', 'lamppost_107'])
    >>> [o.time for o in buffer.drain(until=1.5)], len(buffer)
    ([1.0], 1)
    >>> buffer.drain(until=0.0)                  # nothing that old: nothing removed
    ()
    >>> buffer.post("lamppost_107")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: observation: expected a BearingObservation, RangeBearingObservation \
or GroundLineObservation, got str
    """

    __slots__ = ("_items",)

    def __init__(self, observations: Iterable[Observation] = ()) -> None:
        self._items: list[Observation] = []
        if isinstance(observations, _OBSERVATION_TYPES):
            raise InputError(
                f"observations: expected an iterable of observations, got one {type(observations).__name__}"
            )
        if isinstance(observations, Mapping):
            # Iterating a dict gives its keys: an empty one was taken as no observation.
            raise InputError(
                f"observations: expected an iterable of observations, got {type(observations).__name__}"
            )
        for observation in items_of(observations, "observations", "an iterable of observations"):
            self.post(observation)

    def post(self, observation: Observation) -> None:
        """Add an observation in its place by time (after those with the same time).

        Parameters
        ----------
        observation : BearingObservation, RangeBearingObservation or GroundLineObservation
            What a find-landmark schema identified, with its ``time`` stamp.
        """
        if not isinstance(observation, _OBSERVATION_TYPES):
            raise InputError(
                "observation: expected a BearingObservation, RangeBearingObservation or "
                f"GroundLineObservation, got {type(observation).__name__}"
            )
        items = self._items
        if not items or items[-1].time <= observation.time:
            items.append(observation)  # in time order, the usual case: where insort_right puts it
        else:
            bisect.insort_right(items, observation, key=_time)

    def _post_in_order(self, observations: Sequence[Observation]) -> None:
        """:meth:`post` of each of ``observations``, known to be observations in time order (a frame).

        Appended in one call when none is older than those held (the usual case), else
        posted one by one.
        """
        items = self._items
        if not observations:
            return
        if items and observations[0].time < items[-1].time:
            for observation in observations:
                self.post(observation)
            return
        items += observations

    def drain(self, until: float | None = None) -> tuple[Observation, ...]:
        """Remove and return the observations with ``time <= until``, in time order.

        Parameters
        ----------
        until : float or None
            Latest time to take, seconds; None takes everything.

        Returns
        -------
        tuple
            The observations removed, oldest first (empty when there are none).
        """
        stop = self._stop(until)
        taken = tuple(self._items[:stop])
        del self._items[:stop]
        return taken

    def _drop_first(self, count: int) -> None:
        """Remove the ``count`` oldest observations: :meth:`drain` of what :meth:`peek` just returned."""
        del self._items[:count]

    def peek(self, until: float | None = None) -> tuple[Observation, ...]:
        """Return what :meth:`drain` would, without removing anything."""
        return tuple(self._items[: self._stop(until)])

    @property
    def earliest_time(self) -> float | None:
        """Time of the oldest observation held, seconds; None when the buffer is empty."""
        return self._items[0].time if self._items else None

    def _stop(self, until: float | None) -> int:
        if until is None:
            return len(self._items)
        limit = finite_float(until, "until")
        return bisect.bisect_right(self._items, limit, key=_time)

    def __len__(self) -> int:
        return len(self._items)

    def __bool__(self) -> bool:
        return bool(self._items)

    def __repr__(self) -> str:
        if not self._items:
            return "IdentifiedLandmarkBuffer(empty)"
        first, last = self._items[0].time, self._items[-1].time
        return f"IdentifiedLandmarkBuffer({len(self._items)} observations, t={first:g}..{last:g})"
