#!/usr/bin/env bash
# colcon build of both ROS packages into build/ install/ (log/): the interface package
# hexapod_workspace_msgs (msg_defs/, ament_cmake + rosidl) and the ament_python package
# hexapod_workspace (repository root). colcon stops descending at the root package.xml, so both
# paths are named explicitly. Needs the full venv (tools/venv.sh full).
#
# Idempotent: skipped when no source file is newer than the last successful build.
# FORCE=1 rebuilds anyway; extra arguments go to colcon build.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$ROOT"

stamp="$ROOT/install/.hexapod_build_stamp"
sources=(msg_defs hexapod_workspace config launch resource setup.py setup.cfg package.xml
         README.md "$VENV/.stamp-full")
if [[ "${FORCE:-0}" != 1 && $# -eq 0 && -f "$stamp" ]] \
   && [[ -z "$(find "${sources[@]}" -type f -newer "$stamp" -not -name '*.pyc' -print -quit 2>/dev/null)" ]]; then
  log "colcon build up to date"
  exit 0
fi

"$ROOT/tools/patch_ros_cmake.sh"
start=$SECONDS
log "colcon build (hexapod_workspace_msgs, hexapod_workspace)"
# colcon's own output (CMake, setuptools warnings) goes to log/colcon_build.out; shown on failure.
mkdir -p "$ROOT/log"
if ! PATH="$VENV/bin:$PATH" CMAKE_PREFIX_PATH="$VENV" AMENT_PREFIX_PATH="$VENV" \
  "$VENV/bin/colcon" build --base-paths "$ROOT" "$ROOT/msg_defs" "$@" \
  --cmake-args -DPython3_EXECUTABLE="$VENV/bin/python" -DBUILD_TESTING=OFF \
  >"$ROOT/log/colcon_build.out" 2>&1; then
  log "colcon build failed; the last lines of log/colcon_build.out:"
  tail -n 60 "$ROOT/log/colcon_build.out" >&2
  exit 1
fi
log "colcon build done in $((SECONDS - start)) s"
# The install space holds a copy of the package whose numba cache is empty after a build. A
# node compiles its own model's kernels when it configures (a plain colcon build needs nothing
# more); the tests start nodes of every packaged example, so their kernels are compiled here,
# once, with the node's own warm-up. (python -P: the install space's package, not the source
# tree of the working directory that -c would put first.)
start=$SECONDS
log "compiling the install space's kernels for the packaged examples (numba cache)"
"$ROOT/tools/with_ros_env.sh" python -P -c "
from hexapod_workspace._resources import data_path
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.ros.node import warm_up_kernels
names = ('example_gpm', 'example_collision', 'example_pus', 'example_rus')
warm_up_kernels(*(load_manipulator(data_path('config', f'{n}.yaml')) for n in names))
"
log "kernels ready in $((SECONDS - start)) s"
touch "$stamp"
