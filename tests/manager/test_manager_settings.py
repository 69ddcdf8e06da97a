"""ManagerSettings: defaults, units and ranges in one place; validation, to_dict and from_dict."""

from __future__ import annotations

import dataclasses
import json
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.manager import ManagerSettings, MapProfile, SettingInfo
from aura_ums.uncertainty import cell_count
from aura_ums.uncertainty._growth import DEFAULT_MAX_VERTICES
from aura_ums.uncertainty._joint import DEFAULT_SECTOR
from aura_ums.uncertainty._slices import DEFAULT_SLICE_WIDTH

FIELDS = dataclasses.fields(ManagerSettings)


def test_every_field_carries_its_info_and_a_valid_default() -> None:
    for field in FIELDS:
        info = SettingInfo.of(field)
        assert info.help
        assert not info.help.endswith(".")
        assert info.kind in (float, int, bool)
        assert info.problem(field.default) is None, field.name
        assert field.name in (ManagerSettings.__doc__ or ""), field.name  # documented from the info
    assert "max_vertices : int\n        Cap on the map polygon" in (ManagerSettings.__doc__ or "")


def test_the_defaults_are_the_library_defaults() -> None:
    # Written twice (the manager cannot import the uncertainty layer's private defaults):
    # here they are held equal.
    settings = ManagerSettings()
    assert (settings.max_vertices, settings.joint_sector) == (DEFAULT_MAX_VERTICES, DEFAULT_SECTOR)
    assert (settings.sigmas, settings.joint_above, settings.robust) == (3.0, math.pi / 2, True)
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign to field"):
        settings.sigmas = 2.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"sigmas": 0.0}, r"sigmas: expected a number in \[0\.1, 100\], got 0\.0"),
        ({"sigmas": "3"}, r"sigmas: expected a number in \[0\.1, 100\], got '3'"),
        ({"sigmas": None}, r"sigmas: expected a number in \[0\.1, 100\], got None"),
        # 1e300 overflowed the polygon's coordinates; 1e-300 bounded nothing
        ({"sigmas": 1e300}, r"sigmas: expected a number in \[0\.1, 100\], got 1e\+300"),
        ({"sigmas": 1e-300}, r"sigmas: expected a number in \[0\.1, 100\], got 1e-300"),
        ({"envelope_factor": 1e300}, r"envelope_factor: expected a number in \[1, 100\], got 1e\+300"),
        # 166,751 branches of the relaxed intersection: 2 GB and no end in 100 s
        (
            {"relaxed_q": 3, "relaxed_window": 100},
            r"relaxed_q: expected at most 2000 branches of the relaxed intersection \(the sum of "
            r"C\(relaxed_window, k\) for k <= relaxed_q\), got 166751 \(relaxed_q 3, relaxed_window 100\)",
        ),
        (
            {"relaxed_q": 99_999, "relaxed_window": 100_000},
            r"relaxed_q: expected at most 2000 branches .* got more than 1000000000000000 .*",
        ),
        ({"area_limit": -1.0}, r"area_limit: expected a number in \(0, 4e\+12\] or none, got -1\.0"),
        ({"area_limit": math.inf}, r"area_limit: expected a finite number in \(0, 4e\+12\] or none, got inf"),
        ({"area_limit": 1e300}, r"area_limit: expected a number in \(0, 4e\+12\] or none, got 1e\+300"),
        ({"missed_limit": 0}, "missed_limit: expected an integer >= 1, got 0"),
        ({"missed_limit": True}, "missed_limit: expected an integer >= 1, got True"),
        ({"lost_window_scale": 0.5}, r"lost_window_scale: expected a number in \[1, 100\], got 0\.5"),
        ({"joint_above": -0.1}, r"joint_above: expected a number in \[0, 2 pi\] or none, got -0.1"),
        ({"joint_above": math.nan}, r"joint_above: expected a finite number in \[0, 2 pi\] or none, got nan"),
        ({"joint_above": 1e300}, r"joint_above: expected a number in \[0, 2 pi\] or none, got 1e\+300"),
        ({"joint_sector": 0.0}, r"joint_sector: expected a number in \(0, 2 pi\], got 0.0"),
        ({"joint_sector": 7.0}, r"joint_sector: expected a number in \(0, 2 pi\], got 7.0"),
        # 2 pi / 1e-300 sectors: an OverflowError from the joint reduction's kernel before
        (
            {"joint_sector": 1e-300},
            r"joint_sector: expected at least 0\.00174533 rad \(0\.1 degree: .*got 1e-300",
        ),
        ({"max_vertices": 2}, "max_vertices: expected an integer >= 3, got 2"),
        ({"max_vertices": 16.0}, "max_vertices: expected an integer >= 3, got 16.0"),
        ({"max_vertices": 10**9}, r"max_vertices: expected an integer in \[3, 100000\], got 1000000000"),
        (
            {"envelope_max_vertices": 10**9},
            r"envelope_max_vertices: expected an integer in \[3, 100000\], got 1000000000",
        ),
        ({"max_slices": 10**9}, r"max_slices: expected an integer in \[1, 100000\], got 1000000000"),
        # 2 pi / 1e-12 heading cells: a ValueError traceback from the kernel before
        (
            {"slice_width": 1e-12},
            r"slice_width: expected at least 0\.00174533 rad \(0\.1 degree, 3600 heading cells; a step costs "
            r"in proportion to the cells\), got 1e-12",
        ),
        ({"robust": 1}, "robust: expected true or false, got 1"),
        ({"envelope_factor": 0.9}, r"envelope_factor: expected a number in \[1, 100\], got 0\.9"),
        ({"envelope_max_vertices": 1.5}, "envelope_max_vertices: expected an integer >= 3 or none, got 1.5"),
        ({"relocalize_after": 0}, "relocalize_after: expected an integer >= 1, got 0"),
        (
            {"relocalize_after": 3, "relocalize_window": 2},
            r"relocalize_window: expected an integer >= relocalize_after \(3\), got 2",
        ),
    ],
)
def test_bad_settings_are_refused_by_field_name(changes: dict[str, Any], message: str) -> None:
    with pytest.raises(InputError, match=f"^ManagerSettings.{message}$"):
        ManagerSettings(**changes)
    with pytest.raises(InputError, match=f"^ManagerSettings.{message}$"):
        ManagerSettings.from_dict(changes)


def test_numbers_are_normalized_to_the_fields_types() -> None:
    settings = ManagerSettings(sigmas=np.float32(2.5), max_vertices=np.int64(12), area_limit=4)  # type: ignore[arg-type]
    assert (type(settings.sigmas), type(settings.max_vertices), type(settings.area_limit)) == (
        float,
        int,
        float,
    )
    assert settings == ManagerSettings(sigmas=2.5, max_vertices=12, area_limit=4.0)


def test_from_dict_takes_a_base_and_names_places_through_fail() -> None:
    base = ManagerSettings(area_limit=9.0, robust=False)
    merged = ManagerSettings.from_dict({"sigmas": 2.0}, base=base)
    assert (merged.sigmas, merged.area_limit, merged.robust) == (2.0, 9.0, False)

    def fail(key: str, message: str) -> Exception:
        return KeyError(f"file.toml: [manager] {key}: {message}")

    with pytest.raises(KeyError, match=r"file\.toml: \[manager\] missed_limit: expected an integer >= 1"):
        ManagerSettings.from_dict({"missed_limit": 0}, fail=fail)
    with pytest.raises(KeyError, match=r"\[manager\] sigma: expected a field of ManagerSettings"):
        ManagerSettings.from_dict({"sigma": 3.0}, fail=fail)
    with pytest.raises(InputError, match="expected a mapping of field names to values, got list"):
        ManagerSettings.from_dict([("sigmas", 3.0)])  # type: ignore[arg-type]


valid = st.builds(
    ManagerSettings,
    sigmas=st.floats(0.1, 10.0),
    area_limit=st.none() | st.floats(0.1, 1e6),
    missed_limit=st.integers(1, 20),
    lost_window_scale=st.floats(1.0, 10.0),
    joint_above=st.none() | st.floats(0.0, 2 * math.pi),
    joint_sector=st.floats(2e-3, 2 * math.pi),
    max_vertices=st.integers(3, 500),
    robust=st.booleans(),
    envelope_factor=st.floats(1.0, 10.0),
    envelope_max_vertices=st.none() | st.integers(3, 500),
    relocalize_after=st.just(1),
    relocalize_window=st.integers(1, 10),
)


@given(valid)
def test_to_dict_is_strict_json_and_from_dict_restores_it(settings: ManagerSettings) -> None:
    text = json.dumps(settings.to_dict(), allow_nan=False)
    assert ManagerSettings.from_dict(json.loads(text)) == settings
    assert list(settings.to_dict()) == [field.name for field in FIELDS]


# --- profiles --------------------------------------------------------------------------------


@pytest.mark.parametrize("profile", list(MapProfile))
def test_a_profile_sets_its_fields_and_keeps_the_rest(profile: MapProfile) -> None:
    base = ManagerSettings(area_limit=25.0, robust=False, max_vertices=32)
    chosen = profile.settings(base)
    assert {name: getattr(chosen, name) for name in profile.fields} == dict(profile.fields)
    for field in FIELDS:
        if field.name not in profile.fields:
            assert getattr(chosen, field.name) == getattr(base, field.name), field.name
    # Whatever profile came before, a profile leads to the same settings: each sets the same fields.
    for other in MapProfile:
        assert profile.settings(other.settings(base)) == chosen


def test_the_profiles_are_the_product_map_the_sliced_map_and_the_relaxed_intersection() -> None:
    assert MapProfile.PRODUCT.settings() == ManagerSettings()
    sliced, relaxed = MapProfile.SLICED.settings(), MapProfile.RELAXED.settings()
    assert sliced.slice_width is not None
    assert cell_count(sliced.slice_width) == 180
    assert (sliced.relaxed_q, relaxed.relaxed_q) == (0, 1)
    # The width the map's own with_slices takes by default: one width measured best.
    assert relaxed.slice_width == sliced.slice_width == DEFAULT_SLICE_WIDTH
    assert relaxed.relaxed_window == 5 < ManagerSettings().relaxed_window
    # The relaxed map keeps every cell (merged neighbours widened its windows); the sliced map
    # keeps the default cap.
    assert relaxed.max_slices == cell_count(relaxed.slice_width) == 180
    assert sliced.max_slices == ManagerSettings().max_slices < 180
    assert MapProfile("relaxed") is MapProfile.RELAXED


def test_a_profiles_fields_cannot_be_changed() -> None:
    with pytest.raises(TypeError, match="does not support item assignment"):
        MapProfile.SLICED.fields["relaxed_q"] = 3  # type: ignore[index]
    assert MapProfile.SLICED.fields["relaxed_q"] == 0


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        # the relaxed profile at a cap of 100,000 vertices passed 4 GB and ignored Ctrl-C
        (
            {"slice_width": math.radians(2.0), "max_slices": 180, "relaxed_q": 1, "relaxed_window": 5,
             "max_vertices": 10_000},
            r"max_vertices: expected at most 4000000 vertices at the caps \(the vertex cap 10000 times 180 "
            r"slices times 6 branches of the relaxed intersection\), got 10800000",
        ),
        (
            {"slice_width": math.radians(2.0), "envelope_max_vertices": 100_000},
            r"envelope_max_vertices: expected at most 4000000 vertices at the caps .* got 4800000",
        ),
    ],
)  # fmt: skip
def test_caps_whose_worst_case_holds_too_many_vertices_are_refused(
    changes: dict[str, Any], message: str
) -> None:
    with pytest.raises(InputError, match=f"^ManagerSettings.{message}$"):
        ManagerSettings(**changes)
    # the profiles and a product map at the largest cap stay allowed
    assert ManagerSettings(max_vertices=100_000).max_vertices == 100_000
    assert MapProfile.RELAXED.settings().max_vertices == 64
