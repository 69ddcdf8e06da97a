from __future__ import annotations

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.sim import Building, GroundPatch, GroundStripe, Pole, Scene, ground_texture, random_clutter
from aura_ums.world import sample_world


def test_paper_map_becomes_poles_a_building_patches_and_edges() -> None:
    world = sample_world("paper_sidewalk")
    scene = Scene.from_meadow_map(world, np.random.default_rng(0), pole_radius=0.2, clutter=5)
    assert [(p.id, p.radius, p.z_top) for p in scene.poles] == [
        ("telephone_pole_12", 0.2, 9.0),
        ("lamppost_107", 0.2, 4.5),
    ]
    (building,) = scene.buildings
    # the Class I edge at the Class II corner is the building's corner, not a pole
    assert building.id == "east_engineering_corner"
    assert building.z_top == 7.0
    assert [24.5, 5.0] in building.footprint.tolist()
    # the box extends away from the map's centre, so its corner faces the walk
    assert building.footprint[:, 0].min() == 24.5
    assert building.footprint[:, 1].min() == 5.0
    assert len(scene.patches) == len(world.meadows)
    assert [s.id for s in scene.stripes[:2]] == ["sidewalk_north_edge", "sidewalk_south_edge"]
    assert len(scene.stripes) == 2 + 5


def test_terrains_get_their_shades() -> None:
    world = sample_world("paper_sidewalk")
    scene = Scene.from_meadow_map(world, np.random.default_rng(0), terrain_shades={"concrete": 200.0})
    shades = {meadow.terrain: patch.shade for meadow, patch in zip(world.meadows, scene.patches, strict=True)}
    assert shades == {"concrete": 200.0, "grass": 120.0, "gravel": 120.0}


def test_building_walls_alternate_in_shade() -> None:
    triangle = Building([(0, 0), (4, 0), (0, 3)], 0.0, 2.0, shades=(200.0, 100.0))
    assert [triangle.wall_shade(i) for i in range(3)] == [200.0, 100.0, 150.0]
    clockwise = Building([(0, 0), (0, 3), (4, 3), (4, 0)], 0.0, 2.0)
    assert clockwise.footprint.tolist() == [[4.0, 0.0], [4.0, 3.0], [0.0, 3.0], [0.0, 0.0]]
    assert not clockwise.footprint.flags.writeable


def test_ground_stripe_polygon_has_its_width() -> None:
    stripe = GroundStripe((0.0, 0.0), (10.0, 0.0), 0.2, 220.0)
    assert stripe.polygon().tolist() == [[0.0, -0.1], [10.0, -0.1], [10.0, 0.1], [0.0, 0.1]]


def test_clutter_is_deterministic_per_seed_and_inside_the_bounds() -> None:
    a = random_clutter((0.0, 0.0, 20.0, 10.0), 50, np.random.default_rng(4))
    b = random_clutter((0.0, 0.0, 20.0, 10.0), 50, np.random.default_rng(4))
    assert [s.start.tolist() for s in a] == [s.start.tolist() for s in b]
    centres = np.array([0.5 * (s.start + s.end) for s in a])
    assert np.all((centres >= [0.0, 0.0]) & (centres <= [20.0, 10.0]))


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: Pole(0.0, 0.0, 0.0, 2.0, -0.1), r"Pole.radius: expected a positive number, got -0.1"),
        (
            lambda: Pole(0.0, 0.0, 0.0, 2.0, 0.1, shade=300.0),
            r"Pole.shade: expected a gray level in \[0, 255\]",
        ),
        (lambda: Building([(0, 0), (2, 0), (1, 1), (2, 2), (0, 2)], 0.0, 2.0), "expected a convex polygon"),
        (lambda: Building([(0, 0), (2, 0), (0, 2)], 2.0, 2.0), r"Building.z_top: expected > z_bottom"),
        (lambda: GroundStripe((1.0, 1.0), (1.0, 1.0), 0.1, 100.0), "expected a point distinct from start"),
        (lambda: GroundPatch([(0, 0), (1, 0)], 100.0), "GroundPatch.polygon: expected at least 3 points"),
        (lambda: Scene(poles=(3,)), r"Scene.poles\[0\]: expected a Pole"),  # type: ignore[arg-type]
        (lambda: Scene(texture=np.zeros((6, 6), np.float32)), "side is a power of two"),
        (lambda: ground_texture(np.random.default_rng(0), size=100), "size: expected a power of two >= 4"),
        (
            lambda: ground_texture(np.random.default_rng(0), size=2**63),
            r"size: expected at most 4096 cells \(a 4096-cell tile takes about 5 s and 0.5 GB",
        ),
        (
            lambda: ground_texture(np.random.default_rng(0), size=64, smoothing=1e6),
            r"smoothing: expected a number in \[0, 100\] px, got 1000000.0",
        ),
        (
            lambda: ground_texture(np.random.default_rng(0), size=64, smoothing=-1.0),
            r"smoothing: expected a number in \[0, 100\] px, got -1.0",
        ),
        (
            lambda: Building(np.array([(0, 0), (1, 0), (1, 1), (0, 1)]) * 1e300, 0.0, 5.0),
            r"Building.footprint: expected coordinates a number in \[-1e\+06, 1e\+06\] m, got \[1e\+300, 0",
        ),
        (
            lambda: random_clutter(None, 5, np.random.default_rng(0)),  # type: ignore[arg-type]
            r"bounds: expected \(x_min, y_min, x_max, y_max\) in metres, got NoneType",
        ),
        (
            lambda: random_clutter((0.0, 0.0), 5, np.random.default_rng(0)),  # type: ignore[arg-type]
            r"bounds: expected \(x_min, y_min, x_max, y_max\) in metres, got \(0.0, 0.0\)",
        ),
        (
            lambda: random_clutter((0.0, 0.0, 1e300, 1.0), 5, np.random.default_rng(0)),
            r"bounds: expected a number in \[-1e\+06, 1e\+06\] m, got 1e\+300",
        ),
        (
            lambda: random_clutter((0.0, 0.0, 10.0, 10.0), 10**12, np.random.default_rng(0)),
            r"count: expected at most 10,000,000 strips \(about 400 bytes each: 4 GB\), got 1000000000000",
        ),
        (
            lambda: Building.from_corner(0.0, 0.0, 3.0, width=0.0, depth=1.0),
            "width: expected a positive number",
        ),
    ],
)
def test_bad_values_are_refused(make: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        make()  # type: ignore[operator]
