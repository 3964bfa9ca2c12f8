# Entry points for humans and CI. Everything runs in .venv (tools/venv.sh), created on demand.
#   make demo   CLI demo (no ROS needed): venv with base requirements + the package
#   make ros    colcon build of hexapod_workspace_msgs and hexapod_workspace (full venv)
#   make lint   ruff (lint + format check) and mypy (config in pyproject.toml, strict on the core)
#   make docs   the documentation site (Sphinx) -> docs/_build/html, every warning an error
#   make test   full venv + colcon build + ruff + the docs + Foxglove's npm libraries (npm ci, pinned by
#               test/foxglove/package-lock.json; needs Node.js >= 18 and npm, checked first)
#               + the whole pytest suite over real DDS
#   make clean  remove build/ install/ log/ demo_out/ (keeps .venv)
SHELL := /usr/bin/env bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := test

VENV ?= .venv
export VENV := $(abspath $(VENV))
# Every process that may start rclpy stays on this machine and in its own DDS domain.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
ROS_DOMAIN_ID ?= $(shell echo $$(( 1 + $$$$ % 100 )))
export ROS_DOMAIN_ID
# The ROS tests fail (instead of skipping) when the install space cannot be used.
export HEXAPOD_REQUIRE_ROS := 1
# The log checks with Foxglove's own libraries fail (instead of skipping) without them.
export HEXAPOD_REQUIRE_FOXGLOVE := 1
FOXGLOVE := test/foxglove

.PHONY: demo ros test lint docs venv-base venv-full node-check foxglove clean

venv-base:
	tools/venv.sh base

venv-full:
	tools/venv.sh full

demo: venv-base
	$(VENV)/bin/hexapod-workspace demo --out demo_out

ros: venv-full
	tools/ros_build.sh

lint: venv-full
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/mypy

# npm ci only when the lock file changed; its output goes to log/npm_ci.out (shown on failure).
# Node.js >= 18 and npm, checked first by make test: one line when missing or too old.
node-check:
	@tools/check_node.sh

$(FOXGLOVE)/node_modules/.package-lock.json: $(FOXGLOVE)/package.json $(FOXGLOVE)/package-lock.json | node-check
	@mkdir -p log
	@echo "[tools] npm ci in $(FOXGLOVE) (Foxglove's libraries for the log checks)" >&2
	@cd $(FOXGLOVE) && npm ci --no-audit --no-fund >$(CURDIR)/log/npm_ci.out 2>&1 \
	  || { tail -n 30 $(CURDIR)/log/npm_ci.out >&2; exit 1; }
	@touch $@

foxglove: $(FOXGLOVE)/node_modules/.package-lock.json

# -W --keep-going: every warning fails the build (all of them listed); -n: nitpicky, every
# cross reference to the package's own objects must resolve. In the ROS environment, because
# the API and parameter references import the node's modules.
docs: ros
	tools/with_ros_env.sh $(VENV)/bin/sphinx-build -W --keep-going -n -q -b html docs docs/_build/html
	@echo "docs: docs/_build/html/index.html" >&2

test: node-check ros lint foxglove docs
	tools/with_ros_env.sh python -m pytest test

clean:
	rm -rf build install log demo_out docs/_build docs/_generated $(FOXGLOVE)/node_modules
