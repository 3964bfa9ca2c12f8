"""The core must import without ROS: numpy, numba and the standard library only."""

from __future__ import annotations

import subprocess
import sys

CORE = [
    "hexapod_workspace",
    "hexapod_workspace.core.manipulator",
    "hexapod_workspace.core.rotations",
    "hexapod_workspace.core.constraints",
]


def test_core_imports_without_rclpy_or_yaml():
    # Block rclpy, ROS message packages and PyYAML, then import the core in a fresh process.
    code = (
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        root = name.split('.')[0]\n"
        "        if root in {'rclpy', 'rosidl_runtime_py', 'sensor_msgs', 'std_msgs', 'yaml',\n"
        "                    'matplotlib', 'mcap', 'rosbags', 'hexapod_workspace_msgs'}:\n"
        "            raise ImportError('blocked: ' + name)\n"
        "sys.meta_path.insert(0, Block())\n"
        f"for module in {CORE!r}:\n"
        "    __import__(module)\n"
        "import hexapod_workspace\n"
        "loaded = sorted({m.split('.')[0] for m in sys.modules})\n"
        "print(' '.join(loaded))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert "rclpy" not in done.stdout.split()
