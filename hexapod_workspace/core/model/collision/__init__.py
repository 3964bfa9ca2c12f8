"""Collision bodies of a hexapod cell (core): shapes, exact signed distances, rate bounds.

* :mod:`.distance` — bodies as inflated convex cores (sphere, capsule, box, cylinder) and their
  signed distance: closed forms, and GJK with a stated, certified tolerance.
* :mod:`.scene` — the moving bodies (legs, platform, tool) and the ``collision`` margin of a
  batch of poses (smallest distance minus the clearance, and the pair that gives it), with the
  rate bound of that margin along a move.
* :mod:`.params` — the ``collision.*`` parameters (clearance, platform, tool, obstacles by
  name), validated as a whole.

The ``collision`` row of the constraint table is evaluated inside the compiled kernels by
:mod:`hexapod_workspace.core.kernels.collision` (same bodies, pairs and distances);
:func:`scene_distances` is the standalone evaluation the tests compare it with.
"""

from .distance import GJK_TOLERANCE, pair_distance, pair_distances, record
from .params import (
    CollisionScene,
    Obstacle,
    PlatformBody,
    ToolBody,
    collision_scene,
)
from .scene import (
    MOVING_BODIES,
    RateBound,
    SceneDistances,
    pair_table,
    rate_bound,
    require_free_home,
    scene_distances,
)

__all__ = [
    "GJK_TOLERANCE",
    "MOVING_BODIES",
    "CollisionScene",
    "Obstacle",
    "PlatformBody",
    "RateBound",
    "SceneDistances",
    "ToolBody",
    "collision_scene",
    "pair_distance",
    "pair_distances",
    "pair_table",
    "rate_bound",
    "record",
    "require_free_home",
    "scene_distances",
]
