#!/usr/bin/env bash
# Run a command in the ROS environment of tools/ros_env.sh, e.g.
#   tools/with_ros_env.sh workspace_node --ros-args --params-file config/example_gpm.yaml
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ros_env.sh"
exec "$@"
