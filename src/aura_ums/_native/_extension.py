"""Whether the extension module of the compiled kernels was built (a C compiler was present)."""

from __future__ import annotations


def _built() -> bool:
    try:
        from aura_ums._native import _kernels  # noqa: F401
    except ImportError:
        return False
    return True


#: Whether the extension module ``aura_ums._native._kernels`` was built (and imports).
BUILT = _built()
