"""The exception hierarchy of aura-ums.

Every error the library raises on purpose derives from :class:`AuraUmsError`.
Errors caused by what a caller passed in (a value, an argument, a file) also
derive from :class:`ValueError`, so code that already catches ``ValueError``
keeps working. Messages read "expected ..., got ...".
"""

from __future__ import annotations

__all__ = [
    "AuraUmsError",
    "FileFormatError",
    "InputError",
    "MissingDependencyError",
    "OutsideMapError",
    "RunLostError",
    "UnknownLandmarkError",
    "UnknownTerrainError",
]


class AuraUmsError(Exception):
    """Base class of every error raised on purpose by aura-ums.

    Examples
    --------
    >>> from aura_ums.uncertainty import BearingObservation
    >>> try:
    ...     BearingObservation("pole_1", 0.0, 0.3, -0.01)
    ... except AuraUmsError as exc:   # catches every error aura-ums raises on purpose
    ...     print(type(exc).__name__, "-", exc)
    InputError - bearing_error: expected a non-negative number, got -0.01
    >>> issubclass(RunLostError, AuraUmsError), issubclass(AuraUmsError, ValueError)
    (True, False)
    """


class InputError(AuraUmsError, ValueError):
    """An argument or a value given to aura-ums is not what it expects.

    Examples
    --------
    >>> from aura_ums.camera import CameraMount
    >>> try:
    ...     CameraMount(height=-0.5)
    ... except ValueError as exc:   # an InputError is a ValueError too
    ...     print(type(exc).__name__, "-", exc)
    InputError - CameraMount.height: expected a height >= 0 m above the ground, got -0.5
    """


class OutsideMapError(InputError):
    """A position or a run lies outside every meadow of the meadow map.

    Examples
    --------
    >>> from aura_ums.world import make_grid_world, split_run
    >>> split_run(make_grid_world(1, 2), (100.0, 100.0), 0.0, 5.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.OutsideMapError: start, heading, distance: expected a run that meets a meadow, got ...
    >>> issubclass(OutsideMapError, InputError)
    True
    """


class MissingDependencyError(AuraUmsError, ImportError):
    """An optional dependency (an extra such as ``opencv``) is needed but not installed.

    Examples
    --------
    >>> try:
    ...     raise MissingDependencyError("a campaign needs the package 'dask'; install aura-ums[dask]")
    ... except ImportError as exc:   # an ImportError too, not a ValueError
    ...     print(exc)
    a campaign needs the package 'dask'; install aura-ums[dask]
    """


class RunLostError(AuraUmsError):
    """A run of a campaign was lost (its worker died or it timed out) more often than its retries allow.

    Examples
    --------
    >>> lost = RunLostError("run 3: expected it to finish within 2 retries, got it lost 3 times")
    >>> isinstance(lost, AuraUmsError), isinstance(lost, ValueError)   # not the caller's input
    (True, False)
    """


class FileFormatError(InputError):
    """A file read by aura-ums is missing, unreadable or malformed.

    The message reads ``file:line: expected ..., got ...`` when the place is a line, and
    ``file: key path: expected ..., got ...`` when it is a key (a table, a property).

    Parameters
    ----------
    path : str
        The file, as the caller named it.
    where : str
        The place in the file (a table, a key path, a byte offset), or ``""`` for the
        whole file or a line alone.
    message : str
        What was expected and what was found.
    line, column : int, optional
        1-based line (and column) of the place, written after the file name.

    Examples
    --------
    >>> str(FileFormatError("log/odometry.csv", "", "expected 3 cells, got 2", line=7))
    'log/odometry.csv:7: expected 3 cells, got 2'
    >>> str(FileFormatError("cam.toml", "[mount] height", "expected a finite number, got 'tall'"))
    "cam.toml: [mount] height: expected a finite number, got 'tall'"
    >>> str(FileFormatError("map.geojson", "", "expected valid JSON, got Expecting value", line=1, column=9))
    'map.geojson:1:9: expected valid JSON, got Expecting value'
    """

    #: How the message of a file that could not be written begins; the reason follows.
    UNWRITABLE = "expected a writable file, got "

    def __init__(
        self, path: str, where: str, message: str, *, line: int | None = None, column: int | None = None
    ) -> None:
        self.path = path
        self.where = where
        self.message = message
        self.line = line
        self.column = column
        location = path
        if line is not None:
            location += f":{line}" if column is None else f":{line}:{column}"
        if where:
            location += f": {where}"
        super().__init__(f"{location}: {message}")

    @classmethod
    def unwritable(cls, path: str, reason: OSError | str) -> FileFormatError:
        """Return the error of a file that could not be written, for an ``OSError`` or a reason.

        Examples
        --------
        >>> str(FileFormatError.unwritable("out/steps.csv", OSError(28, "No space left on device")))
        'out/steps.csv: expected a writable file, got No space left on device'
        """
        if isinstance(reason, OSError):
            reason = reason.strerror or str(reason)
        return cls(path, "", f"{cls.UNWRITABLE}{reason}")


class UnknownTerrainError(InputError, KeyError):
    """A name (a terrain, a meadow) is not in the table it was looked up in.

    It is a :class:`KeyError` too, so ``Mapping.get`` and ``in`` work as usual.

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> table = TerrainTable.default()
    >>> table["lava"]
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownTerrainError: terrain: expected one of concrete, grass, gravel, tile, got 'lava'
    >>> "lava" in table, table.get("lava")   # a KeyError: the Mapping methods still work
    (False, None)
    """

    def __str__(self) -> str:
        # KeyError would quote the message; keep it readable.
        return str(self.args[0]) if self.args else ""


class UnknownLandmarkError(InputError, KeyError):
    """A landmark id is not in the map (or log) it was looked up in.

    It is a :class:`KeyError` too, so ``Mapping.get`` and ``in`` work as usual.

    Examples
    --------
    >>> from aura_ums.world import sample_world
    >>> sample_world("paper_sidewalk").landmark("lamppost_999")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownLandmarkError: landmark: expected the id of a landmark ..., got 'lamppost_999'
    """

    def __str__(self) -> str:
        # KeyError would quote the message; keep it readable.
        return str(self.args[0]) if self.args else ""
