"""``aura-ums import rosbag`` and the ``--mcap`` helpers, on a local typer app registered as the CLI does."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import pytest
import typer
from rosbags.rosbag2 import Writer
from rosbags.typesys import Stores, get_typestore
from typer.testing import CliRunner

from aura_ums.cli._interop import MCAP_HELP, rosbag_command, write_simulation_mcap_option
from aura_ums.cli._outputs import Target
from aura_ums.export import mcap_channels
from aura_ums.logs import load_log
from aura_ums.sim import PerceptionMode, Scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def make_app() -> typer.Typer:
    app = typer.Typer()
    import_app = typer.Typer()
    import_app.command("rosbag")(rosbag_command)
    app.add_typer(import_app, name="import")

    @app.command()
    def simulate(
        scenario: Path,
        mcap: Annotated[Path | None, typer.Option("--mcap", help=MCAP_HELP)] = None,
        seed: int = 0,
    ) -> None:
        if mcap is not None:
            write_simulation_mcap_option(
                Target("--mcap", mcap),
                Scenario.from_toml(scenario),
                seed,
                prune=True,
                perception=PerceptionMode.WINDOWS,
                quiet=True,
            )

    return app


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    store = get_typestore(Stores.ROS2_HUMBLE)
    t = store.types

    def header(seconds: float, frame: str = "") -> Any:
        sec = math.floor(seconds)
        stamp = t["builtin_interfaces/msg/Time"](sec=sec, nanosec=round((seconds - sec) * 1e9))
        return t["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    def vector(kind: str, x: float, y: float, z: float) -> Any:
        return t[f"geometry_msgs/msg/{kind}"](x=x, y=y, z=z)

    path = tmp_path_factory.mktemp("bags") / "walk"
    with Writer(path, version=9) as writer:
        motion = writer.add_connection("/cmd", "geometry_msgs/msg/TwistStamped", typestore=store)
        seen = writer.add_connection("/seen", "geometry_msgs/msg/PointStamped", typestore=store)
        truth = writer.add_connection("/truth", "geometry_msgs/msg/PoseStamped", typestore=store)
        for i in range(4):
            time = 5.0 + i
            twist = t["geometry_msgs/msg/Twist"](
                linear=vector("Vector3", 0.5, 0, 0), angular=vector("Vector3", 0, 0, 0)
            )
            command = t["geometry_msgs/msg/TwistStamped"](header=header(time), twist=twist)
            writer.write(motion, round(time * 1e9), store.serialize_cdr(command, command.__msgtype__))
            point = t["geometry_msgs/msg/PointStamped"](
                header=header(time + 0.5, "pole"),
                point=vector("Point", 0.0 if i % 2 else 3.0 - i * 0.5, 0.1, 0),
            )
            writer.write(seen, round((time + 0.5) * 1e9), store.serialize_cdr(point, point.__msgtype__))
            orientation = t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
            pose = t["geometry_msgs/msg/Pose"](
                position=vector("Point", 0.5 * i, 0, 0), orientation=orientation
            )
            stamped = t["geometry_msgs/msg/PoseStamped"](header=header(time, "map"), pose=pose)
            writer.write(truth, round(time * 1e9), store.serialize_cdr(stamped, stamped.__msgtype__))
    return path


@pytest.fixture
def landmarks(tmp_path: Path) -> Path:
    path = tmp_path / "landmarks.csv"
    path.write_text("id,x,y,position_uncertainty\npole,3.0,0.3,0.05\ntree,0.0,5.0,0.2\n")
    return path


def invoke(*args: str) -> Any:
    return CliRunner().invoke(make_app(), list(args))


def test_import_rosbag_writes_the_log_and_a_summary(bag: Path, landmarks: Path, tmp_path: Path) -> None:
    out = tmp_path / "log"
    args = ["import", "rosbag", str(bag), str(out), "--odom", "/cmd", "--observations", "/seen"]
    result = invoke(*args, "--landmarks", str(landmarks), "--groundtruth", "/truth", "--name", "hall")
    assert result.exit_code == 0, result.output
    assert f"wrote {out}" in result.output
    assert "observations       4 (2 bearing, 2 range_bearing)" in result.output
    assert "landmarks          2 (1 observed)" in result.output
    assert "ground truth rows  4" in result.output
    log = load_log(out)
    assert log.meta.name == "hall"
    assert [o.range for o in log.observations] == [3.0, None, 2.0, None]
    assert log.odometry is not None
    assert log.odometry.time.tolist() == [5.0, 6.0, 7.0, 8.0]
    # again without --overwrite: a clean error; with it: replaced
    again = invoke(*args, "--landmarks", str(landmarks))
    assert again.exit_code == 2
    assert "error: OUT_DIR: expected a new or empty folder" in again.stderr
    assert invoke(*args, "--landmarks", str(landmarks), "--overwrite").exit_code == 0
    assert load_log(out).meta.name == "walk"
    assert load_log(out).groundtruth is None


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            ("--odom", "/odom"),
            "topic /odom: expected the motion topic in the bag, got no such topic; topics: /cmd",
        ),
        (("--odom", "/seen"), "topic /seen: expected motion messages of type nav_msgs/msg/Odometry"),
        (("--groundtruth", "/cmd"), "topic /cmd: expected ground truth messages of type"),
        # was "odom_topic: ...": read_rosbag's argument, not the option typed
        (("--odom", ""), "error: --odom: expected a topic name such as '/odom', got ''"),
        (("--observations", ""), "error: --observations: expected a topic name such as '/odom', got ''"),
        (("--groundtruth", ""), "error: --groundtruth: expected a topic name such as '/odom', got ''"),
    ],
)
def test_bad_topics_are_clean_errors(
    bag: Path, landmarks: Path, tmp_path: Path, change: tuple[str, str], message: str
) -> None:
    options = {"--odom": "/cmd", "--observations": "/seen", "--landmarks": str(landmarks)}
    options[change[0]] = change[1]
    args = [item for pair in options.items() for item in pair]
    result = invoke("import", "rosbag", str(bag), str(tmp_path / "log"), *args)
    assert result.exit_code == 2
    assert result.output.startswith("error: ")
    assert message in " ".join(result.output.split())
    assert not (tmp_path / "log").exists()


def test_missing_landmarks_file(bag: Path, tmp_path: Path) -> None:
    args = ["--odom", "/cmd", "--observations", "/seen", "--landmarks", str(tmp_path / "none.csv")]
    result = invoke("import", "rosbag", str(bag), str(tmp_path / "log"), *args)
    assert result.exit_code == 2
    assert "expected a landmarks CSV file, got no such file" in result.output


def test_a_landmarks_file_without_rows_is_named(bag: Path, landmarks: Path, tmp_path: Path) -> None:
    header_only = tmp_path / "landmarks.csv"
    header_only.write_text(landmarks.read_text().splitlines()[0] + "\n")
    args = ["--odom", "/cmd", "--observations", "/seen", "--landmarks", str(header_only)]
    result = invoke("import", "rosbag", str(bag), str(tmp_path / "log"), *args)
    assert result.exit_code == 2
    assert (
        result.stderr == f"error: {header_only}: expected a landmark per row after the header, got no row\n"
    )


def test_a_name_that_cannot_be_a_log_name_is_named_as_the_option(
    bag: Path, landmarks: Path, tmp_path: Path
) -> None:
    args = ["--odom", "/cmd", "--observations", "/seen", "--landmarks", str(landmarks), "--name", "a\nb"]
    result = invoke("import", "rosbag", str(bag), str(tmp_path / "log"), *args)
    assert result.exit_code == 2
    assert (
        result.stderr
        == "error: --name: expected printable characters (no line breaks or tabs), got 'a\\nb'\n"
    )
    assert not (tmp_path / "log").exists()


def test_simulate_mcap_option(tmp_path: Path) -> None:
    out = tmp_path / "run.mcap"
    result = invoke("simulate", str(SCENARIOS / "paper_sidewalk.toml"), "--mcap", str(out), "--seed", "2")
    assert result.exit_code == 0, result.output
    assert "wrote" in result.output
    assert mcap_channels(out)["/camera/image"] == "foxglove.RawImage"
    (tmp_path / "file").write_text("")
    bad = invoke(
        "simulate", str(SCENARIOS / "paper_sidewalk.toml"), "--mcap", str(tmp_path / "file" / "x.mcap")
    )
    assert bad.exit_code == 2
    # Past the command's own checks (this app has none): the library's refusal, worded for the option.
    assert f"--mcap: expected a writable place, got {tmp_path / 'file' / 'x.mcap'}: " in bad.output


def test_import_camera_info_writes_the_camera_toml_replay_reads(tmp_path: Path) -> None:
    # A bag's CameraInfo to a camera TOML from the command line (it took Python before).
    from aura_ums.camera import CameraMount, load_camera
    from aura_ums.cli import app
    from tests.logs.test_rosbag import T0, camera_bag, camera_info

    store = get_typestore(Stores.ROS2_HUMBLE)
    bag = camera_bag(tmp_path / "cam", camera_info(store, T0))
    out = tmp_path / "camera.toml"
    arguments = ["import", "camera-info", str(bag), "--topic", "/camera/camera_info", "--out", str(out)]
    done = CliRunner().invoke(app, [*arguments, "--height", "0.3", "--tilt-deg", "5"])
    assert done.exit_code == 0, done.output
    camera = load_camera(out)
    assert camera.intrinsics.fx == 554.25
    assert camera.intrinsics.distortion == (-0.1, 0.01, 0.0, 0.0, 0.0)
    assert camera.mount == CameraMount(0.3, tilt=math.radians(5.0))
    refused = {
        # an existing output is replaced only with --overwrite
        ("--height", "0.3"): "--out: expected a new file",
        ("--height", "0.3", "--overwrite", "--tilt-deg", "90"): "--tilt-deg: expected |tilt| < pi/2",
        ("--height", "0.3", "--overwrite", "--topic", "/nothing"): "/nothing",
    }
    for extra, message in refused.items():
        result = CliRunner().invoke(app, [*arguments, *extra])
        assert result.exit_code == 2, result.output
        assert message in result.stderr, result.stderr
        assert "Traceback" not in result.output
    assert load_camera(out) == camera  # refused: the file written before is as it was
