# shellcheck shell=bash
# Environment for using the colcon install space (install/) with the venv's ROS 2 wheels.
# Source it from bash:   source tools/ros_env.sh
# (or run a command in it: tools/with_ros_env.sh CMD ...). It sets no shell options.
#
# Exports PATH (venv), PYTHONPATH, LD_LIBRARY_PATH and AMENT_PREFIX_PATH (install space + venv),
# ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (DDS traffic stays on 127.0.0.0/8) and
# ROS_DOMAIN_ID: kept when already set, else 0, ROS 2's own default,
# so that a node and a client started in two shells (this script or tools/with_ros_env.sh, or
# an apt ROS 2's ros2 CLI) meet. make test and .ci/run set a domain of their own.
_hw_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
_hw_venv="${VENV:-$_hw_root/.venv}"
_hw_pyver="$("$_hw_venv/bin/python" -c 'import sys; print(f"python{sys.version_info[0]}.{sys.version_info[1]}")')"
_hw_install="$_hw_root/install"
export PATH="$_hw_venv/bin:$_hw_install/hexapod_workspace/lib/hexapod_workspace:$PATH"
export PYTHONPATH="$_hw_install/hexapod_workspace/lib/$_hw_pyver/site-packages:$_hw_install/hexapod_workspace_msgs/lib/$_hw_pyver/site-packages${PYTHONPATH:+:$PYTHONPATH}"
export LD_LIBRARY_PATH="$_hw_install/hexapod_workspace_msgs/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export AMENT_PREFIX_PATH="$_hw_install/hexapod_workspace:$_hw_install/hexapod_workspace_msgs:$_hw_venv${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export CMAKE_PREFIX_PATH="$_hw_install/hexapod_workspace_msgs:$_hw_venv${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
export ROS_DOMAIN_ID="${ROS_DOMAIN_ID:-0}"
unset _hw_root _hw_venv _hw_pyver _hw_install
