from __future__ import annotations

import dataclasses
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError, UnknownLandmarkError
from aura_ums.manager import ManagerSettings, MapProfile, SettingInfo
from aura_ums.sim import Scenario, StartState, waypoints_array
from aura_ums.uncertainty import FOOT, LandmarkClass, TerrainStats, TurnAndRun

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
DEFAULTS = ManagerSettings().to_dict()
SCENARIO_FILES = sorted(p for p in SCENARIOS.glob("*.toml") if not p.name.endswith("camera.toml"))

GOOD = """\
map = "sample:paper_sidewalk"
camera = "cam.toml"
frame_spacing = 2.0

[start]
x = 0.0
y = 0.0
heading_deg = 0.0
position_radius = 0.3
heading_halfwidth_deg = 2.0

[route]
commands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]

[manager]
area_limit = 20.0
missed_limit = 2
"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    shutil.copy(SCENARIOS / "paper_camera.toml", tmp_path / "cam.toml")
    (tmp_path / "good.toml").write_text(GOOD)
    return tmp_path


def test_expected_scenario_files_exist() -> None:
    names = {p.stem for p in SCENARIO_FILES}
    assert {"paper_sidewalk", "paper_sidewalk_class2", "indoor_corridor", "four_terrains"} <= names


@pytest.mark.parametrize("path", SCENARIO_FILES, ids=lambda p: p.stem)
def test_each_scenario_file_loads_and_runs(path: Path) -> None:
    scenario = Scenario.from_toml(path)
    assert scenario.name == path.stem
    assert scenario.commands
    assert set(scenario.landmark_ids) <= {record.id for record in scenario.meadow_map.landmarks}
    start = scenario.initial_map()
    assert start.contains(scenario.start.pose.x, scenario.start.pose.y, scenario.start.pose.heading)
    frames = list(scenario.simulate(np.random.default_rng(0)))
    assert len(frames) == len(scenario.legs()) + 1
    assert frames[-1].distance == pytest.approx(sum(c.run for c in scenario.commands))
    intrinsics = scenario.camera.intrinsics
    assert all(f.image.shape == (intrinsics.height, intrinsics.width) for f in frames)


def test_paper_sidewalk_is_the_papers_experiment() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    assert scenario.start.position_radius == pytest.approx(FOOT)
    assert scenario.frame_spacing is None
    distances = [f.distance for f in scenario.simulate(np.random.default_rng(1), exact_start=True)]
    assert distances == pytest.approx([0.0, 10 * FOOT, 20 * FOOT, 40 * FOOT])
    k = scenario.camera.intrinsics
    assert (k.width, k.height) == (512, 480)
    assert math.degrees(2.0 * math.atan(k.width / 2.0 / k.fx)) == pytest.approx(50.0, abs=1.0)
    assert scenario.camera.mount.height == pytest.approx(1.2)
    classes = {record.symbol: record.landmark_class for record in scenario.landmarks}
    assert classes == {
        "telephone pole": LandmarkClass.VERTICAL_LINE,
        "lamppost": LandmarkClass.VERTICAL_LINE,
        "building corner": LandmarkClass.VERTICAL_LINE,
    }
    class2 = Scenario.from_toml(SCENARIOS / "paper_sidewalk_class2.toml")
    assert {r.symbol: r.landmark_class for r in class2.landmarks}["building corner"] is LandmarkClass.POINT


def test_confirm_frames_sets_every_landmarks_count(folder: Path) -> None:
    default = Scenario.from_toml(folder / "good.toml")
    assert {r.confirm_frames for r in default.meadow_map.landmarks} == {3}  # the map's own
    (folder / "single.toml").write_text(
        GOOD.replace("frame_spacing = 2.0", "frame_spacing = 2.0\nconfirm_frames = 1")
    )
    single = Scenario.from_toml(folder / "single.toml")
    assert {r.confirm_frames for r in single.meadow_map.landmarks} == {1}
    assert [r.landmark for r in single.meadow_map.landmarks] == [
        r.landmark for r in default.meadow_map.landmarks
    ]
    paper = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")  # still images: one frame each
    assert {r.confirm_frames for r in paper.landmarks} == {1}


def test_four_terrains_crosses_every_terrain() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "four_terrains.toml")
    assert scenario.frame_spacing == pytest.approx(2.0)  # frame_rate 1/s at 2 m/s
    robot = scenario.robot(scenario.start.pose, np.random.default_rng(0))
    seen: list[str] = []
    for leg in scenario.legs():
        robot.execute(leg)
        seen.extend(terrain for _, terrain in robot.last_steps)
    assert list(dict.fromkeys(seen)) == ["tile", "concrete", "grass", "gravel"]


def test_frames_every_spacing_and_at_every_stop(folder: Path) -> None:
    scenario = Scenario.from_toml(folder / "good.toml")
    legs = scenario.legs()
    assert [leg.run for leg in legs] == pytest.approx([2.0, 2.0, 1.0, 1.0])
    assert [leg.turn for leg in legs] == pytest.approx([0.0, 0.0, 0.0, math.radians(10.0)])
    assert scenario.settings == ManagerSettings(area_limit=20.0, missed_limit=2)
    assert scenario.name == "good"
    assert waypoints_array(scenario)[-1] == pytest.approx(
        [5.0 + math.cos(0.17453292519943295), 0.17364817766693033]
    )


def test_simulation_is_deterministic_per_seed(folder: Path) -> None:
    scenario = Scenario.from_toml(folder / "good.toml")
    a = list(scenario.simulate(np.random.default_rng(3)))
    b = list(scenario.simulate(np.random.default_rng(3)))
    c = list(scenario.simulate(np.random.default_rng(4)))
    assert [f.pose for f in a] == [f.pose for f in b]
    assert all(np.array_equal(f.image, g.image) for f, g in zip(a, b, strict=True))
    assert [f.pose for f in a] != [f.pose for f in c]
    assert a[0].command is None
    assert a[1].command == TurnAndRun(0.0, 2.0)


def test_true_start_is_within_the_start_bounds(folder: Path) -> None:
    scenario = Scenario.from_toml(folder / "good.toml")
    start = scenario.initial_map()
    rng = np.random.default_rng(0)
    for _ in range(100):
        pose = scenario.sample_true_start(rng)
        assert math.hypot(pose.x, pose.y) <= 0.3
        assert abs(pose.heading) <= math.radians(2.0) + 1e-12
        assert start.contains(pose.x, pose.y, pose.heading)


def test_route_from_waypoints_and_from_a_goal(folder: Path) -> None:
    text = GOOD.replace(
        "commands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]",
        "waypoints = [[4.0, 0.0], [4.0, 0.5]]",
    )
    (folder / "w.toml").write_text(text)
    commands = Scenario.from_toml(folder / "w.toml").commands
    assert [value for c in commands for value in (c.turn, c.run)] == pytest.approx(
        [0.0, 4.0, math.pi / 2, 0.5]
    )
    (folder / "g.toml").write_text(text.replace("waypoints = [[4.0, 0.0], [4.0, 0.5]]", "goal = [12.0, 0.0]"))
    commands = Scenario.from_toml(folder / "g.toml").commands
    assert sum(c.run for c in commands) == pytest.approx(12.0)
    assert all(c.turn == pytest.approx(0.0) for c in commands)


def terrain_table_toml(terrains: tuple[str, ...], value: float) -> str:
    """A terrain table in TOML: every statistic of every terrain set to ``value``."""
    row = "".join(f"{key} = {value}\n" for key in TerrainStats.field_names())
    return "".join(f"[{name}]\n{row}" for name in terrains)


def test_relative_geojson_map_and_terrain_files(folder: Path) -> None:
    shutil.copy(SCENARIOS / "four_terrains.geojson", folder / "sub_map.geojson")
    (folder / "terrain.toml").write_text(terrain_table_toml(("tile", "concrete", "grass", "gravel"), 0.01))
    text = GOOD.replace('map = "sample:paper_sidewalk"', 'map = "sub_map.geojson"\nterrain = "terrain.toml"')
    text = text.replace("x = 0.0\n", "x = 1.0\n")
    (folder / "m.toml").write_text(text)
    scenario = Scenario.from_toml(folder / "m.toml")
    assert scenario.terrain["grass"].drift == 0.01
    assert len(scenario.meadow_map.meadows) == 4


def test_without_a_terrain_the_scenario_takes_the_table_its_map_names(folder: Path) -> None:
    # The built-in table was taken instead, and the map then refused for a terrain it lacks.
    document = json.loads((SCENARIOS / "four_terrains.geojson").read_text(encoding="utf-8"))
    for feature in document["features"]:
        if feature["properties"].get("terrain") == "grass":
            feature["properties"]["terrain"] = "asphalt"
    document["terrain_table"] = "own.toml"
    (folder / "own_map.geojson").write_text(json.dumps(document), encoding="utf-8")
    (folder / "own.toml").write_text(terrain_table_toml(("tile", "concrete", "asphalt", "gravel"), 0.02))
    text = GOOD.replace('map = "sample:paper_sidewalk"', 'map = "own_map.geojson"').replace(
        "x = 0.0\n", "x = 1.0\n"
    )
    (folder / "m.toml").write_text(text)
    scenario = Scenario.from_toml(folder / "m.toml")
    assert scenario.terrain["asphalt"].drift == 0.02
    assert "grass" not in scenario.terrain
    # A map that names no table of its own: the built-in one, which must hold its terrains.
    del document["terrain_table"]
    (folder / "own_map.geojson").write_text(json.dumps(document), encoding="utf-8")
    with pytest.raises(
        FileFormatError, match=r"m\.toml: terrain: expected a table with the terrain 'asphalt'"
    ):
        Scenario.from_toml(folder / "m.toml")


MALFORMED = [
    # (replace this, with that, key named in the message, what the message says)
    ('map = "sample:paper_sidewalk"', 'map = "sample:moon"', "map", "expected one of"),
    (
        'map = "sample:paper_sidewalk"',
        'map = "nowhere.geojson"',
        "map",
        "nowhere.geojson: expected an existing GeoJSON file",
    ),
    ('map = "sample:paper_sidewalk"', "map = 3", "map", "expected a non-empty string"),
    ('map = "sample:paper_sidewalk"\n', "", "map", "got none"),
    ('camera = "cam.toml"', 'camera = "missing.toml"', "camera", "no such file"),
    ('camera = "cam.toml"\n', "", "camera", "got none"),
    (
        'camera = "cam.toml"',
        'camera = "cam.toml"\nterrain = "none.toml"',
        "terrain",
        "expected a terrain table",
    ),
    ("frame_spacing = 2.0", "frame_spacing = -1.0", "frame_spacing", r"expected a number in \(0, 10000\] m"),
    ("frame_spacing = 2.0", "frame_spacing = 2.0\nframe_rate = 1.0", "frame_rate", "got both"),
    ("frame_spacing = 2.0", "frame_rate = 1.0", "speed", "expected the speed"),
    ("frame_spacing = 2.0", "frame_spacing = 2.0\ncolour = 1", "colour", "unknown key 'colour'"),
    ("frame_spacing = 2.0", 'frame_spacing = 2.0\nlandmarks = ["nope"]', r"landmarks\[0\]", "got 'nope'"),
    (
        "frame_spacing = 2.0",
        "frame_spacing = 2.0\nconfirm_frames = 0",
        "confirm_frames",
        "integer >= 1, got 0",
    ),
    ("frame_spacing = 2.0", "frame_spacing = 2.0\nconfirm_frames = 1.5", "confirm_frames", "integer >= 1"),
    ("x = 0.0\n", "", r"\[start\] x", "expected this key"),
    ("x = 0.0", 'x = "east"', r"\[start\] x", "expected a finite number, got 'east'"),
    ("x = 0.0", "x = 100.0", r"\[start\] x", "expected a start inside a meadow"),
    ("heading_deg = 0.0", "heading_deg = 0.0\nheading = 0.0", r"\[start\] heading_deg", "got both"),
    ("heading_halfwidth_deg = 2.0\n", "", r"\[start\] heading_halfwidth_deg", "got none"),
    (
        "position_radius = 0.3",
        "position_radius = -0.3",
        r"\[start\] position_radius",
        r"expected a number in \[0, 10000\] m",
    ),
    ("position_radius = 0.3", "position_radius = 0.3\nspeed = 3", r"\[start\] speed", "unknown key"),
    ("run = 5.0 }", "run = -5.0 }", r"\[route\] commands\[0\]\.run", r"in \[0, 10000\] m"),
    ("{ turn_deg = 10.0, run = 1.0 }", "{ turn_deg = 10.0 }", r"\[route\] commands\[1\]\.run", "got none"),
    (
        "{ turn_deg = 10.0, run = 1.0 }",
        "{ turn = 1, turn_deg = 1, run = 1 }",
        r"\[route\] commands\[1\]\.turn_deg",
        "both",
    ),
    ("{ turn_deg = 10.0, run = 1.0 }", "{ spin = 1, run = 1 }", r"\[route\] commands\[1\]\.spin", "unknown"),
    ("{ turn_deg = 10.0, run = 1.0 }", "3", r"\[route\] commands\[1\]", "expected a table"),
    ("commands = [", "waypoints = [[1.0, 0.0]]\ncommands = [", r"\[route\]", "expected exactly one"),
    (
        "commands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]",
        "commands = []",
        r"\[route\] commands",
        "non-empty list",
    ),
    (
        "commands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]",
        "waypoints = [[1.0]]",
        r"\[route\] waypoints\[0\]",
        r"expected \[x, y\]",
    ),
    (  # within the coordinates' range, but a leg longer than any run: named, not TurnAndRun.run
        "commands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]",
        "waypoints = [[1000000.0, 0.0]]",
        r"\[route\] waypoints\[0\]",
        r"expected a point at most 10000 m from the previous one \(a leg's run\), "
        r"got \(1000000\.0, 0\.0\)",
    ),
    (
        "commands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]",
        "waypoints = [[0.0, 0.0]]",
        r"\[route\] waypoints\[0\]",
        "away from the previous",
    ),
    (
        "commands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]",
        "goal = [500.0, 0.0]",
        r"\[route\] goal",
        "expected a goal reachable",
    ),
    (
        "area_limit = 20.0",
        "area_limit = 0",
        r"\[manager\] area_limit",
        "number in \\(0, 4e\\+12\\] or none, got 0",
    ),
    ("missed_limit = 2", "missed_limit = 1.5", r"\[manager\] missed_limit", "integer >= 1, got 1.5"),
    ("missed_limit = 2", "sigma = 2", r"\[manager\] sigma", "unknown key 'sigma'"),
    # the key the file sets is named, not the default it conflicts with
    (
        "missed_limit = 2",
        "relocalize_after = 2",
        r"\[manager\] relocalize_after",
        r"relocalize_window \(1\), got 2",
    ),
    (
        "missed_limit = 2",
        "joint_above = 0.5\njoint_above_deg = 30",
        r"\[manager\] joint_above_deg",
        "another in",
    ),
    ("missed_limit = 2", "joint_sector_deg = 400", r"\[manager\] joint_sector_deg", r"in \(0, 2 pi\]"),
    ("missed_limit = 2", 'robust = "none"', r"\[manager\] robust", "expected true or false, got 'none'"),
    (
        "[manager]",
        "[lost]\nmissed_limit = 3\n[manager]",
        r"\[manager\] missed_limit",
        r"got another in \[lost\]",
    ),
    ("[manager]", "[render]\nnoise = -1\n[manager]", r"\[render\] noise", r"in \[0, 255\] gray levels"),
    ("[manager]", "[render]\nclutter = 2.5\n[manager]", r"\[render\] clutter", "integer >= 0"),
    ("[manager]", "[render]\nsparkle = 1\n[manager]", r"\[render\] sparkle", "unknown key"),
    ("[start]", "[begin]", "begin", "unknown key 'begin'"),
    (
        "[route]\ncommands = [{ turn_deg = 0.0, run = 5.0 }, { turn_deg = 10.0, run = 1.0 }]\n",
        "",
        r"\[route\]",
        "expected this table, got none",
    ),
]


@pytest.mark.parametrize(
    ("old", "new", "key", "message"), MALFORMED, ids=[f"{m[2]}-{i}" for i, m in enumerate(MALFORMED)]
)
def test_malformed_scenario_names_file_and_key(
    folder: Path, old: str, new: str, key: str, message: str
) -> None:
    assert old in GOOD
    path = folder / "bad.toml"
    path.write_text(GOOD.replace(old, new, 1))
    with pytest.raises(FileFormatError, match=rf"bad\.toml: {key}.*{message}") as info:
        Scenario.from_toml(path)
    assert info.value.path == str(path)


def test_missing_and_unreadable_scenario_files(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match=r"none\.toml: expected an existing scenario file"):
        Scenario.from_toml(tmp_path / "none.toml")
    (tmp_path / "bin.toml").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(
        FileFormatError, match=r"bin\.toml:1: byte 0: expected UTF-8 text, got a UTF-16 or UTF-32"
    ):
        Scenario.from_toml(tmp_path / "bin.toml")
    (tmp_path / "latin.toml").write_bytes(
        GOOD.replace("[manager]", "# d\xe9j\xe0 vu\n[manager]").encode("latin-1")
    )
    with pytest.raises(
        FileFormatError, match=r"latin\.toml:15: byte \d+: expected UTF-8 text, got the byte 0xe9"
    ):
        Scenario.from_toml(tmp_path / "latin.toml")


def test_toml_syntax_errors_name_line_and_column(folder: Path) -> None:
    (folder / "bad.toml").write_text(GOOD.replace("[manager]", "x = = 3\n[manager]"))
    with pytest.raises(FileFormatError, match=r"bad\.toml:15:5: expected valid TOML, got Invalid value"):
        Scenario.from_toml(folder / "bad.toml")


def test_sample_map_with_a_table_lacking_its_terrain(folder: Path) -> None:
    (folder / "t.toml").write_text(terrain_table_toml(("concrete",), 0.0))
    (folder / "bad.toml").write_text(
        GOOD.replace('camera = "cam.toml"', 'camera = "cam.toml"\nterrain = "t.toml"')
    )
    with pytest.raises(
        FileFormatError, match=r"bad\.toml: terrain: expected a table with the terrain 'gravel'"
    ):
        Scenario.from_toml(folder / "bad.toml")


def test_values_built_in_code_are_checked() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    with pytest.raises(InputError, match=r"StartState.position_radius: expected a non-negative number"):
        StartState(scenario.start.pose, -1.0, 0.1)
    with pytest.raises(InputError, match=r"Scenario.settings: expected a ManagerSettings, got dict"):
        dataclasses.replace(scenario, settings={"area_limit": 10.0})  # type: ignore[arg-type]
    with pytest.raises(UnknownLandmarkError, match="got 'nope'"):
        dataclasses.replace(scenario, landmark_ids=("nope",))
    with pytest.raises(InputError, match=r"Scenario.frame_spacing: expected a positive number or None"):
        dataclasses.replace(scenario, frame_spacing=0.0)


def test_frames_are_read_only() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    frame = next(iter(scenario.simulate(np.random.default_rng(0))))
    with pytest.raises(ValueError, match="read-only"):
        frame.image[0, 0] = 0


def test_the_manager_table_knows_every_field(folder: Path) -> None:
    # A value other than the default for every field of ManagerSettings, by its own name.
    chosen: dict[str, object] = {}
    for field in dataclasses.fields(ManagerSettings):
        info = SettingInfo.of(field)
        if info.kind is bool:
            chosen[field.name] = not DEFAULTS[field.name]
        elif info.kind is int:
            chosen[field.name] = (DEFAULTS[field.name] or 3) + 2
        else:
            chosen[field.name] = (DEFAULTS[field.name] or 1.0) * 1.5
    lines = [f"{name} = {str(value).lower()}" for name, value in chosen.items()]
    (folder / "all.toml").write_text(GOOD.split("[manager]")[0] + "[manager]\n" + "\n".join(lines) + "\n")
    settings = Scenario.from_toml(folder / "all.toml").settings
    assert settings.to_dict() == chosen
    assert settings.to_dict() != ManagerSettings().to_dict()


def test_the_manager_table_takes_degrees_and_none_and_the_earlier_lost_table(folder: Path) -> None:
    text = GOOD.replace("missed_limit = 2", 'joint_above = "none"\njoint_sector_deg = 10.0\nrobust = false')
    (folder / "deg.toml").write_text(text)
    settings = Scenario.from_toml(folder / "deg.toml").settings
    assert (settings.joint_above, settings.joint_sector, settings.robust) == (None, math.radians(10.0), False)
    assert settings.area_limit == 20.0
    (folder / "earlier.toml").write_text(GOOD.replace("[manager]", "[lost]"))
    earlier = Scenario.from_toml(folder / "earlier.toml").settings
    assert earlier == ManagerSettings(area_limit=20.0, missed_limit=2)
    (folder / "plain.toml").write_text(GOOD.split("[manager]")[0])
    assert Scenario.from_toml(folder / "plain.toml").settings == ManagerSettings()


def test_the_manager_table_takes_a_profile_under_its_own_keys(folder: Path) -> None:
    text = GOOD.replace("missed_limit = 2", 'missed_limit = 2\nprofile = "relaxed"\nrelaxed_window = 7')
    (folder / "relaxed.toml").write_text(text)
    settings = Scenario.from_toml(folder / "relaxed.toml").settings
    expected = MapProfile.RELAXED.settings(ManagerSettings(area_limit=20.0, missed_limit=2))
    assert settings == dataclasses.replace(expected, relaxed_window=7)
    for bad in ('"sound"', "3", '["sliced"]'):
        (folder / "bad.toml").write_text(GOOD.replace("missed_limit = 2", f"profile = {bad}"))
        with pytest.raises(
            FileFormatError, match=r"\[manager\] profile: expected one of product, sliced, relaxed, got"
        ):
            Scenario.from_toml(folder / "bad.toml")


def test_scenario_with_a_byte_order_mark_reads_the_same(folder: Path) -> None:
    (folder / "bom.toml").write_bytes(b"\xef\xbb\xbf" + GOOD.encode())
    plain, with_bom = Scenario.from_toml(folder / "good.toml"), Scenario.from_toml(folder / "bom.toml")
    assert (with_bom.commands, with_bom.start, with_bom.settings, with_bom.camera) == (
        plain.commands,
        plain.start,
        plain.settings,
        plain.camera,
    )
    assert with_bom.name == "bom"


def test_over_size_scenario_is_refused_stating_the_limit(folder: Path) -> None:
    with (folder / "huge.toml").open("wb") as handle:
        handle.truncate(64 * 1024 * 1024 + 1)
    with pytest.raises(FileFormatError, match=r"huge\.toml: expected a scenario file of at most 64 MiB"):
        Scenario.from_toml(folder / "huge.toml")


@pytest.mark.parametrize("spacing", [0.4, 0.3, 0.1, 0.7, 1e-3])
def test_legs_end_when_rounding_leaves_a_frame_just_short_of_its_place(spacing: float) -> None:
    # 0.4 + 0.4 + 0.4 falls 1e-16 short of 1.2: the next leg was 1e-17 m long, which left
    # the distance travelled unchanged, and legs() appended such legs until memory ran out.
    paper = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    scenario = dataclasses.replace(paper, frame_spacing=spacing)
    legs = scenario.legs()
    assert len(legs) <= scenario.frame_count()
    assert sum(leg.run for leg in legs) == pytest.approx(sum(c.run for c in paper.commands), abs=1e-9)
    # No leg of a rounding error's length; shorter than the spacing only a command's first
    # (the rest of a spacing begun by the command before) and last.
    assert min(leg.run for leg in legs) > 1e-6
    short = [leg.run for leg in legs if leg.run < spacing * (1.0 - 1e-6)]
    assert len(short) <= 2 * len(paper.commands)


def test_a_scenario_camera_may_name_its_calibration(folder: Path) -> None:
    """The camera file's [intrinsics] calibration is read, and listed among the files the scenario reads."""
    (folder / "calibration").mkdir()
    (folder / "calibration" / "ost.yaml").write_text(
        "image_width: 512\nimage_height: 480\ncamera_name: paper\n"
        "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [549, 0, 255.5, 0, 549, 239.5, 0, 0, 1]\n"
        "distortion_model: plumb_bob\n"
        "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.1, 0.01, 0, 0, 0]\n"
    )
    (folder / "named.toml").write_text(
        '[intrinsics]\ncalibration = "calibration/ost.yaml"\n[mount]\nheight = 1.2\ntilt_deg = 3.0\n'
    )
    (folder / "m.toml").write_text(GOOD.replace('camera = "cam.toml"', 'camera = "named.toml"'))
    scenario = Scenario.from_toml(folder / "m.toml")
    assert scenario.camera.intrinsics.distortion == (-0.1, 0.01, 0.0, 0.0, 0.0)
    assert scenario.camera.intrinsics.fx == Scenario.from_toml(folder / "good.toml").camera.intrinsics.fx
    assert [(key, path.relative_to(folder).as_posix()) for key, path in scenario.files] == [
        ("camera", "named.toml"),
        ("camera's calibration", "calibration/ost.yaml"),
    ]
    (folder / "calibration" / "ost.yaml").unlink()
    with pytest.raises(
        FileFormatError,
        match=r"m\.toml: camera: expected a camera file that loads, got: .*named\.toml: "
        r"\[intrinsics\] calibration: expected an OpenCV or ROS calibration file that reads, got: "
        r".*ost\.yaml: expected an existing calibration file, got no such file$",
    ):
        Scenario.from_toml(folder / "m.toml")
