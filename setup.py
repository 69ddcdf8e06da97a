"""The optional C kernels of growth and the landmark reductions.

Everything else is configured in pyproject.toml. Without a C compiler the build skips the
extension and the numpy reference runs instead.
"""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "aura_ums.geometry._kernels",
            sources=["src/aura_ums/geometry/_kernels.c"],
            optional=True,
            extra_compile_args=["-O2", "-Wall"],
        )
    ]
)
