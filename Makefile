# Entry points for humans and CI. Everything runs in .venv (tools/venv.sh), created on demand.
#   make demo   CLI demo (no ROS needed): venv with base requirements + the package
#   make ros    colcon build of hexapod_workspace_msgs and hexapod_workspace (full venv)
#   make test   full venv + colcon build + ruff + the whole pytest suite over real DDS
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

.PHONY: demo ros test lint venv-base venv-full clean

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

test: ros lint
	tools/with_ros_env.sh python -m pytest test

clean:
	rm -rf build install log demo_out
