from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.manager import IdentifiedLandmarkBuffer
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineObservation,
    Observation,
    RangeBearingObservation,
)


def bearing(landmark_id: str, time: float) -> BearingObservation:
    return BearingObservation(landmark_id, time, 0.1, 0.01)


def test_drain_returns_in_time_order_and_removes() -> None:
    buffer = IdentifiedLandmarkBuffer()
    buffer.post(bearing("a", 3.0))
    buffer.post(RangeBearingObservation("b", 1.0, 0.0, 0.01, 4.0, 5.0))
    buffer.post(GroundLineObservation("c", 2.0, 1.0, 0.1, 0.0, 0.05))
    assert len(buffer) == 3
    assert buffer.earliest_time == 1.0
    drained = buffer.drain(until=2.0)
    assert isinstance(drained, tuple)
    assert [o.landmark_id for o in drained] == ["b", "c"]
    assert len(buffer) == 1
    assert [o.time for o in buffer.drain()] == [3.0]
    assert len(buffer) == 0
    assert not buffer
    assert buffer.earliest_time is None
    assert buffer.drain() == ()


def test_until_is_inclusive_and_older_than_everything_takes_nothing() -> None:
    buffer = IdentifiedLandmarkBuffer([bearing("a", 1.0), bearing("b", 2.0)])
    assert buffer.drain(until=0.5) == ()
    assert len(buffer) == 2
    assert [o.landmark_id for o in buffer.drain(until=1.0)] == ["a"]


def test_out_of_order_posts_are_sorted_and_ties_keep_posting_order() -> None:
    rng = np.random.default_rng(7)
    times = rng.integers(0, 10, size=60).astype(float)
    buffer = IdentifiedLandmarkBuffer()
    posted: list[Observation] = []
    for k, t in enumerate(times):
        observation = bearing(f"lm{k}", float(t))
        buffer.post(observation)
        posted.append(observation)
    expected = sorted(posted, key=lambda o: o.time)  # sorted() is stable: ties in posting order
    assert list(buffer.peek()) == expected
    assert list(buffer.drain(until=4.0)) == [o for o in expected if o.time <= 4.0]
    assert list(buffer.drain()) == [o for o in expected if o.time > 4.0]


def test_observations_in_order_are_posted_in_one_call_as_one_by_one() -> None:
    rng = np.random.default_rng(11)
    frames = [
        [bearing(f"lm{k}{j}", float(t)) for j in range(3)] for k, t in enumerate(rng.integers(0, 10, 12))
    ]
    buffer, one_by_one = IdentifiedLandmarkBuffer(), IdentifiedLandmarkBuffer()
    for frame in frames:  # some older than those held: posted in their place
        buffer._post_in_order(frame)
        for observation in frame:
            one_by_one.post(observation)
        assert buffer.peek() == one_by_one.peek()
    buffer._post_in_order([])
    assert buffer.peek() == one_by_one.peek()


def test_peek_does_not_remove() -> None:
    buffer = IdentifiedLandmarkBuffer([bearing("a", 1.0), bearing("b", 5.0)])
    assert [o.landmark_id for o in buffer.peek(until=2.0)] == ["a"]
    assert [o.landmark_id for o in buffer.peek()] == ["a", "b"]
    assert len(buffer) == 2


def test_returned_observations_are_immutable() -> None:
    buffer = IdentifiedLandmarkBuffer([bearing("a", 1.0)])
    (observation,) = buffer.drain()
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign"):
        observation.time = 5.0  # type: ignore[misc]


def test_repr_mentions_count_and_times() -> None:
    assert repr(IdentifiedLandmarkBuffer()) == "IdentifiedLandmarkBuffer(empty)"
    text = repr(IdentifiedLandmarkBuffer([bearing("a", 1.0), bearing("b", 2.5)]))
    assert "2 observations" in text
    assert "1..2.5" in text


def test_rejects_what_is_not_an_observation() -> None:
    buffer = IdentifiedLandmarkBuffer()
    with pytest.raises(InputError, match=r"observation: expected a BearingObservation.*got tuple"):
        buffer.post(("a", 1.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="until: expected a finite number, got nan"):
        buffer.drain(until=float("nan"))
    with pytest.raises(InputError, match="until: expected a finite number, got 'soon'"):
        buffer.peek(until="soon")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="observations: expected an iterable of observations, got one"):
        IdentifiedLandmarkBuffer(bearing("a", 1.0))  # type: ignore[arg-type]
    # A dict iterates its keys: an empty one was taken as no observation, a full one failed on a key.
    with pytest.raises(InputError, match=r"^observations: expected an iterable of observations, got dict$"):
        IdentifiedLandmarkBuffer({})
