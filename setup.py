"""hexapod_workspace: orientation workspace of 6-DOF parallel manipulators.

Installs with pip on a machine without ROS (the CLI and the Python API), and as an ament_python
package under colcon (adds the ROS 2 node ``workspace_node``). ROS is never an install
requirement: rclpy comes from the ROS installation (apt) or from the ``ros`` test requirements.
"""

import re
import shutil
from glob import glob
from pathlib import Path

from setuptools import find_packages, setup
from setuptools.command.build_py import build_py

PACKAGE = "hexapod_workspace"
HERE = Path(__file__).resolve().parent
# The version's one definition is hexapod_workspace/_version.py (read here without importing
# the package, whose dependencies may not be installed yet).
VERSION = re.search(
    r'^__version__ = "([^"]+)"$',
    (HERE / PACKAGE / "_version.py").read_text(encoding="utf-8"),
    re.MULTILINE,
)[1]
# Data that lives at the top of the repository (where ROS users expect it) and is also needed by
# the installed Python package: the example parameters file and the interface definitions (the
# CLI writes MCAP schemas from them without ROS). Copied into hexapod_workspace/_data at build.
DATA_DIRS = {"config": "config", "msg": "msg_defs/msg", "srv": "msg_defs/srv"}


class BuildPyWithData(build_py):
    """build_py that also copies the top-level config and interface files into the package."""

    def run(self) -> None:
        super().run()
        for name, source in DATA_DIRS.items():
            target = Path(self.build_lib) / PACKAGE / "_data" / name
            target.mkdir(parents=True, exist_ok=True)
            for path in sorted((HERE / source).glob("*")):
                if path.suffix in {".yaml", ".msg", ".srv"}:
                    shutil.copy2(path, target / path.name)


setup(
    name=PACKAGE,
    version=VERSION,
    description="Orientation workspace of hexapods (Gough-Stewart platforms), CLI and ROS 2 node",
    long_description=(HERE / "README.md").read_text(encoding="utf-8"),
    long_description_content_type="text/markdown",
    license="Apache-2.0",
    python_requires=">=3.11",
    packages=find_packages(exclude=["test", "test.*", "benchmarks"]),
    package_data={PACKAGE: ["py.typed"]},
    cmdclass={"build_py": BuildPyWithData},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/config", glob("config/*.yaml") + glob("config/*.rviz")),
        (f"share/{PACKAGE}/launch", glob("launch/*.py")),
    ],
    install_requires=[
        # Lower bounds a ROS 2 Jazzy user on Ubuntu 24.04 meets with apt (python3-numpy 1.26,
        # python3-numba 0.59); tested against those in a venv, and the pins of requirements/.
        "numpy>=1.26",
        "numba>=0.59",
        "PyYAML>=5.4",
        "matplotlib>=3.6",
        "mcap>=1.6",
        "rosbags>=0.11",
    ],
    extras_require={
        # The workspace atlas engine (hexapod_workspace.atlas): pip install .[atlas]
        "atlas": ["dask[distributed]>=2024.12", "xarray>=2025.1", "zarr>=3.0"],
    },
    zip_safe=False,
    entry_points={
        "console_scripts": [
            "hexapod-workspace = hexapod_workspace.cli:main",
            "workspace_node = hexapod_workspace.ros:main",
        ],
    },
)
