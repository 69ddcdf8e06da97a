"""The numeric CSV rows: compiled (``csv.c``) against numpy's loadtxt, its reference, bit for bit."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums._native._csv import parse_float_rows_compiled, parse_float_rows_reference
from tests._native.native_helpers import built

# Every float64 but NaN and the infinities (the logs refuse them anyway, the slow way).
FINITE = st.floats(allow_nan=False, allow_infinity=False)
# How a writer may spell a number: repr, C's %g, %.9f (rounded first), %e, with a plus sign.
SPELLINGS = st.sampled_from(["{!r}", "{:g}", "{:.9f}", "{:.17e}", "{:+.3E}", "{:.0f}."])
BLANKS = st.sampled_from(["", " ", "\t", "  "])


def bits(values: np.ndarray) -> list[bytes]:
    return [struct.pack("<d", value) for value in values.ravel().tolist()]


@st.composite
def tables(draw: st.DrawFn) -> tuple[bytes, int, int]:
    rows = draw(st.integers(0, 6))
    columns = draw(st.integers(1, 5))
    lines = []
    for _ in range(rows):
        cells = []
        for _ in range(columns):
            value = draw(FINITE)
            text = draw(SPELLINGS).format(value)
            cells.append(draw(BLANKS) + text + draw(BLANKS))
        lines.append(",".join(cells))
    text = "\n".join(lines) + ("\n" if rows and draw(st.booleans()) else "")
    return text.encode("ascii"), rows, columns


@built
@given(tables())
def test_compiled_reads_every_plain_number_as_the_reference_does(table: tuple[bytes, int, int]) -> None:
    data, rows, columns = table
    ours = parse_float_rows_compiled(data, rows, columns)
    reference = parse_float_rows_reference(data, rows, columns)
    assert ours is not None, data
    assert reference is not None, data
    assert ours.shape == reference.shape == (rows, columns)
    assert bits(ours) == bits(reference)


@built
@given(tables(), st.integers(0, 2**32 - 1))
def test_a_changed_byte_gives_none_or_what_float_reads(table: tuple[bytes, int, int], seed: int) -> None:
    """Whatever the bytes, the compiled kernel never gives a number ``float`` would not."""
    data, rows, columns = table
    if not data:
        return
    rng = np.random.default_rng(seed)
    spoilt = bytearray(data)
    spoilt[int(rng.integers(len(spoilt)))] = int(rng.choice(list(b"0123456789.,eE+-_ \tnaxif\n#")))
    ours = parse_float_rows_compiled(bytes(spoilt), rows, columns)
    if ours is None:
        return
    cells = [cell for line in bytes(spoilt).decode().splitlines() for cell in line.split(",")]
    assert bits(ours) == bits(np.array([float(cell) for cell in cells]))


@built
@pytest.mark.parametrize(
    ("data", "rows", "columns"),
    [
        (b"nan,1\n", 1, 2),  # not plain: the slow way names it
        (b"inf,1\n", 1, 2),
        (b"0x1p3,1\n", 1, 2),
        (b"1_0,1\n", 1, 2),
        (b"1e,1\n", 1, 2),
        (b".,1\n", 1, 2),
        (b"- 1,1\n", 1, 2),
        (b"1,\n", 1, 2),  # an empty cell
        (b"1,2,3\n", 1, 2),  # a cell too many
        (b"1\n", 1, 2),  # one too few
        (b"1,2\n3,4\n", 1, 2),  # a row too many
        (b"1,2\n", 2, 2),  # one too few
        (b"1,2\n\n", 1, 2),  # a blank line (the caller drops those)
        (b"1;2\n", 1, 2),
        (b"1," + b"1" * 401 + b"\n", 1, 2),  # longer than the kernel reads
    ],
)
def test_anything_but_the_plain_rows_gives_none(data: bytes, rows: int, columns: int) -> None:
    assert parse_float_rows_compiled(data, rows, columns) is None


@built
def test_edge_cases_match_the_reference() -> None:
    cases = [
        (b"", 0, 3),  # no rows
        (b"-0,+0,0.\n", 1, 3),  # signed zeros
        (b"1e-400,4.9e-324,2.2250738585072011e-308\n", 1, 3),  # underflow, the least subnormal
        (b"1.7976931348623157e308,1e309\n", 1, 2),  # the largest float, and beyond: inf
        (b"0.1,0.2,0.30000000000000004\n", 1, 3),
        (b"9007199254740993,1\n", 1, 2),  # halfway between two floats: rounds to even
    ]
    for data, rows, columns in cases:
        ours = parse_float_rows_compiled(data, rows, columns)
        reference = parse_float_rows_reference(data, rows, columns)
        assert ours is not None, data
        assert reference is not None, data
        assert bits(ours) == bits(reference), data


@built
def test_the_arguments_are_checked() -> None:
    from aura_ums._native._kernels import parse_float_rows

    with pytest.raises(TypeError, match="expects 3 arguments"):
        parse_float_rows(b"1\n", 1)  # type: ignore[call-arg]
    with pytest.raises(ValueError, match="columns"):
        parse_float_rows(b"1\n", 1, 0)
    with pytest.raises(TypeError, match="bytes-like"):
        parse_float_rows("1\n", 1, 1)  # type: ignore[arg-type]


@built
def test_short_decimals_and_their_exponent_edges_read_as_float_does() -> None:
    # The fast path (Clinger: <= 15 significant digits times an exact power of ten within
    # 1e22) against float(), bit for bit, at and beyond its edges: 15/16 digits, 1e22/1e23,
    # leading and trailing zeros, signs, exponents written both ways.
    rng = np.random.default_rng(20261129)
    cells = []
    for _ in range(40_000):
        digits = int(rng.integers(1, 18))
        mantissa = "".join(str(d) for d in rng.integers(0, 10, digits))
        point = int(rng.integers(0, digits + 1))
        text = (mantissa[:point] or "0") + "." + mantissa[point:] if rng.random() < 0.8 else mantissa
        text = "0" * int(rng.integers(0, 3)) + text + "0" * int(rng.integers(0, 3) if "." in text else 0)
        if rng.random() < 0.5:
            text += "eE"[int(rng.integers(2))] + str(int(rng.integers(-30, 31)))
        if rng.random() < 0.3:
            text = "-+"[int(rng.integers(2))] + text
        cells.append(text)
    data = ("\n".join(",".join(cells[i : i + 4]) for i in range(0, len(cells), 4)) + "\n").encode()
    ours = parse_float_rows_compiled(data, len(cells) // 4, 4)
    assert ours is not None
    assert bits(ours) == bits(np.array([float(cell) for cell in cells]))
