"""Sphinx configuration of the hexapod_workspace documentation (``make docs``).

Built with ``-W --keep-going -n``: every warning is an error and every cross reference to the
package's own objects must resolve. Reference pages (CLI, ROS interfaces, parameters) and the
tutorial's figures are generated from the code at build time by ``_ext/hexapod_docs.py``.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
# The working tree, not an installed copy (the ROS environment puts install/ on the path).
sys.path[:0] = [str(HERE.parent), str(HERE / "_ext")]

from hexapod_workspace import __version__  # noqa: E402

project = "hexapod_workspace"
author = "hexapod_workspace contributors"
copyright = "hexapod_workspace contributors, Apache-2.0"
release = version = __version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "hexapod_docs",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "_generated/**/*.md", "images"]
templates_path: list[str] = []
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

html_theme = "furo"
html_title = f"hexapod_workspace {release}"
html_static_path: list[str] = []

# ---------------------------------------------------------------- API reference
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # numpydoc's Parameters/Returns carry shapes, units and frames
autodoc_default_options = {"members": True, "show-inheritance": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# The docstrings follow numpydoc's sections; the checks below are numpydoc's validation,
# limited to what the build should refuse (unknown sections).
numpydoc_validation_checks = {"GL06"}

# ---------------------------------------------------------------- nitpicky
# Every reference to this package's own objects must resolve. Third-party objects cannot: the
# build runs offline (no intersphinx inventories of Python, numpy, rclpy, xarray, dask are
# fetched), so references into these packages are listed here, by package, and only these.
nitpicky = True
_THIRD_PARTY = (
    "numpy",
    "np",
    "numpy.typing",
    "NDArray",
    "ArrayLike",
    "xarray",
    "dask",
    "distributed",
    "zarr",
    "rclpy",
    "mcap",
    "mcap_ros2",
    "rosbags",
    "matplotlib",
    "yaml",
    "pathlib",
    "os",
    "collections",
    "collections.abc",
    "typing",
    "enum",
    "argparse",
    "multiprocessing",
    "threading",
    "dataclasses",
    "sensor_msgs",
    "hexapod_workspace_msgs",
    "std_msgs",
    "rcl_interfaces",
)
_PACKAGES = "|".join(re.escape(name) for name in _THIRD_PARTY)
nitpick_ignore_regex = [
    (r"py:.*", rf"({_PACKAGES})(\..*)?"),
    # Builtin types and Python's own vocabulary in numpydoc type fields.
    (r"py:.*", r"(int|float|bool|str|bytes|object|None|type|Exception|ValueError|KeyError)"),
]
