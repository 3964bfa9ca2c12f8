"""Collision bodies of a hexapod cell (core): shapes, exact signed distances, rate bounds.

* :mod:`.distance` — bodies as inflated convex cores (sphere, capsule, box, cylinder) and their
  signed distance: closed forms, and GJK with a stated, certified tolerance.
* :mod:`.scene` — the moving bodies (legs, platform, tool) and the ``collision`` margin of a
  batch of poses (smallest distance minus the clearance, and the pair that gives it), with the
  rate bound of that margin along a move.
* :mod:`.params` — the ``collision.*`` parameters (clearance, platform, tool, obstacles by
  name), validated as a whole.

The wiring of the ``collision`` margin into the constraint table (every check, workspace, move
certificate) follows the constraint-table work; this package is what it will call.
"""

from .distance import GJK_TOLERANCE, pair_distance, pair_distances, record
from .params import CollisionScene, Obstacle, PlatformBody, ToolBody, collision_scene
from .scene import MOVING_BODIES, RateBound, SceneDistances, pair_table, rate_bound, scene_distances

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
    "scene_distances",
]
