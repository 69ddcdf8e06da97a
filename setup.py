"""The optional C kernels of aura_ums._native: one extension module, one C source per concept.

Everything else is configured in pyproject.toml. Without a C compiler the build skips the
extension and the numpy reference runs instead (docs/installation.md).
"""

from pathlib import Path

from setuptools import Extension, setup

NATIVE = Path("src/aura_ums/_native")
SOURCES = [
    "args.c",
    "polygon.c",
    "growth.c",
    "reduce.c",
    "expecter.c",
    "distance.c",
    "slices.c",
    "csv.c",
    "module.c",
]

setup(
    ext_modules=[
        Extension(
            "aura_ums._native._kernels",
            sources=[str(NATIVE / name) for name in SOURCES],
            depends=[str(NATIVE / "kernels.h")],
            include_dirs=[str(NATIVE)],
            optional=True,
            # Hidden: the kernels' helpers share one namespace; only PyInit__kernels leaves it.
            extra_compile_args=["-O2", "-Wall", "-fvisibility=hidden"],
        )
    ]
)
