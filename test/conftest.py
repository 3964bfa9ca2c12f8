"""Shared fixtures: the packaged example manipulator and seeded random poses."""

from __future__ import annotations

import numpy as np
import pytest

from hexapod_workspace import Manipulator
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core import kernels
from hexapod_workspace.core.evaluation.loading import load_manipulator, manipulator_from_mapping


@pytest.fixture(scope="session", autouse=True)
def compiled_kernels() -> float:
    """Compile (or load) the kernels of the packaged examples' variants once before any test
    (with and without the reported singularity margin): the CLI subprocesses of the tests share
    this source tree's cache, so none of them prints the first-run notice. A test of another
    variant compiles it where it first uses it."""
    config = example_config_path().parent
    models = [
        kernels.model_vector(load_manipulator(config / f"{name}.yaml"), report_singularity=report)
        for name in ("example_gpm", "example_collision", "example_pus", "example_rus")
        for report in (False, True)
    ]
    return kernels.warm_up(*models)


@pytest.fixture(scope="session")
def example() -> Manipulator:
    """The packaged example GPM (axisymmetric, platform below the base)."""
    return load_manipulator(example_config_path())


@pytest.fixture(scope="session")
def example_parameters() -> dict:
    """The example's parameters as dotted names (a fresh copy per use is the caller's job)."""
    return load_manipulator(example_config_path()).to_parameters()


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261121)


def polar_joints(radius: float, azimuths_deg: list[float], height: float) -> list[float]:
    """18 floats: joints on a circle of ``radius`` at ``azimuths_deg``, at z = ``height``."""
    angles = np.radians(azimuths_deg)
    points = np.column_stack([radius * np.cos(angles), radius * np.sin(angles), np.full(6, height)])
    return points.ravel().tolist()


@pytest.fixture(scope="session")
def symmetric(example) -> Manipulator:
    """The example design with exact (unrounded) joint coordinates: symmetric under a 120 deg
    rotation about z to machine precision (the YAML carries 6 decimals)."""
    parameters = example.to_parameters()
    parameters["geometry.base_joints"] = polar_joints(0.55, [-12, 12, 108, 132, 228, 252], 0.0)
    parameters["geometry.platform_joints"] = polar_joints(0.30, [-48, 48, 72, 168, 192, 288], 0.10)
    return manipulator_from_mapping(parameters)
