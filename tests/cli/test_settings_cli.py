"""The map manager's options: declared once from ManagerSettings, the same on replay, compare and simulate."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import pytest
import typer
from typer.testing import CliRunner

from aura_ums.cli import app
from aura_ums.cli._common import NO_OPTIONS, SettingOptions, manager_options, setting_flag
from aura_ums.manager import ManagerSettings, MapProfile, SettingInfo
from aura_ums.sim import Scenario
from aura_ums.uncertainty import cell_count

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
DEFAULTS = ManagerSettings().to_dict()
FIELDS = dataclasses.fields(ManagerSettings)
runner = CliRunner()


def flags_of(command: str) -> set[str]:
    group = typer.main.get_command(app)
    found = group.commands[command]  # type: ignore[attr-defined]
    return {flag for param in found.params for flag in (*param.opts, *param.secondary_opts)}


@pytest.mark.parametrize("command", ["replay", "compare", "simulate"])
def test_the_commands_know_every_field(command: str) -> None:
    flags = flags_of(command)
    for field in FIELDS:
        assert setting_flag(field.name) in flags, field.name
        off = SettingInfo.of(field).off_flag
        assert not off or off in flags, off


def recorder() -> tuple[typer.Typer, list[ManagerSettings]]:
    seen: list[ManagerSettings] = []
    tool = typer.Typer()

    @tool.command()
    @manager_options()
    def run(name: str, settings: SettingOptions = NO_OPTIONS) -> None:
        seen.append(settings.over())

    return tool, seen


def other_than_default(field: dataclasses.Field[Any]) -> tuple[list[str], object]:
    """The arguments that set a field to a value other than its default, and that value."""
    info = SettingInfo.of(field)
    flag = setting_flag(field.name)
    if info.kind is bool:
        return ([flag] if not DEFAULTS[field.name] else [info.off_flag]), not DEFAULTS[field.name]
    if info.kind is int:
        value: object = (DEFAULTS[field.name] or 3) + 2
    else:
        value = (DEFAULTS[field.name] or 1.0) * 1.5
    return [flag, str(value)], value


def test_every_field_reaches_the_command_from_its_option() -> None:
    tool, seen = recorder()
    arguments, expected = ["x"], {}
    for field in FIELDS:
        given, value = other_than_default(field)
        arguments += given
        expected[field.name] = value
    result = runner.invoke(tool, arguments)
    assert result.exit_code == 0, result.output
    assert seen[-1].to_dict() == expected
    assert runner.invoke(tool, ["x"]).exit_code == 0
    assert seen[-1] == ManagerSettings()


def test_an_off_flag_sets_none_and_bad_values_name_their_option() -> None:
    tool, seen = recorder()
    assert runner.invoke(tool, ["x", "--one-by-one", "--gate-only"]).exit_code == 0
    assert (seen[-1].joint_above, seen[-1].robust) == (None, False)
    both = runner.invoke(tool, ["x", "--one-by-one", "--joint-above", "1.0"])
    assert both.exit_code == 2
    assert "--joint-above: expected it or --one-by-one, got both" in both.output
    # the option given is named, not the default it conflicts with
    bad = runner.invoke(tool, ["x", "--relocalize-after", "3"])
    assert bad.exit_code == 2
    assert "--relocalize-after: expected an integer <= relocalize_window (1), got 3" in bad.output
    bad = runner.invoke(tool, ["x", "--relaxed-q", "100000"])
    assert bad.exit_code == 2
    assert "--relaxed-q: expected an integer < relaxed_window (10), got 100000" in bad.output
    both = runner.invoke(tool, ["x", "--relaxed-q", "3", "--relaxed-window", "3"])
    assert both.exit_code == 2
    assert "--relaxed-window: expected an integer > relaxed_q (3), got 3" in both.output
    window = runner.invoke(tool, ["x", "--relocalize-window", "1", "--relocalize-after", "3"])
    assert "--relocalize-window: expected an integer >= relocalize_after (3), got 1" in window.output


@pytest.fixture
def ran(monkeypatch: pytest.MonkeyPatch) -> list[Scenario]:
    """The scenarios ``simulate`` runs, as it hands them to its campaign."""
    import aura_ums.campaign

    seen: list[Scenario] = []
    real = aura_ums.campaign.simulate_campaign

    def spy(scenario: Scenario, *args: Any, **kwargs: Any) -> Any:
        seen.append(scenario)
        return real(scenario, *args, **kwargs)

    # simulate runs its Monte Carlo as a campaign (aura_ums.campaign), serially by default.
    monkeypatch.setattr(aura_ums.campaign, "simulate_campaign", spy)
    return seen


def test_simulate_options_override_the_scenarios_manager_table(ran: list[Scenario]) -> None:
    path = str(SCENARIOS / "paper_sidewalk.toml")
    result = runner.invoke(app, ["simulate", path, "--runs", "1", "--gate-only", "--missed-limit", "5"])
    assert result.exit_code == 0, result.output
    file = Scenario.from_toml(path).settings
    assert ran[-1].settings == dataclasses.replace(file, robust=False, missed_limit=5)
    assert ran[-1].settings.area_limit == file.area_limit == 25.0
    bad = runner.invoke(app, ["simulate", path, "--runs", "1", "--envelope-factor", "0.5"])
    assert bad.exit_code == 2
    assert "--envelope-factor: expected a number in [1, 100], got 0.5" in bad.output


@pytest.mark.parametrize(
    ("text", "radians"),
    [("2deg", math.radians(2.0)), ("2 deg", math.radians(2.0)), ("90°", math.pi / 2), ("0.034907", 0.034907)],
)
def test_an_angle_option_takes_radians_or_degrees(text: str, radians: float) -> None:
    tool, seen = recorder()
    result = runner.invoke(tool, ["x", "--slice-width", text, "--joint-sector", text])
    assert result.exit_code == 0, result.output
    assert seen[-1].slice_width == seen[-1].joint_sector == radians
    # 2 degrees is 180 cells of the heading grid, as 0.034907 is (0.0349 is 181)
    assert cell_count(seen[-1].slice_width) == (4 if radians > 1.0 else 180)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "2 degrees",
            "expected a number in (0, 2 pi] or none (radians, or degrees as 2deg), got '2 degrees'",
        ),
        ("deg", "expected a number in (0, 2 pi] or none (radians, or degrees as 2deg), got 'deg'"),
        ("400deg", "expected a number in (0, 2 pi] or none, got '400deg' (6.98132 rad)"),
        ("-1deg", "expected a number in (0, 2 pi] or none, got '-1deg' (-0.0174533 rad)"),
        ("nandeg", "expected a number in (0, 2 pi] or none, got 'nandeg' (nan rad)"),
    ],
)
def test_a_bad_angle_is_named_as_typed(text: str, message: str) -> None:
    tool, seen = recorder()
    result = runner.invoke(tool, ["x", "--slice-width", text])
    assert result.exit_code == 2
    assert result.stderr == f"error: --slice-width: {message}\n"
    assert not seen


def test_a_profile_is_the_base_of_the_options_given_one_by_one() -> None:
    tool, seen = recorder()
    assert runner.invoke(tool, ["x", "--profile", "relaxed"]).exit_code == 0
    assert seen[-1] == MapProfile.RELAXED.settings()
    given = ["x", "--profile", "relaxed", "--relaxed-window", "7", "--max-vertices", "20"]
    result = runner.invoke(tool, given)
    assert result.exit_code == 0, result.output
    assert seen[-1] == dataclasses.replace(MapProfile.RELAXED.settings(), relaxed_window=7, max_vertices=20)
    assert runner.invoke(tool, ["x", "--profile", "sliced", "--product-map"]).exit_code == 0
    assert seen[-1] == ManagerSettings()
    bad = runner.invoke(tool, ["x", "--profile", "sound"])
    assert bad.exit_code == 2
    assert "--profile" in bad.output
    assert "'sound' is not one of" in bad.output


def test_the_profile_help_names_the_options_it_sets() -> None:
    group = typer.main.get_command(app)
    option = next(p for p in group.commands["replay"].params if "--profile" in p.opts)  # type: ignore[attr-defined]
    assert "relaxed = --slice-width 2deg --max-slices 180 --relaxed-q 1 --relaxed-window 5," in option.help
    assert "sliced = --slice-width 2deg," in option.help
    assert "product = the defaults," in option.help


def test_simulate_profile_overrides_the_scenarios_map_keeps_the_rest(ran: list[Scenario]) -> None:
    path = str(SCENARIOS / "paper_sidewalk.toml")
    file = Scenario.from_toml(path).settings
    assert file.relaxed_q == 1  # the scenario's own relaxed intersection, which the profile turns off
    result = runner.invoke(app, ["simulate", path, "--runs", "1", "--profile", "sliced", "-q"])
    assert result.exit_code == 0, result.output
    assert ran[-1].settings == MapProfile.SLICED.settings(file)
    assert ran[-1].settings.area_limit == file.area_limit == 25.0
    shown = next(line for line in result.stdout.splitlines() if line.startswith("slice_width_rad"))
    assert float(shown.split()[1]) == pytest.approx(math.radians(2.0))


@pytest.mark.parametrize(
    "flag", ["--area-limit", "--envelope-max-vertices", "--slice-width", "--joint-above"]
)
def test_a_nullable_setting_takes_none_as_its_message_says(flag: str) -> None:
    # "expected ... or none" refused 'none' (typer's own parse, or the angle parser)
    tool, seen = recorder()
    base = {"area_limit": 4.0, "envelope_max_vertices": 20, "slice_width": 0.1, "joint_above": 1.0}
    start = ManagerSettings.from_dict(base)
    given = ["x", "--area-limit", "4", "--envelope-max-vertices", "20", "--slice-width", "0.1"]
    given += ["--joint-above", "1.0"]
    index = given.index(flag)
    given[index + 1] = "None"
    result = runner.invoke(tool, given)
    assert result.exit_code == 0, result.output
    name = flag.removeprefix("--").replace("-", "_")
    assert seen[-1] == ManagerSettings.from_dict({name: None}, base=start)
    # over a profile that sets it, too
    assert runner.invoke(tool, ["x", "--profile", "sliced", "--slice-width", "none"]).exit_code == 0
    assert seen[-1] == ManagerSettings()


@pytest.mark.parametrize(
    ("given", "message"),
    [
        (["--area-limit", "abc"], "--area-limit: expected a number in (0, 4e+12] or none, got 'abc'"),
        (["--area-limit", "1_0"], "--area-limit: expected a number in (0, 4e+12] or none, got '1_0'"),
        (
            ["--envelope-max-vertices", "1.5"],
            "--envelope-max-vertices: expected an integer >= 3 or none, got '1.5'",
        ),
        (["--slice-width", "1e-6"], "--slice-width: expected at least 0.00174533 rad (0.1 degree, 3600"),
        (["--sigmas", "1e300"], "--sigmas: expected a number in [0.1, 100], got 1e+300"),
        # typer's own conversion: a boxed "Invalid value for '--sigmas': Input should be a valid
        # number", without the value
        (["--sigmas", "abc"], "--sigmas: expected a number in [0.1, 100], got 'abc'"),
        (["--max-vertices", "1.5"], "--max-vertices: expected an integer >= 3, got '1.5'"),
        (
            ["--relaxed-q", "3", "--relaxed-window", "100"],
            "--relaxed-q: expected at most 2000 branches of the relaxed intersection",
        ),
        (
            ["--relaxed-window", "100000", "--profile", "relaxed"],
            "--relaxed-window: expected at most 2000 branches of the relaxed intersection",
        ),
    ],
)
def test_a_bad_nullable_or_costly_setting_is_named_with_its_option(given: list[str], message: str) -> None:
    tool, seen = recorder()
    result = runner.invoke(tool, ["x", *given])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error: {message}"), result.stderr
    assert not seen
