"""workspace_node started with the 6-PUS and 6-RUS example files, over real Fast DDS from
another process: it serves them (the margins by name of each architecture, ``ik`` violated and
NaN margins where a leg has no solution; the singularity margin reported on request with
``check.report_singularity``, on ``~/check_poses`` and on the waypoints of ``~/check_path``),
computes their workspaces, and refuses a file that mixes
architectures, naming the parameter.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from ros_support import require_ros, running_node

require_ros()

from geometry_msgs.msg import Pose  # noqa: E402
from hexapod_workspace_msgs.msg import TiltTorsion, WorkspaceRequest  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPath, CheckPoses  # noqa: E402

from hexapod_workspace import check, projected_workspace  # noqa: E402
from hexapod_workspace.core.base.rotations import matrix_to_quaternion, tt_to_matrix  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.ros.conversions import margins_by_name  # noqa: E402

NODE = "/hexapod_workspace"
CONFIG = Path(__file__).resolve().parents[2] / "config"
N_PHI = 36


def params_text(architecture: str, directory: Path, **changes: object) -> str:
    """The example file of ``architecture`` with the node's recording folder, small resolutions
    and dotted-name ``changes``."""
    tree = yaml.safe_load((CONFIG / f"example_{architecture}.yaml").read_text(encoding="utf-8"))
    parameters = tree["hexapod_workspace"]["ros__parameters"]
    flat = {
        "recording.directory": str(directory / "logs"),
        "resolution.n_phi": N_PHI,
        "resolution.tolerance": 1e-6,
        **changes,
    }
    for name, value in flat.items():
        *groups, leaf = name.split(".")
        target = parameters
        for group in groups:
            target = target.setdefault(group, {})
        target[leaf] = value
    return yaml.safe_dump(tree, sort_keys=False)


def unsolved_legs(result) -> np.ndarray:
    """Poses where some leg has no inverse-kinematics solution (NaN actuator margin)."""
    return np.isnan(result.margins["actuator"])


def ros_poses(position, angles: np.ndarray) -> list[Pose]:
    """geometry_msgs/Pose at one position, orientations from (φ, θ, ψ) rad."""
    poses = []
    for x, y, z, w in matrix_to_quaternion(tt_to_matrix(angles)).tolist():
        pose = Pose()
        pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
        pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = x, y, z, w
        poses.append(pose)
    return poses


def check_request(angles: np.ndarray, position) -> CheckPoses.Request:
    request = CheckPoses.Request()
    request.position.x, request.position.y, request.position.z = (float(v) for v in position)
    request.orientations = [
        TiltTorsion(phi=float(p), theta=float(t), psi=float(s)) for p, t, s in angles
    ]
    return request


@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_node_serves_an_architecture_file(architecture, ros_domain, ros_client, tmp_path):
    text = params_text(architecture, tmp_path, **{"check.report_singularity": True})
    with running_node(tmp_path, params_text=text) as node:
        model = load_manipulator(node.params_path)
        assert model.architecture == architecture
        ros_client.client(CheckPoses, f"{NODE}/check_poses")
        rng = np.random.default_rng(17)
        angles = np.column_stack(
            [
                rng.uniform(-math.pi, math.pi, 200),
                rng.uniform(0.0, math.radians(70.0), 200),
                rng.uniform(-0.6, 0.6, 200),
            ]
        )
        expected = check(model, angles, model.position, singularity=True)  # the node reports it
        assert np.all(np.isfinite(expected.margins["singularity"]) | unsolved_legs(expected))
        assert np.any(np.isnan(expected.margins["actuator"])), "need poses without IK"
        response = ros_client.call(
            CheckPoses, f"{NODE}/check_poses", check_request(angles, model.position)
        )
        assert response.success, response.message
        assert [list(r.violated) for r in response.results] == expected.violated
        for result in response.results:
            assert list(result.constraint_names) == list(expected.margins)
        for name in expected.margins:
            got = np.array([margins_by_name(r)[name] for r in response.results])
            np.testing.assert_array_equal(got, expected.margins[name])
        unsolved = np.isnan(expected.margins["actuator"])
        assert all("ik" in response.results[k].violated for k in np.flatnonzero(unsolved))

        # ~/check_path reports it too, at every waypoint, with the same values
        tilted = angles[:8] * np.array([1.0, 0.2, 0.2])
        path = CheckPath.Request(poses=ros_poses(model.position, tilted))
        response = ros_client.call(CheckPath, f"{NODE}/check_path", path)
        assert response.success, response.message
        reported = check(model, tilted, model.position, singularity=True).margins["singularity"]
        got = [margins_by_name(w)["singularity"] for w in response.waypoints]
        np.testing.assert_allclose(got, reported, rtol=1e-12)
        assert np.all(np.isfinite(reported))

        request = WorkspaceRequest(kind=WorkspaceRequest.PROJECTED_TORSION_ZERO, request_id="a")
        request.position.x, request.position.y, request.position.z = model.position.tolist()
        result = ros_client.compute(f"{NODE}/compute_workspace", request)
        assert result.success, result.message
        core = projected_workspace(model, model.position, n_phi=N_PHI, tolerance=1e-6)
        assert result.summary.tilt_min == pytest.approx(core.tilt_min, abs=1e-9)
        assert node.stop() == 0


def test_node_refuses_a_parameter_of_another_architecture(ros_domain, tmp_path):
    text = params_text("pus", tmp_path, **{"geometry.crank_lengths": [0.1]})
    with running_node(tmp_path, params_text=text) as node:
        node.process.wait(timeout=60)
        assert node.process.returncode != 0
        output = node.output()
    assert "geometry.crank_lengths: a parameter of geometry.architecture rus, given for pus" in (
        output
    )
