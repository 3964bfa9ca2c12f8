# Shared settings of the tools/ scripts; sourced by them, never run on its own.
# shellcheck shell=bash
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${VENV:-$ROOT/.venv}"
PYTHON="${PYTHON:-python3}"
# The oldest Python the package and its pinned requirements install on (apsw, pandas, xarray and
# zarr of requirements/ need 3.11); setup.py's python_requires says the same (a test checks).
MIN_PYTHON=3.11
log() { printf '[tools] %s\n' "$*" >&2; }
# sha256 of the given files (missing files count as empty), one line.
files_hash() { cat "$@" 2>/dev/null | sha256sum | cut -d' ' -f1; }
# Exit 1 with one line unless interpreter $1 is at least MIN_PYTHON.
require_python() {
  local version
  if ! version="$("$1" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null)"; then
    log "no Python interpreter '$1' (set PYTHON=python${MIN_PYTHON} or newer)"; exit 1
  fi
  if [[ "$(printf '%s\n%s\n' "$MIN_PYTHON" "$version" | sort -V | head -n1)" != "$MIN_PYTHON" ]]; then
    log "$1 is Python $version; hexapod_workspace needs Python >= $MIN_PYTHON (its pinned apsw, pandas, xarray and zarr do): set PYTHON=python${MIN_PYTHON} or newer"
    exit 1
  fi
}
