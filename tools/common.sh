# Shared settings of the tools/ scripts; sourced by them, never run on its own.
# shellcheck shell=bash
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${VENV:-$ROOT/.venv}"
PYTHON="${PYTHON:-python3}"
log() { printf '[tools] %s\n' "$*" >&2; }
# sha256 of the given files (missing files count as empty), one line.
files_hash() { cat "$@" 2>/dev/null | sha256sum | cut -d' ' -f1; }
