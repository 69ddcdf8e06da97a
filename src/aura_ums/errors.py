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
    "UnknownLandmarkError",
    "UnknownTerrainError",
]


class AuraUmsError(Exception):
    """Base class of every error raised on purpose by aura-ums."""


class InputError(AuraUmsError, ValueError):
    """An argument or a value given to aura-ums is not what it expects."""


class OutsideMapError(InputError):
    """A position or a run lies outside every meadow of the meadow map."""


class MissingDependencyError(AuraUmsError, ImportError):
    """An optional dependency (an extra such as ``opencv``) is needed but not installed."""


class FileFormatError(InputError):
    """A file read by aura-ums is missing, unreadable or malformed.

    Parameters
    ----------
    path : str
        The file, as the caller named it.
    where : str
        The place in the file (a table, a key, a line), or ``""`` for the whole file.
    message : str
        What was expected and what was found.
    """

    def __init__(self, path: str, where: str, message: str) -> None:
        self.path = path
        self.where = where
        self.message = message
        location = f"{path}: {where}" if where else path
        super().__init__(f"{location}: {message}")


class UnknownTerrainError(InputError, KeyError):
    """A name (a terrain, a meadow) is not in the table it was looked up in.

    It is a :class:`KeyError` too, so ``Mapping.get`` and ``in`` work as usual.
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
