"""Sphinx configuration of the aura-ums documentation (``make docs``).

Built with ``sphinx-build -W --keep-going -n``: every warning, unresolved cross-references
included, fails the build. Pages are MyST Markdown; the API reference comes from the
numpydoc docstrings, one page per public subpackage (``_ext/aura_api.py``).
"""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

import aura_ums  # noqa: E402 - the package must be installed (`make docs` does it)

project = "aura-ums"
author = "aura-ums developers"
copyright = "aura-ums developers, MIT license"
release = aura_ums.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "numpydoc",
    "myst_parser",
    "aura_api",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "Thumbs.db", ".DS_Store"]
nitpicky = True
suppress_warnings: list[str] = []

# Known docstring problems in the library, reported to their owners; each entry here is
# narrow (one name, one message) and goes away with the fix named beside it.
nitpick_ignore = [
    # External: no intersphinx inventory (the build is offline). perception/_lines.py LineBackend.
    ("py:func", "scipy.ndimage.label"),
    # Unqualified names of another subpackage that aura_ums does not export at the top:
    # sim/_loop.py LoopState -> ~aura_ums.manager.UncertaintyMapManager.to_json and
    # ~aura_ums.manager.Blackboard.to_json.
    ("py:meth", "UncertaintyMapManager.to_json"),
    ("py:meth", "Blackboard.to_json"),
    # Constants that are no longer public, named in docstrings of modules being rewritten:
    # expecter/_expecter.py Expecter.bounds -> ~aura_ums.geometry.UNBOUNDED_PIXELS and
    # Expecter.window -> DEFAULT_MARGINS (private: ~aura_ums.expecter.margin_pixels);
    # uncertainty/_joint.py reduce_jointly -> JOINT_INCONSISTENT (private: its reason text).
    ("py:data", "UNBOUNDED_PIXELS"),
    ("py:data", "DEFAULT_MARGINS"),
    ("py:data", "JOINT_INCONSISTENT"),
    # A private module is not documented: baselines/_ekf.py ExtendedKalmanFilter.region
    # -> :class:`ConfidenceRegion` (or :func:`ellipse_polygon`).
    ("py:mod", "aura_ums.baselines._region"),
]
# ``|z|``, ``|tilt|`` and ``|bearing error|`` in docstrings are absolute values, not reST
# substitutions (uncertainty/_map.py SpatialUncertaintyMap.grow, camera/_model.py
# CameraMount, logs/_calibrate.py calibrate_logs): render them as written until the
# docstrings put them in double backticks.
rst_prolog = """
.. |z| replace:: \\|z\\|
.. |tilt| replace:: \\|tilt\\|
.. |bearing error| replace:: \\|bearing error\\|
"""
# numpydoc drops sections it does not know, with a Python warning: FindLandmarkSchema's
# "Tracking window" and "Observations" (schemas/_schema.py) belong under "Notes".
warnings.filterwarnings(
    "ignore",
    message=r"Unknown section (Tracking Window|Observations) in the docstring of FindLandmarkSchema",
    category=UserWarning,
)

# MyST: ```{directive} fences, $math$, and heading anchors for [text](page.md#anchor) links.
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
myst_heading_anchors = 3

# autodoc: signatures without annotations (the numpydoc sections give every type, in
# words and units); members in source order; a public name is documented once, under its
# subpackage (see _ext/aura_api.py), so no canonical duplicates arise.
autodoc_typehints = "none"
autodoc_member_order = "bysource"
autodoc_inherit_docstrings = False
autodoc_class_signature = "mixed"
autoclass_content = "class"

# numpydoc: the docstrings' own sections; no generated member tables (they need stubs).
numpydoc_show_class_members = False
numpydoc_show_inherited_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_attributes_as_param_list = True
numpydoc_use_plots = False

html_theme = "furo"
html_title = f"aura-ums {release}"
html_static_path: list[str] = []
html_show_sourcelink = False
pygments_style = "friendly"
pygments_dark_style = "monokai"
