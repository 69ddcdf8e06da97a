from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums import (
    FileFormatError,
    InputError,
    Pose,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    UnknownTerrainError,
)

FIELDS = TerrainStats.field_names()


def stats(**overrides: float) -> TerrainStats:
    values = dict.fromkeys(FIELDS, 0.0)
    values.update(overrides)
    return TerrainStats(**values)


# --- the generative model ----------------------------------------------------------------------


def test_mean_translational_loss_matches_the_paper_example(rng: np.random.Generator) -> None:
    # "if the mean translational loss is 0.10 and the robot is commanded to move 20.0 feet,
    # the mean distance actually traveled would be 18.0 feet"
    terrain = stats(translation_loss=0.10, translation_sd=0.02)
    poses = terrain.sample_motions(np.zeros((50_000, 3)), TurnAndRun(0.0, 20.0), rng)
    assert np.mean(poses[:, 0]) == pytest.approx(18.0, abs=0.01)
    assert np.std(poses[:, 0]) == pytest.approx(0.4, rel=0.02)


def test_never_farther_or_more_turned_than_commanded(rng: np.random.Generator) -> None:
    terrain = stats(translation_sd=0.5, rotation_sd=0.5)
    poses = terrain.sample_motions(np.zeros((20_000, 3)), TurnAndRun(1.0, 10.0), rng)
    assert np.all(np.hypot(poses[:, 0], poses[:, 1]) <= 10.0 + 1e-12)
    assert np.all(poses[:, 2] <= 1.0 + 1e-12)
    assert np.all(poses[:, 2] >= 0.0)


def test_inertial_loss_is_independent_of_distance(rng: np.random.Generator) -> None:
    terrain = stats(translation_inertial_loss=0.25)
    for run in (1.0, 100.0):
        pose = terrain.sample_motion(Pose(0, 0, 0), TurnAndRun(0.0, run), rng)
        assert pose.x == pytest.approx(run - 0.25)
    # A run shorter than the inertial loss goes nowhere, never backwards.
    assert terrain.sample_motion(Pose(0, 0, 0), TurnAndRun(0.0, 0.1), rng).x == 0.0


def test_rotation_loss_and_skitter(rng: np.random.Generator) -> None:
    terrain = stats(rotation_loss=0.1, skitter=0.02)
    poses = terrain.sample_motions(np.zeros((1000, 3)), TurnAndRun(math.pi / 2, 0.0), rng)
    assert np.allclose(poses[:, 2], 0.9 * math.pi / 2)
    displacement = np.hypot(poses[:, 0], poses[:, 1])
    assert np.allclose(displacement, 0.02 * math.pi / 2)
    # Skitter goes in every direction, so it does not move the mean.
    assert abs(np.mean(poses[:, 0])) < 0.003
    assert abs(np.mean(poses[:, 1])) < 0.003


def test_drift_bends_the_run_into_an_arc(rng: np.random.Generator) -> None:
    terrain = stats(drift=0.05)
    poses = terrain.sample_motions(np.zeros((5000, 3)), TurnAndRun(0.0, 10.0), rng)
    # Heading change within drift * run either side, spread uniformly.
    assert np.max(np.abs(poses[:, 2])) <= 0.5 + 1e-12
    assert np.max(np.abs(poses[:, 2])) > 0.49
    # The end lies on the arc: the chord subtends half the heading change.
    assert np.allclose(np.arctan2(poses[:, 1], poses[:, 0]), poses[:, 2] / 2)
    chord = np.hypot(poses[:, 0], poses[:, 1])
    assert np.all(chord <= 10.0 + 1e-12)
    assert np.allclose(chord, 10.0 * np.sinc(poses[:, 2] / (2 * math.pi)))


def test_truncation_clips_the_normals(rng: np.random.Generator) -> None:
    terrain = stats(translation_sd=0.1)
    poses = terrain.sample_motions(np.zeros((20_000, 3)), TurnAndRun(0.0, 10.0), rng, truncate=1.0)
    assert np.min(poses[:, 0]) == pytest.approx(9.0)
    assert np.max(poses[:, 0]) == pytest.approx(10.0)
    with pytest.raises(InputError, match=r"truncate: expected a positive finite number or None"):
        terrain.sample_motions(np.zeros((1, 3)), TurnAndRun(0.0, 1.0), rng, truncate=-1.0)


def test_same_seed_same_outcome() -> None:
    terrain = TerrainTable.default()["grass"]
    a = terrain.sample_motions(np.zeros((10, 3)), TurnAndRun(0.3, 2.0), np.random.default_rng(7))
    b = terrain.sample_motions(np.zeros((10, 3)), TurnAndRun(0.3, 2.0), np.random.default_rng(7))
    assert np.array_equal(a, b)


def test_sample_motions_checks_its_array(rng: np.random.Generator) -> None:
    with pytest.raises(InputError, match=r"poses: expected shape \(n, 3\), got \(2, 2\)"):
        TerrainStats.zero().sample_motions(np.zeros((2, 2)), TurnAndRun(0, 1), rng)
    with pytest.raises(InputError, match=r"poses: expected finite numbers"):
        TerrainStats.zero().sample_motions([[0.0, np.nan, 0.0]], TurnAndRun(0, 1), rng)


def test_headings_stay_wrapped(rng: np.random.Generator) -> None:
    poses = TerrainStats.zero().sample_motions([[0.0, 0.0, 3.0]], TurnAndRun(1.0, 0.0), rng)
    assert poses[0, 2] == pytest.approx(4.0 - 2 * math.pi)


# --- validation ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"translation_loss": 1.0}, r"translation_loss: expected a number in \[0, 1\), got 1.0"),
        ({"rotation_loss": -0.1}, r"rotation_loss: expected a number in \[0, 1\), got -0.1"),
        ({"translation_sd": -0.01}, r"translation_sd: expected a number in \[0, 10\], got -0.01"),
        ({"skitter_sd": float("nan")}, r"skitter_sd: expected a finite number, got nan"),
        ({"drift": float("inf")}, r"drift: expected a finite number, got inf"),
    ],
)
def test_bad_statistics_are_refused(overrides: dict[str, float], message: str) -> None:
    with pytest.raises(InputError, match=message):
        stats(**overrides)


def test_default_table_is_illustrative_and_complete() -> None:
    table = TerrainTable.default()
    assert sorted(table) == ["concrete", "grass", "gravel", "tile"]
    assert len(table) == 4
    # Rougher terrain loses more.
    assert table["grass"].translation_sd > table["tile"].translation_sd
    assert table.get("sand") is None
    assert "tile" in table
    with pytest.raises(
        UnknownTerrainError, match=r"terrain: expected one of concrete, grass, gravel, tile, got 'sand'"
    ):
        table["sand"]


def test_table_is_read_only() -> None:
    table = TerrainTable.default()
    with pytest.raises(TypeError, match=r"does not support item assignment"):
        table.entries["new"] = TerrainStats.zero()  # type: ignore[index]


# --- TOML ------------------------------------------------------------------------------------------------


def test_toml_round_trip(tmp_path: Path) -> None:
    path = tmp_path / "terrain.toml"
    path.write_text(TerrainTable.default().to_toml())
    loaded = TerrainTable.from_toml(path)
    assert dict(loaded) == dict(TerrainTable.default())


def test_toml_accepts_degrees_per_metre(tmp_path: Path) -> None:
    path = tmp_path / "terrain.toml"
    body = "\n".join(f"{name} = 0.0" for name in FIELDS if name != "drift")
    path.write_text(f"[carpet]\n{body}\ndrift_deg_per_m = 2.0\n")
    assert TerrainTable.from_toml(path)["carpet"].drift == pytest.approx(math.radians(2.0))


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return path


def _complete(**overrides: str) -> str:
    lines = dict.fromkeys(FIELDS, "0.01")
    lines.update(overrides)
    return "[tile]\n" + "\n".join(f"{key} = {value}" for key, value in lines.items()) + "\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[tile\n", r"bad.toml:1:6: expected valid TOML, got Expected ']'"),
        ("", r"bad.toml: expected at least one terrain table, got none"),
        ("tile = 3\n", r"bad.toml: \[tile\]: expected a table of statistics, got 3"),
        (
            _complete(wheel_slip="0.1"),
            r"bad.toml: \[tile\] wheel_slip: expected one of translation_loss, .*got unknown key 'wheel_sl",
        ),
        (
            _complete(translation_sd="-0.1"),
            r"bad.toml: \[tile\] translation_sd: expected a number in \[0, 10\], got -0.1",
        ),
        (
            _complete(rotation_loss="1.5"),
            r"bad.toml: \[tile\] rotation_loss: expected a number in \[0, 1\), got 1.5",
        ),
        (_complete(drift="nan"), r"bad.toml: \[tile\] drift: expected a finite number, got nan"),
        (_complete(skitter='"much"'), r"bad.toml: \[tile\] skitter: expected a finite number, got 'much'"),
        (_complete(skitter="[1]"), r"bad.toml: \[tile\] skitter: expected a finite number, got an array"),
        (
            _complete(drift_deg_per_m="1.0"),
            r"bad.toml: \[tile\] drift_deg_per_m: expected drift once, got it twice",
        ),
        (
            "[tile]\ntranslation_loss = 0.1\n",
            r"bad.toml: \[tile\]: expected keys translation_inertial_loss, .*got none for them",
        ),
    ],
)
def test_malformed_toml_names_file_terrain_and_key(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(FileFormatError, match=message):
        TerrainTable.from_toml(_write(tmp_path, text))


def test_missing_file_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(
        FileFormatError, match=r"nope.toml: expected an existing terrain table TOML file, got no such"
    ):
        TerrainTable.from_toml(tmp_path / "nope.toml")


def test_file_errors_are_value_errors_too(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"expected valid TOML"):
        TerrainTable.from_toml(_write(tmp_path, "= 1"))


def test_a_byte_order_mark_is_accepted(tmp_path: Path) -> None:
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + TerrainTable.default().to_toml().encode())
    assert TerrainTable.from_toml(path) == TerrainTable.default()


def test_latin1_bytes_are_refused_naming_file_line_and_offset(tmp_path: Path) -> None:
    path = tmp_path / "latin.toml"
    path.write_bytes(b"# caf\xe9\n" + TerrainTable.default().to_toml().encode())
    with pytest.raises(
        FileFormatError, match=r"latin\.toml:1: byte 5: expected UTF-8 text, got the byte 0xe9"
    ):
        TerrainTable.from_toml(path)


def test_a_file_over_the_size_limit_is_refused_stating_it(tmp_path: Path) -> None:
    path = tmp_path / "huge.toml"
    with path.open("wb") as handle:
        handle.truncate(64 * 1024 * 1024 + 1)
    with pytest.raises(
        FileFormatError, match=r"huge\.toml: expected a terrain table TOML file of at most 64 MiB"
    ):
        TerrainTable.from_toml(path)


@settings(max_examples=60, deadline=None)
@given(st.text(min_size=1, max_size=12))
def test_any_terrain_name_round_trips_through_toml(
    tmp_path_factory: pytest.TempPathFactory, name: str
) -> None:
    # names with '"' or '\\' were written unescaped, and 'café' as a bare key: invalid TOML
    table = TerrainTable({name: TerrainTable.default()["grass"]})
    path = tmp_path_factory.mktemp("names") / "terrain.toml"
    path.write_text(table.to_toml(), encoding="utf-8")
    assert TerrainTable.from_toml(path) == table


def test_bad_arguments_get_the_library_error() -> None:
    # these raised AttributeError or TypeError from deep inside
    tile, rng = TerrainTable.default()["tile"], np.random.default_rng(0)
    pose: Any = (0, 0, 0)
    command: Any = (0, 1)
    nothing: Any = None
    text: Any = "3"
    with pytest.raises(InputError, match=r"pose: expected a Pose, got tuple"):
        tile.sample_motion(pose, TurnAndRun(0, 1), rng)
    with pytest.raises(InputError, match=r"command: expected a TurnAndRun, got tuple"):
        tile.sample_motion(Pose(0, 0, 0), command, rng)
    with pytest.raises(InputError, match=r"rng: expected a numpy.random.Generator, got NoneType"):
        tile.sample_motion(Pose(0, 0, 0), TurnAndRun(0, 1), nothing)
    with pytest.raises(InputError, match=r"truncate: expected a positive finite number or None, got '3'"):
        tile.sample_motion(Pose(0, 0, 0), TurnAndRun(0, 1), rng, truncate=text)
    with pytest.raises(InputError, match=r"entries: expected a mapping of terrain names"):
        TerrainTable(nothing)
    listed: Any = [("a", 1)]
    with pytest.raises(FileFormatError, match=r"<mapping>: expected a mapping of terrain tables, got list"):
        TerrainTable.from_mapping(listed)
    with pytest.raises(
        InputError, match=r"path: expected a terrain table TOML file's path \(str or path-like\)"
    ):
        TerrainTable.from_toml(nothing)


def test_a_name_that_is_not_a_string_is_refused() -> None:
    # unhashable type: 'list', a TypeError, before
    table = TerrainTable.default()
    wrong: Any = ["tile"]
    nothing: Any = None
    one: Any = 1
    with pytest.raises(InputError, match="terrain: expected a terrain name \\(a str\\), got list"):
        table[wrong]
    with pytest.raises(InputError, match="w: expected a terrain name \\(a str\\), got list"):
        table.require(wrong, where="w", whose="x")
    with pytest.raises(InputError, match="where: expected a str, got NoneType"):
        table.require("tile", where=nothing, whose="x")
    with pytest.raises(InputError, match="whose: expected a str, got int"):
        table.require("tile", where="w", whose=one)
