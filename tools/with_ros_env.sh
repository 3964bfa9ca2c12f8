#!/usr/bin/env bash
# Run a command in the ROS environment of tools/ros_env.sh, e.g.
#   tools/with_ros_env.sh workspace_node --ros-args --params-file config/example_gpm.yaml
# ROS_DOMAIN_ID is kept when set, else 0 (as in tools/ros_env.sh): commands started this way in
# two shells meet.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/ros_env.sh"
exec "$@"
