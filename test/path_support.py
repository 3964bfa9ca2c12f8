"""Shared inputs of the path tests: large random moves around the example's working volume."""

from __future__ import annotations

import numpy as np


def random_large_moves(count: int = 3000, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Positions (count, 3), m, ±0.3 m around (0, 0, −1.15), and T&T angles (count, 3), rad,
    tilts to 30°. With seed 3, some moves between two reachable poses leave the workspace for
    both interpolations (found by the certified check and confirmed by dense sampling)."""
    rng = np.random.default_rng(seed)
    positions = np.array([0.0, 0.0, -1.15]) + rng.uniform(-0.3, 0.3, (count, 3))
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(30.0), count),
            rng.uniform(-0.6, 0.6, count),
        ]
    )
    return positions, angles
