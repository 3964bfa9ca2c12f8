#!/usr/bin/env bash
# Rewrite the wheel builder's hard-coded paths in the CMake files exported by the ROS 2 wheels
# (<venv>/share/*/cmake/*.cmake): its Python include dir and its numpy include dir become this
# interpreter's. Without this, configuring an interface package fails with "includes
# non-existent path". Idempotent (a no-op once patched).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

py="$VENV/bin/python"
py_include="$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
np_include="$("$py" -c 'import numpy; print(numpy.get_include())')"
# e.g. /opt/python/cp311-cp311/include/python3.11 and .../site-packages/numpy/_core/include
builder='/opt/python/cp3[0-9]+-cp3[0-9]+'

mapfile -t files < <(grep -l -s "/opt/python/cp3" "$VENV"/share/*/cmake/*.cmake || true)
if [[ ${#files[@]} -eq 0 ]]; then
  log "ROS cmake files: nothing to patch"
  exit 0
fi
sed -E -i \
  -e "s#${builder}/lib/python3\.[0-9]+/site-packages/numpy/(_core|core)/include#${np_include}#g" \
  -e "s#${builder}/include/python3\.[0-9]+#${py_include}#g" "${files[@]}"
if left="$(grep -l -s "/opt/python/cp3" "${files[@]}")"; then
  log "unexpected builder paths remain in: $left"
  exit 1
fi
log "ROS cmake files: patched ${#files[@]} file(s)"
