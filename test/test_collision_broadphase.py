"""The broad phase of the kernels' collision margin changes nothing: pruned against every pair.

``collision_margin`` skips the pairs whose lower bounds (a sphere that holds the obstacle or the
tool against a capsule that holds the moving body, then two capsules) prove they cannot give the
margin. Over random scenes (boxes, cylinders, spheres, capsules around the legs and the tool,
contacts and deep overlaps included), scenes with more pairs than the bounds kept between the
two passes, and scenes with exact ties (two copies of one obstacle), the margin, the pair named
and the gap are the evaluation of every pair's, bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_collision import random_poses, scene_parameters

from hexapod_workspace import Manipulator
from hexapod_workspace.core.base.params import flatten
from hexapod_workspace.core.evaluation.loading import example_manipulator, manipulator_from_mapping
from hexapod_workspace.core.kernels.collision import collision_margins
from hexapod_workspace.core.kernels.layout import MODEL_SIZE, B, model_vector
from hexapod_workspace.core.kernels.scene_layout import KEPT_BOUNDS
from hexapod_workspace.core.model.legs import leg_endpoints
from hexapod_workspace.errors import ConfigError


@pytest.fixture(scope="module")
def plain() -> Manipulator:
    return example_manipulator()


def _both(model: Manipulator, rotations: np.ndarray, positions: np.ndarray):
    """(pruned, every pair) results of the kernel, shape (N, 3) each: margin, pair, gap."""
    base_ends, platform_ends = leg_endpoints(model, rotations, positions)
    legs = np.ascontiguousarray(np.transpose(platform_ends - base_ends, (0, 2, 1)))
    vector = model_vector(model)
    r = np.ascontiguousarray(rotations.reshape(-1, 9))
    p = np.ascontiguousarray(positions)
    found = np.empty((r.shape[0], 3))
    every = np.empty((r.shape[0], 3))
    collision_margins(vector, MODEL_SIZE, B, r, p, legs, True, found)
    collision_margins(vector, MODEL_SIZE, B, r, p, legs, False, every)
    return found, every


def _scenes(plain: Manipulator, rng: np.random.Generator, count: int, obstacles: int):
    """``count`` models with ``obstacles`` random obstacles each (refused scenes drawn again)."""
    made = 0
    while made < count:
        parameters = scene_parameters(rng)
        group = parameters["collision"]["obstacles"]
        names = [f"o{k}" for k in range(obstacles)]
        templates = [group[name] for name in group["names"]]
        extra = scene_parameters(rng)["collision"]["obstacles"]
        templates += [extra[name] for name in extra["names"]]
        while len(templates) < obstacles:
            more = scene_parameters(rng)["collision"]["obstacles"]
            templates += [more[name] for name in more["names"]]
        obstacle_groups = {name: templates[k] for k, name in enumerate(names)}
        parameters["collision"]["obstacles"] = {"names": names, **obstacle_groups}
        try:
            model = manipulator_from_mapping({**plain.to_parameters(), **flatten(parameters)})
        except ConfigError:  # an obstacle in collision at the home pose: drawn again
            continue
        made += 1
        yield model


def test_pruned_equals_every_pair_on_random_scenes(plain: Manipulator) -> None:
    """200 scenes of three obstacles, 100 poses each: identical margins, pairs and gaps."""
    rng = np.random.default_rng(7)
    colliding = poses = 0
    pairs_named = set()
    for model in _scenes(plain, rng, 200, 3):
        rotations, positions = random_poses(rng, 100)
        found, every = _both(model, rotations, positions)
        np.testing.assert_array_equal(found, every)
        colliding += int(np.sum(found[:, 0] + model.collision.clearance < 0.0))
        poses += found.shape[0]
        pairs_named.update(found[:, 1].astype(int).tolist())
    # The comparison covers contacts and many different closest pairs.
    assert 0.02 < colliding / poses < 0.9
    assert len(pairs_named) > 20


def test_pruned_equals_every_pair_beyond_the_kept_bounds(plain: Manipulator) -> None:
    """Scenes of 9 obstacles (6 + 8 × 9 = 78 pairs > KEPT_BOUNDS): bounds past the kept ones are
    recomputed, with the same result."""
    assert KEPT_BOUNDS < 6 + 8 * 9
    rng = np.random.default_rng(11)
    for model in _scenes(plain, rng, 20, 9):
        rotations, positions = random_poses(rng, 200)
        found, every = _both(model, rotations, positions)
        np.testing.assert_array_equal(found, every)


def test_ties_name_the_lowest_pair(plain: Manipulator) -> None:
    """Two copies of each obstacle: every value is tied with its copy's, and both kernels name the
    pair of the first copy (the lower index), as the evaluation of every pair does."""
    rng = np.random.default_rng(3)
    checked = 0
    for model in _scenes(plain, rng, 30, 3):
        parameters = model.to_parameters()
        flat = flatten(parameters)
        names = list(flat["collision.obstacles.names"])
        doubled = dict(flat)
        for name in names:
            for key, value in flat.items():
                if key.startswith(f"collision.obstacles.{name}."):
                    doubled[key.replace(f".{name}.", f".{name}_copy.")] = value
        doubled["collision.obstacles.names"] = names + [f"{name}_copy" for name in names]
        twin = manipulator_from_mapping(doubled)
        rotations, positions = random_poses(rng, 100)
        found, every = _both(twin, rotations, positions)
        np.testing.assert_array_equal(found, every)
        # Pairs of the copies come after those of the originals: never named.
        assert np.all(found[:, 1] < 6 + 8 * 3)
        checked += 1
    assert checked == 30
