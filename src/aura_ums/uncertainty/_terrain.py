"""Terrain statistics, the turn-and-run generative model, and terrain tables from TOML."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._files import Fields, key_path, load_toml
from aura_ums._validate import Range, check_rng, float_array, positive_float
from aura_ums.errors import FileFormatError, InputError, UnknownTerrainError
from aura_ums.uncertainty._motion import Pose, TurnAndRun

#: A key TOML takes without quotes.
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")

_FRACTION = Range(0.0, 1.0, "", high_open=True)
_SD = Range(0.0, 10.0, "")
_ALTERNATE_UNITS = {"drift_deg_per_m": ("drift", math.pi / 180.0)}


@dataclass(frozen=True, slots=True)
class TerrainStats:
    """Slippage statistics of the robot on one terrain type (DESIGN §3).

    Each field's physical range is in its metadata (``"range"``, an
    ``aura_ums._validate.Range``) and :meth:`field_ranges`; a value outside it is an
    error, not a statistic (a drift of 1e20 rad/m would make every map a full disk).

    Parameters
    ----------
    translation_loss : float
        Mean translational loss, fraction in [0, 1) (0.10: 20 m commanded, 18 m run).
    translation_inertial_loss : float
        Fixed loss per move from acceleration and braking, metres, in [0, 10].
    translation_sd : float
        Standard deviation of the translational error, fraction of the distance, in [0, 10].
    drift : float
        Bound on the heading change per metre run, either side, rad/m, in [0, 10].
    rotation_loss : float
        Mean rotational loss, fraction in [0, 1).
    rotation_sd : float
        Standard deviation of the rotational error, fraction of the turn, in [0, 10].
    skitter : float
        Mean translation per radian turned, m/rad, in [0, 10].
    skitter_sd : float
        Standard deviation of the skitter, m/rad, in [0, 10].

    Examples
    --------
    >>> stats = TerrainStats(0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    >>> stats.sample_motion(Pose(0, 0, 0), TurnAndRun(0.0, 20.0), np.random.default_rng(0)).x
    18.0
    >>> TerrainStats(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: translation_loss: expected a number in [0, 1), got 1.0
    >>> TerrainStats(0.1, 0.0, 0.0, 1e20, 0.0, 0.0, 0.0, 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: drift: expected a number in [0, 10] rad/m, got 1e+20
    """

    translation_loss: float = field(metadata={"range": _FRACTION})
    translation_inertial_loss: float = field(metadata={"range": Range(0.0, 10.0, "m")})
    translation_sd: float = field(metadata={"range": _SD})
    drift: float = field(metadata={"range": Range(0.0, 10.0, "rad/m")})
    rotation_loss: float = field(metadata={"range": _FRACTION})
    rotation_sd: float = field(metadata={"range": _SD})
    skitter: float = field(metadata={"range": Range(0.0, 10.0, "m/rad")})
    skitter_sd: float = field(metadata={"range": Range(0.0, 10.0, "m/rad")})

    def __post_init__(self) -> None:
        for item in fields(self):
            bounds: Range = item.metadata["range"]
            object.__setattr__(self, item.name, bounds.check(getattr(self, item.name), item.name))

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """Return the names of the statistics, in declaration order."""
        return tuple(f.name for f in fields(cls))

    @classmethod
    def field_ranges(cls) -> dict[str, Range]:
        """Return each statistic's physical range, in declaration order.

        Examples
        --------
        >>> TerrainStats.field_ranges()["drift"].text()
        'a number in [0, 10] rad/m'
        """
        return {f.name: f.metadata["range"] for f in fields(cls)}

    @classmethod
    def zero(cls) -> TerrainStats:
        """Return statistics of a perfect terrain: every motion goes exactly as commanded."""
        return cls(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    def sample_motion(
        self,
        pose: Pose,
        command: TurnAndRun,
        rng: np.random.Generator,
        *,
        truncate: float | None = None,
    ) -> Pose:
        """Draw the true pose after ``command`` from ``pose`` under this terrain's model.

        The model (DESIGN §3): the actual turn is ``turn * clip(1 - rotation_loss +
        rotation_sd*z1, 0, 1)``; skitter moves the robot ``|turn| * max(0, skitter +
        skitter_sd*z2)`` metres in a uniformly random direction; the actual run is
        ``clip(run*(1 - translation_loss + translation_sd*z3) - translation_inertial_loss,
        0, run)``, along a circular arc whose heading changes by ``drift * run * u``.

        Parameters
        ----------
        pose : Pose
            True pose before the command.
        command : TurnAndRun
            The commanded motion.
        rng : numpy.random.Generator
            Source of randomness.
        truncate : float, optional
            Clip the standard normals z1..z3 to +-``truncate``; None leaves them Gaussian.

        Returns
        -------
        Pose
            The true pose after the command.
        """
        if not isinstance(pose, Pose):
            raise InputError(f"pose: expected a Pose, got {type(pose).__name__} {pose!r}")
        result = self.sample_motions(pose.as_array(), command, rng, truncate=truncate)
        return Pose(float(result[0, 0]), float(result[0, 1]), float(result[0, 2]))

    def sample_motions(
        self,
        poses: ArrayLike,
        command: TurnAndRun,
        rng: np.random.Generator,
        *,
        truncate: float | None = None,
    ) -> NDArray[np.float64]:
        """Draw true poses after ``command`` for many poses at once (see :meth:`sample_motion`).

        Parameters
        ----------
        poses : array_like, shape (n, 3) or (3,)
            Rows of ``x`` (m), ``y`` (m), ``heading`` (rad).

        Returns
        -------
        ndarray, shape (n, 3)
            The poses after the command, headings wrapped to (-pi, pi].
        """
        state = float_array(poses, "poses")
        if state.ndim == 1:
            state = state.reshape(1, -1)
        if state.ndim != 2 or state.shape[1] != 3:
            raise InputError(f"poses: expected shape (n, 3), got {state.shape}")
        if not isinstance(command, TurnAndRun):
            raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__} {command!r}")
        check_rng(rng)
        if truncate is not None:
            try:
                truncate = positive_float(truncate, "truncate")
            except InputError:
                raise InputError(
                    f"truncate: expected a positive finite number or None, got {truncate!r}"
                ) from None
        n = len(state)
        z = rng.standard_normal((3, n))
        if truncate is not None:
            z = np.clip(z, -truncate, truncate)
        skitter_direction = rng.uniform(-math.pi, math.pi, n)
        drift_fraction = rng.uniform(-1.0, 1.0, n)

        turn = command.turn * np.clip(1.0 - self.rotation_loss + self.rotation_sd * z[0], 0.0, 1.0)
        skitter = abs(command.turn) * np.maximum(0.0, self.skitter + self.skitter_sd * z[1])
        run = np.clip(
            command.run * (1.0 - self.translation_loss + self.translation_sd * z[2])
            - self.translation_inertial_loss,
            0.0,
            command.run,
        )
        heading_change = self.drift * run * drift_fraction
        heading = state[:, 2] + turn
        # A circular arc of length `run` turning by `heading_change` ends at a chord of
        # length run*sinc(change/2) along the mean heading of the arc.
        chord = run * np.sinc(heading_change / (2.0 * math.pi))
        chord_direction = heading + heading_change / 2.0
        out = np.empty_like(state)
        out[:, 0] = state[:, 0] + skitter * np.cos(skitter_direction) + chord * np.cos(chord_direction)
        out[:, 1] = state[:, 1] + skitter * np.sin(skitter_direction) + chord * np.sin(chord_direction)
        wrapped = np.pi - np.mod(np.pi - (heading + heading_change), 2.0 * math.pi)
        out[:, 2] = np.where(wrapped <= -np.pi, wrapped + 2.0 * math.pi, wrapped)
        return out


# Illustrative figures only: the paper's measured table is not in its text. They are
# of plausible size for a slow wheeled robot; calibrate your own (`aura-ums calibrate`).
_DEFAULT_TABLE: dict[str, TerrainStats] = {
    "tile": TerrainStats(0.02, 0.01, 0.01, math.radians(0.3), 0.02, 0.02, 0.01, 0.005),
    "concrete": TerrainStats(0.03, 0.015, 0.015, math.radians(0.5), 0.02, 0.03, 0.02, 0.01),
    "grass": TerrainStats(0.10, 0.03, 0.04, math.radians(1.5), 0.06, 0.06, 0.05, 0.02),
    "gravel": TerrainStats(0.07, 0.025, 0.03, math.radians(1.0), 0.05, 0.05, 0.04, 0.02),
}


@dataclass(frozen=True, slots=True, eq=False)
class TerrainTable(Mapping[str, TerrainStats]):
    """A read-only mapping from terrain name to :class:`TerrainStats`.

    Examples
    --------
    >>> table = TerrainTable.default()
    >>> sorted(table)
    ['concrete', 'grass', 'gravel', 'tile']
    >>> table["sand"]
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownTerrainError: terrain: expected one of concrete, grass, gravel, tile, got 'sand'
    """

    entries: Mapping[str, TerrainStats]

    def __post_init__(self) -> None:
        if not isinstance(self.entries, Mapping):
            raise InputError(
                f"entries: expected a mapping of terrain names to TerrainStats, got {self.entries!r}"
            )
        checked: dict[str, TerrainStats] = {}
        for name, stats in dict(self.entries).items():
            if not isinstance(name, str) or not name:
                raise InputError(f"terrain name: expected a non-empty string, got {name!r}")
            if not isinstance(stats, TerrainStats):
                raise InputError(f"terrain {name!r}: expected TerrainStats, got {type(stats).__name__}")
            checked[name] = stats
        object.__setattr__(self, "entries", MappingProxyType(checked))

    @classmethod
    def default(cls) -> TerrainTable:
        """Return the built-in table: tile, concrete, grass and gravel.

        The figures are illustrative (the paper's measured table is not in its text);
        calibrate a table for your own robot and terrain.
        """
        return cls(_DEFAULT_TABLE)

    @classmethod
    def from_toml(cls, path: str | Path) -> TerrainTable:
        """Read a terrain table from a TOML file: one table per terrain, keys as in TerrainStats.

        ``drift_deg_per_m`` may be given instead of ``drift`` (rad/m).

        Raises
        ------
        FileFormatError
            Naming the file, the terrain and the key, for unreadable files, malformed
            TOML, unknown or missing keys and values out of range.
        """
        return cls.from_mapping(load_toml(path, kind="terrain table TOML"), source=str(path))

    @classmethod
    def from_mapping(cls, document: Mapping[str, object], *, source: str = "<mapping>") -> TerrainTable:
        """Build a table from nested mappings as TOML gives them (see :meth:`from_toml`)."""
        if not isinstance(document, Mapping):
            raise FileFormatError(
                source, "", f"expected a mapping of terrain tables, got {type(document).__name__}"
            )
        if not document:
            raise FileFormatError(source, "", "expected at least one terrain table, got none")
        reader = Fields(source)
        names = TerrainStats.field_names()
        entries: dict[str, TerrainStats] = {}
        for terrain, table in document.items():
            where = f"[{terrain}]"
            if not isinstance(table, Mapping):
                raise reader.error(where, f"expected a table of statistics, got {reader.describe(table)}")
            values: dict[str, float] = {}
            for key, raw in table.items():
                target, scale = _ALTERNATE_UNITS.get(key, (key, 1.0))
                if target not in names:
                    reader.keys({key: raw}, names, where)
                if target in values:
                    raise reader.error(key_path(where, key), f"expected {target} once, got it twice")
                values[target] = reader.number(raw, key_path(where, key)) * scale
            missing = [name for name in names if name not in values]
            if missing:
                raise reader.error(where, f"expected keys {', '.join(missing)}, got none for them")
            try:
                entries[terrain] = TerrainStats(**values)
            except InputError as exc:
                key, _, message = str(exc).partition(": ")
                raise reader.error(key_path(where, key), message) from exc
        return cls(entries)

    def to_toml(self) -> str:
        r"""Return the table as TOML text that :meth:`from_toml` reads back exactly.

        Examples
        --------
        >>> table = TerrainTable({'wet "grass"': TerrainTable.default()["grass"]})
        >>> print(table.to_toml().splitlines()[0])   # a name TOML must quote, escaped
        ["wet \"grass\""]
        """
        lines: list[str] = []
        for terrain, stats in self.entries.items():
            lines.append(f"[{_toml_key(terrain)}]")
            lines.extend(f"{name} = {getattr(stats, name)!r}" for name in TerrainStats.field_names())
            lines.append("")
        return "\n".join(lines)

    def require(self, name: str, *, where: str, whose: str) -> None:
        """Refuse a table without the terrain ``name`` that ``whose`` needs, naming ``where``.

        The one check behind every command and reader that pairs a log (or a scenario)
        with a terrain table, so that each says the same thing.

        Parameters
        ----------
        name : str
            The terrain needed.
        where : str
            What to name in the error: an argument, option or file (``"table"``).
        whose : str
            Who needs it (``"the log (its meta.toml)"``).

        Raises
        ------
        UnknownTerrainError
            Reading "<where>: expected the terrain <name> of <whose>, got <the table's terrains>".

        Examples
        --------
        >>> table = TerrainTable.default()
        >>> table.require("grass", where="table", whose="the log")   # present: nothing happens
        >>> table.require("floor", where="t.toml", whose="the log")  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        aura_ums.errors.UnknownTerrainError: t.toml: expected the terrain 'floor' of the log, got 'tile', ...
        """
        for label, value in (("where", where), ("whose", whose)):
            if not isinstance(value, str):
                raise InputError(f"{label}: expected a str, got {type(value).__name__}")
        if not isinstance(name, str):
            raise InputError(f"{where}: expected a terrain name (a str), got {type(name).__name__}")
        if name in self.entries:
            return
        held = ", ".join(repr(entry) for entry in self.entries) or "none"
        raise UnknownTerrainError(f"{where}: expected the terrain {name!r} of {whose}, got {held}")

    def __getitem__(self, name: str) -> TerrainStats:
        try:
            return self.entries[name]
        except KeyError:
            known = ", ".join(sorted(self.entries))
            raise UnknownTerrainError(f"terrain: expected one of {known}, got {name!r}") from None
        except TypeError:  # unhashable: checked only here, off the lookups' path
            raise InputError(f"terrain: expected a terrain name (a str), got {type(name).__name__}") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self.entries)


def _toml_key(name: str) -> str:
    """Return ``name`` as a TOML key: bare when TOML allows it, else a basic string with escapes."""
    if _BARE_KEY.fullmatch(name):
        return name
    # JSON's escapes are TOML's, but for DEL, which TOML wants escaped too.
    return json.dumps(name, ensure_ascii=False).replace("\x7f", "\\u007f")
