#!/usr/bin/env bash
# Create or refresh the virtual environment .venv (or $VENV).
#
#   tools/venv.sh base   runtime requirements + the package (editable): enough for the CLI, demo
#   tools/venv.sh full   base + dev tools (pytest, ruff) + ROS 2 Jazzy wheels and build tools
#                        + the atlas extra (Dask, xarray, Zarr)
#
# Idempotent: each level records a hash of its requirement files and packaging metadata in the
# venv and is skipped when nothing changed. Needs only python3 (and the package index).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

level="${1:-full}"
case "$level" in
  base) reqs=("$ROOT/requirements/base.txt") ;;
  full) reqs=("$ROOT/requirements/base.txt" "$ROOT/requirements/dev.txt"
              "$ROOT/requirements/ros.txt" "$ROOT/requirements/atlas.txt") ;;
  *) log "usage: tools/venv.sh [base|full]"; exit 2 ;;
esac

if [[ ! -x "$VENV/bin/python" ]]; then
  log "creating $VENV"
  "$PYTHON" -m venv "$VENV"
fi

stamp="$VENV/.stamp-$level"
want="$(files_hash "${reqs[@]}" "$ROOT/setup.py" "$ROOT/setup.cfg" "$ROOT/pyproject.toml")"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$want" ]]; then
  log "venv ($level) up to date"
else
  start=$SECONDS
  pip_args=()
  for req in "${reqs[@]}"; do pip_args+=(-r "$req"); done
  log "installing requirements ($level)"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "${pip_args[@]}"
  # Editable: the console script hexapod-workspace runs the working tree. The colcon build
  # (tools/ros_build.sh) installs its own copy for ros2 run / the node executable.
  log "installing the package (editable)"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps -e "$ROOT"
  if [[ "$level" == full ]]; then
    "$ROOT/tools/patch_ros_cmake.sh"
  fi
  echo "$want" > "$stamp"
  log "venv ($level) ready in $((SECONDS - start)) s"
fi
