"""``aura_ums.Metrics``: one table of keys, checked values, strict and atomic JSON."""

from __future__ import annotations

import json
import math
import os
import stat
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums import Metrics
from aura_ums.errors import InputError

DOC = Path(__file__).resolve().parents[1] / "docs" / "metrics.md"
START = "<!-- metrics table: generated from aura_ums.Metrics.table(); tests/test_metrics.py checks it -->"
END = "<!-- end of the metrics table -->"
WRITERS = {
    "simulate",
    "replay",
    "replay (several logs)",
    "compare",
    "compare (per method)",
    "replay --steps-csv",
    "replay --camera",
    "replay --camera (per baseline)",
    "replay --windows-csv",
}
KINDS = {"text", "true/false", "integer", "count", "fraction", "number", "count by reason", "list of metrics"}
NUMERIC = [key.name for key in Metrics.table() if key.kind in ("number", "fraction")]


def strict_json(text: str) -> Any:
    """Parse JSON as the standard says: NaN, Infinity and -Infinity are errors."""

    def refuse(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def rendered_table() -> list[str]:
    lines = ["| key | unit | type | written by | meaning |", "| --- | --- | --- | --- | --- |"]
    for key in Metrics.table():
        writers = ", ".join(key.written_by)
        lines.append(f"| `{key.name}` | {key.unit} | {key.kind} | {writers} | {key.meaning} |")
    return lines


def test_the_table_has_one_row_per_key_and_only_known_types_and_writers() -> None:
    names = [key.name for key in Metrics.table()]
    assert len(names) == len(set(names))
    for key in Metrics.table():
        assert key.kind in KINDS, key
        assert key.written_by, key
        assert set(key.written_by) <= WRITERS, key
        assert key.meaning.endswith("."), key
        assert "|" not in key.meaning, key
        # A physical quantity's key ends in its unit.
        suffix = {"m²": "m2", "rad": "rad", "m": "m", "µs": "us", "ms": "ms"}.get(key.unit)
        if suffix is not None:
            assert key.name.endswith(suffix), key


def test_docs_show_the_table_exactly() -> None:
    text = DOC.read_text(encoding="utf-8").splitlines()
    assert START in text
    assert END in text
    shown = text[text.index(START) + 1 : text.index(END)]
    expected = rendered_table()
    assert shown == expected, "docs/metrics.md is stale; its table should read:\n" + "\n".join(expected)


def test_undefined_numbers_are_written_as_null_and_read_back_strictly(tmp_path: Path) -> None:
    metrics = Metrics(
        {
            "containment_rate": math.nan,
            "median_area_m2": math.inf,
            "median_wedge_width_rad": -math.inf,
            "median_update_us": np.float64(12.5),
            "steps": np.int64(3),
            "rejected_by_reason": {"stale": 2},
        }
    )
    assert metrics["containment_rate"] is None
    assert math.isnan(metrics.number("median_area_m2"))
    written = metrics.write_json(tmp_path / "new" / "m.json")
    parsed = strict_json(written.read_text(encoding="utf-8"))
    assert parsed == {
        "containment_rate": None,
        "median_area_m2": None,
        "median_wedge_width_rad": None,
        "median_update_us": 12.5,
        "steps": 3,
        "rejected_by_reason": {"stale": 2},
    }
    assert type(parsed["steps"]) is int
    with pytest.raises(ValueError, match="not JSON: NaN"):
        strict_json('{"containment_rate": NaN}')


@given(
    st.dictionaries(
        st.sampled_from(NUMERIC),
        st.floats(allow_nan=True, allow_infinity=True, min_value=None, max_value=None)
        | st.floats(min_value=0.0, max_value=1.0),
        max_size=len(NUMERIC),
    )
)
def test_any_numbers_give_strict_json_that_reads_back_equal(figures: dict[str, float]) -> None:
    kinds = {key.name: key.kind for key in Metrics.table()}
    figures = {
        # A fraction outside [0, 1] is refused (tested below); fold the draw into range.
        k: (abs(v) % 1.0 if kinds[k] == "fraction" and math.isfinite(v) else v)
        for k, v in figures.items()
    }
    metrics = Metrics(figures)
    parsed = strict_json(metrics.to_json())
    assert list(parsed) == list(figures)
    for name, value in figures.items():
        assert parsed[name] == (value if math.isfinite(value) else None)
    assert Metrics(parsed) == metrics


def test_a_rewrite_replaces_the_whole_file_and_leaves_no_temporary_file(tmp_path: Path) -> None:
    path = tmp_path / "m.json"
    path.write_text("old, and not JSON")
    Metrics({"steps": 1}).write_json(path)
    Metrics({"steps": 2, "method": "EKF"}).write_json(str(path))
    assert strict_json(path.read_text()) == {"steps": 2, "method": "EKF"}
    assert [p.name for p in tmp_path.iterdir()] == ["m.json"]
    # The usual mode of a new file (the umask's), not a temporary file's 0600.
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask


def test_a_failed_write_keeps_the_old_file_and_leaves_nothing_behind(tmp_path: Path) -> None:
    path = tmp_path / "m.json"
    Metrics({"steps": 1}).write_json(path)
    (tmp_path / "m.json.d").mkdir()
    with pytest.raises(IsADirectoryError, match=r"m\.json\.d"):
        Metrics({"steps": 2}).write_json(tmp_path / "m.json.d")
    assert strict_json(path.read_text()) == {"steps": 1}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json", "m.json.d"]
    blocked = tmp_path / "file"
    blocked.write_text("")
    with pytest.raises(OSError, match=r"File exists|Not a directory"):
        Metrics({"steps": 1}).write_json(blocked / "m.json")


def test_rows_nest_as_a_list_of_objects() -> None:
    rows = (Metrics({"method": "aura-ums", "containment_rate": 1.0}), Metrics({"method": "EKF"}))
    table = Metrics({"log": "r1", "methods": rows})
    assert strict_json(table.to_json()) == {
        "log": "r1",
        "methods": [{"method": "aura-ums", "containment_rate": 1.0}, {"method": "EKF"}],
    }
    assert table.lines() == (
        "log                          r1",
        "methods                      2 entries",
        "  method                       aura-ums",
        "  containment_rate             1",
        "  method                       EKF",
    )


def test_lines_are_readable() -> None:
    metrics = Metrics(
        {
            "prune": True,
            "median_area_m2": 31.160440526706363,
            "envelope_containment_rate": None,
            "rejected_by_reason": {},
            "accepted_observations": 1534,
        }
    )
    assert metrics.lines() == (
        "prune                        true",
        "median_area_m2               31.1604",
        "envelope_containment_rate    n/a",
        "rejected_by_reason           none",
        "accepted_observations        1534",
    )
    assert Metrics({"rejected_by_reason": {"stale": 2, "outside": 1}}).lines() == (
        "rejected_by_reason           stale 2, outside 1",
    )


@pytest.mark.parametrize(
    ("figures", "message"),
    [
        ({"area": 1.0}, r"expected a key of the metrics table \(docs/metrics\.md\), got 'area'"),
        ({3: 1.0}, r"expected a key of the metrics table \(docs/metrics\.md\), got 3"),
        (
            {"containment_rate": -0.1},
            r"\['containment_rate'\]: expected a fraction in \[0, 1\] or None, got -0\.1",
        ),
        ({"median_area_m2": "1.0"}, r"\['median_area_m2'\]: expected a number or None, got '1\.0'"),
        ({"median_area_m2": True}, r"\['median_area_m2'\]: expected a number or None, got True"),
        ({"steps": -1}, r"\['steps'\]: expected an integer >= 0, got -1"),
        ({"steps": 1.0}, r"\['steps'\]: expected an integer, got 1\.0"),
        ({"seed": False}, r"\['seed'\]: expected an integer, got False"),
        ({"prune": 1}, r"\['prune'\]: expected True or False, got 1"),
        ({"log": 7}, r"\['log'\]: expected text, got 7"),
        ({"rejected_by_reason": [("stale", 1)]}, r"expected a mapping of reasons to counts"),
        ({"rejected_by_reason": {1: 1}}, r"expected reasons as text, got 1"),
        (
            {"rejected_by_reason": {"stale": -2}},
            r"\['rejected_by_reason'\]\['stale'\]: expected an integer >= 0",
        ),
        ({"methods": "EKF"}, r"\['methods'\]: expected a sequence of Metrics, got 'EKF'"),
        ({"methods": [{"method": "EKF"}]}, r"\['methods'\]: expected a sequence of Metrics, got an item"),
    ],
)
def test_a_bad_key_or_value_is_refused_by_name(figures: dict[Any, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        Metrics(figures)


def test_metrics_are_read_only_and_compare_as_mappings() -> None:
    source = {"steps": 1, "rejected_by_reason": {"stale": 1}}
    metrics = Metrics(source)
    source["steps"] = 2
    assert metrics["steps"] == 1
    with pytest.raises(TypeError, match="does not support item assignment"):
        metrics["rejected_by_reason"]["stale"] = 3  # type: ignore[index]
    assert metrics == {"steps": 1, "rejected_by_reason": {"stale": 1}}
    assert Metrics({"steps": 1}) != Metrics({"steps": 2})
    with pytest.raises(InputError, match=r"Metrics: expected a mapping of keys to values, got list"):
        Metrics([("steps", 1)])  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"Metrics\.number: expected a numeric key, got 'log' \(text\)"):
        Metrics({"log": "r1"}).number("log")
