"""Plain 4x4 homogeneous transforms written from the definitions, the independent reference of
the tool and work frames (test/test_frames.py, test/ros/test_ros_cell.py): T&T matrices from
their own Rz·Ry·Rz product, not from hexapod_workspace.core.base.rotations or core.cell.frames."""

from __future__ import annotations

import math

import numpy as np


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def tt(phi: float, theta: float, psi: float) -> np.ndarray:
    """R(φ, θ, ψ) = Rz(φ)·Ry(θ)·Rz(−φ)·Rz(ψ), from the convention's definition."""
    return rz(phi) @ ry(theta) @ rz(-phi) @ rz(psi)


def homogeneous(rotation: np.ndarray, translation) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    matrix[:3, 3] = translation
    return matrix
