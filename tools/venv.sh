#!/usr/bin/env bash
# Create or refresh the virtual environment .venv (or $VENV).
#
#   tools/venv.sh base   runtime requirements + the package (editable): enough for the CLI, demo
#   tools/venv.sh full   base + dev tools (pytest, ruff) + ROS 2 Jazzy wheels and build tools
#                        + the atlas extra (Dask, xarray, Zarr) + the docs tools (Sphinx)
#
# Idempotent: each level records a hash of its requirement files and packaging metadata in the
# venv and is skipped when nothing changed. Needs only Python >= 3.11 ($PYTHON, default python3)
# and the package index; an older interpreter stops it with one line naming the cause, before
# pip runs.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

level="${1:-full}"
case "$level" in
  base) reqs=("$ROOT/requirements/base.txt") ;;
  full) reqs=("$ROOT/requirements/base.txt" "$ROOT/requirements/dev.txt"
              "$ROOT/requirements/ros.txt" "$ROOT/requirements/atlas.txt"
              "$ROOT/requirements/docs.txt") ;;
  *) log "usage: tools/venv.sh [base|full]"; exit 2 ;;
esac

if [[ ! -x "$VENV/bin/python" ]]; then
  require_python "$PYTHON"
  log "creating $VENV"
  "$PYTHON" -m venv "$VENV"
fi

require_python "$VENV/bin/python"  # an older venv made by another interpreter

stamp="$VENV/.stamp-$level"
want="$(files_hash "${reqs[@]}" "$ROOT/setup.py" "$ROOT/setup.cfg" "$ROOT/pyproject.toml" \
        "${BASH_SOURCE[0]}")"
# pip's own output (hundreds of lines, and warnings of the machine's pip configuration) goes to
# a log file; it is shown only when pip fails.
pip_log="$VENV/pip.log"
quiet_pip() {
  if ! "$VENV/bin/python" -m pip "$@" >>"$pip_log" 2>&1; then
    log "pip $1 failed; the last lines of $pip_log:"
    tail -n 40 "$pip_log" >&2
    exit 1
  fi
}
if [[ -f "$stamp" && "$(cat "$stamp")" == "$want" ]]; then
  log "venv ($level) up to date"
else
  start=$SECONDS
  pip_args=()
  for req in "${reqs[@]}"; do pip_args+=(-r "$req"); done
  : >"$pip_log"
  log "installing requirements ($level; pip's output in $pip_log)"
  quiet_pip install --disable-pip-version-check "${pip_args[@]}"
  # Editable: the console script hexapod-workspace runs the working tree. The colcon build
  # (tools/ros_build.sh) installs its own copy for ros2 run / the node executable.
  # editable_mode=compat puts the repository root on sys.path (a .pth line), so that Python
  # started in the folder above a clone named hexapod_workspace still imports the package,
  # not the clone as an empty namespace package (setuptools' default finder comes too late).
  log "installing the package (editable)"
  quiet_pip install --disable-pip-version-check --no-deps \
    --config-settings editable_mode=compat -e "$ROOT"
  if [[ "$level" == full ]]; then
    "$ROOT/tools/patch_ros_cmake.sh"
  fi
  echo "$want" > "$stamp"
  log "venv ($level) ready in $((SECONDS - start)) s"
fi
