"""The Codac box localizer: sound under bounded noise, relaxed intersection, re-initialisation, the extra."""

from __future__ import annotations

import ctypes
import ctypes.util
import gc
import math
import sys

import numpy as np
import pytest

from aura_ums.baselines import CodacLocalizer, Estimator, codac_available
from aura_ums.errors import InputError, MissingDependencyError
from aura_ums.uncertainty import (
    BearingObservation,
    Pose,
    RangeBearingObservation,
    TerrainTable,
    TurnAndRun,
)

LANDMARKS = ((12.0, 4.0), (4.0, 14.0), (-6.0, 6.0), (6.0, -4.0))
BEARING_ERROR = 0.03
RANGE_ERROR = 0.3
SIGMAS = 3.0
FENV = ctypes.CDLL(ctypes.util.find_library("m") or None)
# Everything but the test of the missing extra needs Codac; CI installs it (make test).
CODAC = codac_available()
needs_codac = pytest.mark.skipif(not CODAC, reason="the codac extra is not installed: aura-ums[codac]")

Observed = BearingObservation | RangeBearingObservation


def observed(
    truth: Pose, landmark: tuple[float, float], rng: np.random.Generator, *, ranged: bool, wrong: bool = False
) -> Observed:
    """An observation whose errors lie inside its bounds (uniform), or far outside them when ``wrong``."""
    dx, dy = landmark[0] - truth.x, landmark[1] - truth.y
    bearing = math.atan2(dy, dx) - truth.heading + float(rng.uniform(-BEARING_ERROR, BEARING_ERROR))
    if wrong:
        bearing += math.pi / 2
    if not ranged:
        return BearingObservation("lm", 0.0, bearing, BEARING_ERROR)
    distance = math.hypot(dx, dy) + float(rng.uniform(-RANGE_ERROR, RANGE_ERROR))
    return RangeBearingObservation(
        "lm", 0.0, bearing, BEARING_ERROR, max(distance - RANGE_ERROR, 0.0), distance + RANGE_ERROR
    )


def drive(
    seed: int, *, ranged: bool, q: int = 0, window: int = 10, wrong_every: int = 0
) -> tuple[list[bool], CodacLocalizer]:
    """Drive a loop on tile, normals truncated at SIGMAS; return whether the box held the truth, each step."""
    rng = np.random.default_rng(seed)
    tile = TerrainTable.default()["tile"]
    truth = Pose(0.0, 0.0, 0.0)
    box = CodacLocalizer(
        truth, position_halfwidth=0.1, heading_halfwidth=0.02, sigmas=SIGMAS, q=q, window=window
    )
    inside: list[bool] = []
    sightings = 0
    for step in range(30):
        command = TurnAndRun(0.5 if step % 5 == 4 else 0.0, 1.5)
        truth = tile.sample_motion(truth, command, rng, truncate=SIGMAS)
        box.predict(command, tile)
        for landmark in LANDMARKS[step % 2 :: 2]:
            sightings += 1
            wrong = wrong_every > 0 and sightings % wrong_every == 0
            box.update(observed(truth, landmark, rng, ranged=ranged, wrong=wrong), landmark)
        inside.append(bool(box.region().contains(truth.x, truth.y, truth.heading)))
    return inside, box


@needs_codac
@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("ranged", [True, False])
def test_the_box_holds_the_truth_under_bounded_noise(seed: int, ranged: bool) -> None:
    inside, box = drive(seed, ranged=ranged)
    assert all(inside)
    assert box.reinitialisations == 0


@needs_codac
def test_the_observations_shrink_the_box() -> None:
    _, observed_box = drive(1, ranged=True)
    blind = CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.02)
    tile = TerrainTable.default()["tile"]
    for step in range(30):
        blind.predict(TurnAndRun(0.5 if step % 5 == 4 else 0.0, 1.5), tile)
    assert observed_box.region().area < 0.1 * blind.region().area


@needs_codac
@pytest.mark.parametrize("seed", range(4))
def test_the_relaxed_intersection_survives_one_wrong_sighting_in_five(seed: int) -> None:
    inside, box = drive(seed, ranged=True, q=1, window=5, wrong_every=5)
    assert all(inside)
    assert box.reinitialisations == 0


@needs_codac
def test_without_relaxation_wrong_sightings_empty_the_box_and_count() -> None:
    _, box = drive(0, ranged=True, q=0, window=5, wrong_every=5)
    assert box.reinitialisations > 0


@needs_codac
def test_a_contradicting_observation_reinitialises_around_the_landmark() -> None:
    box = CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.01)
    # Truth is really at (20, 0) heading pi/2: the landmark (20, 5) is straight ahead, 5 m away.
    seen = RangeBearingObservation("lm", 0.0, 0.0, 0.02, 4.9, 5.1)
    assert box.update(seen, (20.0, 5.0)) is False
    assert (box.reinitialisations, box.rejected_count) == (1, 1)
    region = box.region()
    assert region.contains(20.0, 0.0, math.pi / 2)
    assert not region.contains(0.0, 0.0, 0.0)


@needs_codac
def test_a_contradicting_bearing_keeps_the_position_and_frees_the_heading() -> None:
    box = CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.01)
    behind = BearingObservation("lm", 0.0, math.pi, 0.02)  # the landmark ahead seen behind: heading pi
    assert box.update(behind, (10.0, 0.0)) is False
    (x0, x1), (y0, y1), _ = box.box
    assert (x0, x1, y0, y1) == pytest.approx((-0.1, 0.1, -0.1, 0.1))
    assert box.region().contains(0.0, 0.0, math.pi)


@needs_codac
def test_it_is_an_estimator_and_its_box_is_its_region() -> None:
    box = CodacLocalizer(Pose(1.0, 2.0, 3.1), position_halfwidth=0.5, heading_halfwidth=0.1)
    assert isinstance(box, Estimator)
    region = box.region(0.9)
    assert region.area == pytest.approx(1.0)
    assert region.heading_width == pytest.approx(0.2)
    assert region.contains(1.0, 2.0, -math.pi + 0.05)  # across the +-pi seam
    mean = box.mean
    assert (mean.x, mean.y, mean.heading) == pytest.approx((1.0, 2.0, 3.1))


@needs_codac
def test_codac_leaves_the_callers_rounding_mode() -> None:
    before = FENV.fegetround()
    box = CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.01)
    box.predict(TurnAndRun(0.3, 2.0), TerrainTable.default()["tile"])
    box.update(BearingObservation("lm", 0.0, 0.5, 0.02), (10.0, 5.0))
    box.region()
    assert FENV.fegetround() == before
    assert 0.1 + 0.2 == 0.30000000000000004


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"q": -1}, r"q: expected an integer >= 0, got -1"),
        ({"q": 3, "window": 3}, r"window: expected an integer > q \(3\), got 3"),
        ({"sigmas": 0.0}, r"sigmas: expected a number in \[0\.1, 100\], got 0\.0"),
        ({"position_halfwidth": -1.0}, r"position_halfwidth: expected a non-negative number, got -1.0"),
    ],
)
@needs_codac
def test_bad_settings_are_refused(arguments: dict[str, float], message: str) -> None:
    settings: dict[str, float] = {"position_halfwidth": 0.1, "heading_halfwidth": 0.01, **arguments}
    with pytest.raises(InputError, match=message):
        CodacLocalizer(Pose(0, 0, 0), **settings)  # type: ignore[arg-type]


@needs_codac
def test_the_contractors_handed_to_codac_do_not_pile_up() -> None:
    # A Python contractor passed to Codac is never freed: one built per sighting and update
    # grew a 250,000-observation comparison to 2.8 GB. The window's pool is all there is.
    from aura_ums.baselines._codac import _contractor_class, codac_module

    contractor = _contractor_class(codac_module())

    def alive() -> int:
        gc.collect()
        return sum(isinstance(item, contractor) for item in gc.get_objects())

    before = alive()
    _, box = drive(0, ranged=True, q=1, window=6, wrong_every=5)
    assert alive() - before == 6
    assert box.region().area > 0.0


@needs_codac
def test_bad_updates_are_refused() -> None:
    box = CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.01)
    with pytest.raises(InputError, match="observation: expected a BearingObservation"):
        box.update("north", (1.0, 2.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"landmark_xy: expected \(x, y\)"):
        box.update(BearingObservation("lm", 0.0, 0.5, 0.02), (1.0, math.nan))
    with pytest.raises(InputError, match="command: expected a TurnAndRun"):
        box.predict((0.0, 1.0), TerrainTable.default()["tile"])  # type: ignore[arg-type]


def test_without_codac_the_localizer_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "codac", None)  # an import of codac now fails
    assert codac_available() is False
    with pytest.raises(MissingDependencyError, match=r"import of codac failed.*install aura-ums\[codac\]"):
        CodacLocalizer(Pose(0, 0, 0), position_halfwidth=0.1, heading_halfwidth=0.01)
    monkeypatch.undo()
    assert codac_available() is CODAC
