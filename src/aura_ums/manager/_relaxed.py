"""The q-relaxed intersection: branches of the map, each excluding at most q of the latest N sightings.

A *sighting* is an observation that passed the manager's checks and met the map; each gets
a serial number. The window holds the latest ``N`` sightings. A *branch* is a map and the
set of sightings of the window it excludes (at most ``q``, its *choices*), plus the
sightings it *carries*: later sightings of a landmark whose sighting it chose to exclude,
while that one is in the window. Its map holds the poses consistent with every sighting
but those (and, after merges, an outer bound of that).

- A new sighting reduces every branch (a branch it empties dies), unless the branch has
  chosen to exclude a sighting of the same landmark still in the window: then the branch
  carries it (one wrong identity is not trusted again while its wrong sighting is in view
  of the window; a misread barcode tends to repeat). From each branch with fewer than ``q``
  choices it spawns a copy that excludes it (the sightings of one landmark in one instant
  go together: one choice, the rest carried), unless the reduction left the branch as it
  was (the copy would add nothing).
- When a sighting leaves the window, each branch forgets it (its choices and carried
  sightings without it); branches left with the same sets merge (an outer bound: hull of
  polygons, union of headings).
- Growth applies to every branch and ends what each carries (see :func:`grow`); branches
  then left with the same choices merge, as on a departure. The reported map is the outer
  bound of all branches.

Guarantee: the truth stays inside whenever the wrong sightings among any ``N`` consecutive
ones name at most ``q`` landmarks; in particular whenever at most ``q`` of any ``N``
consecutive sightings are wrong (and the growth and the correct sightings' bounds hold).
Invariant, by induction over sightings: some branch holds the truth whose choices are
sightings of the window of distinct landmarks, each with a wrong sighting of its landmark
in its instant. Growth keeps it, or merges it (an outer bound) with the branches left with
its choices; a departing sighting only merges it into a branch with the same property (a
merge never drops a map: two branches with the same sets are one hypothesis); a correct arrival reduces
it soundly or is carried (ignoring a sighting only loosens); a wrong arrival of a landmark
it chose in the window is carried; a wrong arrival of another landmark finds it with fewer
than ``q`` choices (they and the arrival are wrong sightings of distinct landmarks in ``N``
consecutive ones), so its copy excluding the arrival exists, or the reduction left it
unchanged. Nothing here needs more: ``q`` and ``N`` bound the branch count by the sum of
``C(N, k)`` for ``k <= q``.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from aura_ums.uncertainty import Observation, SpatialUncertaintyMap, union_of_maps

#: Reduce a map by the sightings of an instant at these indices; None when no pose agrees.
Reducer = Callable[[SpatialUncertaintyMap, Sequence[int]], SpatialUncertaintyMap | None]


@dataclass(frozen=True, slots=True)
class Branch:
    """One hypothesis of the relaxed intersection: the sightings it excludes, and its map.

    ``excluded`` are its choices (at most ``q``); ``carried`` the sightings it ignores
    because it chose to exclude a sighting of their landmark (see the module notes).
    """

    excluded: frozenset[int]
    map: SpatialUncertaintyMap
    carried: frozenset[int] = frozenset()

    @property
    def ignored(self) -> frozenset[int]:
        """Every sighting of the window whose bounds its map need not respect: chosen or carried."""
        return self.excluded | self.carried


@dataclass(frozen=True, slots=True)
class Sighting:
    """A sighting of the window: its serial number and the observation."""

    serial: int
    observation: Observation


@dataclass(frozen=True, slots=True)
class RelaxedState:
    """The branches, the window of the latest sightings, and which of them were reported excluded.

    ``branches`` is never empty and is kept in :func:`_order`: the first is the primary
    one (fewest exclusions; among equals, the latest exclusions first), whose centre and
    most probable heading the reported map takes.
    """

    branches: tuple[Branch, ...]
    window: tuple[Sighting, ...]
    reported: frozenset[int]
    next_serial: int

    @classmethod
    def start(cls, uncertainty_map: SpatialUncertaintyMap, next_serial: int = 0) -> RelaxedState:
        """Return one branch excluding nothing, an empty window."""
        return cls((Branch(frozenset(), uncertainty_map),), (), frozenset(), next_serial)

    @property
    def primary(self) -> SpatialUncertaintyMap:
        """The map of the branch with the fewest exclusions."""
        return self.branches[0].map


def _order(branch: Branch) -> tuple[int, tuple[int, ...]]:
    return len(branch.excluded), tuple(sorted(-serial for serial in branch.excluded))


def _sorted(branches: Sequence[Branch]) -> tuple[Branch, ...]:
    return tuple(sorted(branches, key=_order))


def grow(
    state: RelaxedState,
    grow_map: Callable[[SpatialUncertaintyMap], SpatialUncertaintyMap],
    max_vertices: int,
) -> RelaxedState:
    """Return the state with every branch's map grown by ``grow_map``; the branches carry nothing after.

    Dropping what a branch carries is what keeps the branch count within the sum of
    ``C(N, k)``: branches with the same choices could otherwise differ only in what they
    carry, and none would ever merge. Those left with the same choices merge here (the
    outer bound of their grown maps, the first in order's centre kept): each may be the
    one that holds the truth. It is sound: a carried sighting was never applied to the
    branch's map, so forgetting it only spares the merge its leaving would have made (the
    map stays an outer bound of what it claims).
    """
    grown = [((branch.excluded, frozenset[int]()), grow_map(branch.map)) for branch in state.branches]
    joined = _joined(grown, max_vertices)
    # In order still: the branches' choices are as they were, and only equal ones merged.
    return dataclasses.replace(
        state, branches=tuple(Branch(excluded, found) for (excluded, _), found in joined.items())
    )


def admit(
    state: RelaxedState, observations: Sequence[Observation], window: int, max_vertices: int
) -> tuple[RelaxedState, tuple[int, ...]]:
    """Slide the window to make room for ``observations`` (at most ``window``), then append them.

    Every sighting that leaves merges the branches excluding it into the branches with
    the same set minus it. Returns the state and the new sightings' serials.
    """
    kept = list(state.window)
    branches = list(state.branches)
    reported = state.reported
    while kept and len(kept) + len(observations) > window:
        leaving = kept.pop(0).serial
        reported = reported - {leaving}
        if any(leaving in branch.ignored for branch in branches):
            branches = _merged(branches, leaving, max_vertices)
    serials = tuple(range(state.next_serial, state.next_serial + len(observations)))
    kept += [Sighting(serial, observation) for serial, observation in zip(serials, observations, strict=True)]
    return (
        RelaxedState(_sorted(branches), tuple(kept), reported, state.next_serial + len(observations)),
        serials,
    )


def _merged(branches: Sequence[Branch], leaving: int, max_vertices: int) -> list[Branch]:
    """Forget ``leaving`` in every branch; merge the branches then left with the same sets."""
    # The branches that ignore it last: each joins the one already left with its sets.
    keyed = [
        ((branch.excluded - {leaving}, branch.carried - {leaving}), branch.map)
        for branch in sorted(branches, key=lambda branch: leaving in branch.ignored)
    ]
    return [
        Branch(excluded, found, carried)
        for (excluded, carried), found in _joined(keyed, max_vertices).items()
    ]


_Key = tuple[frozenset[int], frozenset[int]]


def _joined(
    keyed: Iterable[tuple[_Key, SpatialUncertaintyMap]], max_vertices: int
) -> dict[_Key, SpatialUncertaintyMap]:
    """Return one map per key (its choices and carried sightings), in the order keys first come.

    Maps of one key join in their outer bound, pairwise in order: two branches with the
    same sets are one hypothesis, and either may hold the truth (one must not replace the
    other).
    """
    by_set: dict[_Key, SpatialUncertaintyMap] = {}
    for key, found in keyed:
        there = by_set.get(key)
        by_set[key] = found if there is None else union_of_maps([there, found], max_vertices=max_vertices)
    return by_set


def relax(state: RelaxedState, serials: Sequence[int], q: int, reduce: Reducer) -> RelaxedState | None:
    """Return the state after an instant's sightings (``serials``, already admitted); None if all die.

    A branch carries the new sightings of the landmarks it chose to exclude in the window.
    For the others, grouped by landmark, each branch with ``k`` choices has a child for each
    set of at most ``q - k`` groups: the branch reduced by the other sightings, excluding
    the set's (one choice per group, the rest carried). A child whose reduction is empty
    dies; a child whose map is that of a child with fewer choices (the reduction changed
    nothing) adds nothing and is dropped.
    """
    landmark_of = {sighting.serial: sighting.observation.landmark_id for sighting in state.window}
    children: list[Branch] = []
    for branch in state.branches:
        chosen = {landmark_of[serial] for serial in branch.excluded}
        carry = [index for index, serial in enumerate(serials) if landmark_of[serial] in chosen]
        groups: dict[str, list[int]] = {}
        for index, serial in enumerate(serials):
            if index not in carry:
                groups.setdefault(landmark_of[serial], []).append(index)
        room = q - len(branch.excluded)
        made: list[tuple[frozenset[int], SpatialUncertaintyMap]] = []
        for size in range(min(room, len(groups)) + 1):
            for dropped in itertools.combinations(groups.values(), size):
                ignored = set(carry).union(*dropped)
                keep = [index for index in range(len(serials)) if index not in ignored]
                reduced = reduce(branch.map, keep) if keep else branch.map
                if reduced is None:
                    continue
                excluded = branch.excluded | {serials[group[0]] for group in dropped}
                if any(other is reduced and smaller <= excluded for smaller, other in made):
                    continue
                made.append((excluded, reduced))
                carried = branch.carried | {serials[index] for index in ignored} - excluded
                children.append(Branch(excluded, reduced, frozenset(carried)))
    if not children:
        return None
    return dataclasses.replace(state, branches=_sorted(children))


def newly_excluded(state: RelaxedState) -> tuple[RelaxedState, tuple[Observation, ...]]:
    """Return the sightings that every branch now excludes and were not reported yet.

    A sighting of the window is *excluded* when every surviving branch ignores it (chose
    to exclude it, or carries it): no pose the manager still keeps had to agree with it.
    Until it leaves the window no branch respecting it can come back (children only add
    to what they ignore), so each is reported once.
    """
    common = frozenset.intersection(*(branch.ignored for branch in state.branches))
    fresh = common - state.reported
    if not fresh:
        return state, ()
    found = tuple(sighting.observation for sighting in state.window if sighting.serial in fresh)
    return dataclasses.replace(state, reported=state.reported | fresh), found


def outer_map(state: RelaxedState, max_vertices: int) -> SpatialUncertaintyMap:
    """Return the outer bound of every branch's map, the primary branch's centre and heading kept."""
    return union_of_maps([branch.map for branch in state.branches], max_vertices=max_vertices)
