#!/usr/bin/env bash
# Exit 1 with one line unless Node.js >= 18 and npm are on PATH: make test checks MCAP logs with
# Foxglove's own TypeScript libraries (test/foxglove, installed with npm ci).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
MIN_NODE=18

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  log "make test needs Node.js >= $MIN_NODE and npm (Foxglove's libraries check the MCAP logs): install them, e.g. apt-get install nodejs npm"
  exit 1
fi
version="$(node --version 2>/dev/null || true)"  # v20.20.2
major="${version#v}"; major="${major%%.*}"
if ! [[ "$major" =~ ^[0-9]+$ ]] || (( major < MIN_NODE )); then
  log "make test needs Node.js >= $MIN_NODE (Foxglove's libraries check the MCAP logs), found node ${version:-of unknown version}: install a newer Node.js"
  exit 1
fi
