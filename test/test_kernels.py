"""The compiled kernels against the numpy batch reference, the searches against themselves, the
compilation cache in a read-only install.

Reference: :func:`reference.batched_margins`, the numpy batch evaluation the package used before
the kernels (commit 0b9ef59), and the literal per-pose definitions for spot checks. Margins must
agree to 1e-12 and verdicts exactly on 10⁶ random poses per design; a limiting leg or pair may
differ only where two candidates tie to rounding (checked against the reference's own values).
"""

from __future__ import annotations

import math
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from reference import BATCHED_NAMES, batched_margins, pose_margins_literal

from hexapod_workspace import InputError, Manipulator, check
from hexapod_workspace.core import kernels
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.constraints.table import CONSTRAINT_NAMES as TABLE_NAMES
from hexapod_workspace.core.evaluation import check as constraints
from hexapod_workspace.core.evaluation.check import (
    check_pose,
    inverse_kinematics,
    pose_margins,
    segment_distance,
)
from hexapod_workspace.core.evaluation.loading import (
    load_manipulator,
    manipulator_from_mapping,
)
from hexapod_workspace.core.kernels import blocks as block_kernels
from hexapod_workspace.core.kernels import pose as pose_kernels
from hexapod_workspace.core.kernels import trig as trig_kernels
from hexapod_workspace.core.workspaces.search import RaySearch

POSES = 1_000_000
PACKAGE = Path(__file__).resolve().parents[1] / "hexapod_workspace"
CONFIG = Path(__file__).resolve().parents[1] / "config" / "example_gpm.yaml"

#: The 6-UPS model's constraints (the rows of the table that apply to it), as before the leg
#: architectures: ``check`` gives exactly these names for a 6-UPS manipulator.
CONSTRAINT_NAMES = ("leg_length", "base_joint", "platform_joint", "leg_interference", "singularity")


def _design(example: Manipulator, name: str) -> Manipulator:
    """The four test designs: axisymmetric (the example), per-leg limits,
    non-axisymmetric, crossed legs."""
    parameters = example.to_parameters()
    if name == "per_leg_limits":
        parameters["limits.leg_length_min"] = [0.98, 1.0, 1.01, 0.99, 1.02, 0.97]
        parameters["limits.leg_length_max"] = [1.55, 1.6, 1.58, 1.62, 1.57, 1.61]
        parameters["limits.base_joint_max_angle"] = np.radians([40, 45, 50, 42, 47, 44]).tolist()
        parameters["limits.platform_joint_max_angle"] = np.radians(
            [35, 40, 38, 45, 36, 41]
        ).tolist()
    elif name == "non_axisymmetric":
        rng = np.random.default_rng(7)
        base = np.reshape(parameters["geometry.base_joints"], (6, 3))
        platform = np.reshape(parameters["geometry.platform_joints"], (6, 3))
        base[:, :2] += rng.normal(scale=0.04, size=(6, 2))
        platform[:, :2] += rng.normal(scale=0.03, size=(6, 2))
        parameters["geometry.base_joints"] = base.ravel().tolist()
        parameters["geometry.platform_joints"] = platform.ravel().tolist()
    elif name == "crossed_legs":
        # Neighbouring legs swap their platform ends: each pair crosses like an X.
        platform = np.reshape(parameters["geometry.platform_joints"], (6, 3))
        parameters["geometry.platform_joints"] = platform[[1, 0, 3, 2, 5, 4]].ravel().tolist()
    elif name != "axisymmetric":
        raise ValueError(name)
    return manipulator_from_mapping(parameters, warn=False)


def _random_poses(rng: np.random.Generator, count: int) -> np.ndarray:
    return np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, math.radians(60.0), count),
            rng.uniform(-math.radians(90.0), math.radians(90.0), count),
        ]
    )


@pytest.mark.parametrize(
    "name", ["axisymmetric", "per_leg_limits", "non_axisymmetric", "crossed_legs"]
)
def test_check_equals_the_numpy_reference_on_a_million_poses(example, name):
    model = _design(example, name)
    rng = np.random.default_rng(20261123)
    angles = _random_poses(rng, POSES)
    position = model.position + np.array([0.01, -0.02, 0.03])
    result = check(model, angles, position)
    reference, legs, pairs = batched_margins(model, angles, position)
    margins = np.stack([result.margins[name] for name in BATCHED_NAMES])
    assert np.all(np.isinf(result.margins["singularity"]))  # not evaluated: limit 0
    assert np.all(np.isfinite(margins))
    difference = np.abs(margins - reference)
    np.testing.assert_array_less(difference[:3], 1e-12)
    # Interference to 1e-12 too, except for legs all but touching: there both compute the
    # distance as the root of a squared distance expanded from terms of order 1 m², whose
    # rounding (~1e-16 m²) becomes ~1e-16 / (2 d) in the distance d (crossed legs: 3 in 10⁴).
    loose = difference[3] > 1e-12
    distance = reference[3, loose] + model.leg_diameter
    assert np.count_nonzero(loose) <= 1e-3 * POSES
    assert np.all(distance < 1e-3)
    assert np.all(difference[3, loose] <= 1e-15 / distance)
    np.testing.assert_array_equal(result.reachable, np.all(reference >= 0.0, axis=0))
    # Both outcomes occur, or the comparison of verdicts would be empty.
    assert 0.05 < result.reachable.mean() < 0.95
    # Limiting legs: equal, or a tie to rounding in the reference's own per-leg values.
    kinematics = inverse_kinematics(model, tt_to_matrix(angles[:20_000]), position)
    per_leg = np.minimum(
        kinematics.lengths - model.leg_length_min, model.leg_length_max - kinematics.lengths
    )
    ours = result.limiting_legs["leg_length"][:20_000] - 1
    rows = np.arange(20_000)
    assert np.all(per_leg[rows, ours] - reference[0, :20_000] <= 1e-12)
    for row in range(3):
        assert np.mean(result.limiting_legs[CONSTRAINT_NAMES[row]] - 1 == legs[row]) > 0.999
    # Closest pair: at the reference's minimum distance (to 1e-12) wherever it differs.
    ours = result.limiting_pair - 1
    differ = np.flatnonzero(np.any(ours != pairs, axis=1))
    assert differ.size < 0.05 * POSES
    sample = differ[:2000]
    ends = kinematics_ends(model, angles[sample], position)
    distance = segment_distance(
        ends[0][np.arange(sample.size), ours[sample, 0]],
        ends[1][np.arange(sample.size), ours[sample, 0]],
        ends[0][np.arange(sample.size), ours[sample, 1]],
        ends[1][np.arange(sample.size), ours[sample, 1]],
    )
    np.testing.assert_allclose(
        distance - model.leg_diameter, reference[3, sample], rtol=0.0, atol=1e-12
    )


def kinematics_ends(model: Manipulator, angles: np.ndarray, position: np.ndarray):
    """Leg end points A_i (n, 6, 3) and B_i (n, 6, 3) of poses (n, 3)."""
    platform = inverse_kinematics(model, tt_to_matrix(angles), position).platform_points
    return np.broadcast_to(model.base_joints, platform.shape), platform


def test_limiting_constraint_and_leg_follow_relative_margins(example, rng):
    angles = _random_poses(rng, 50_000)
    result = check(example, angles)
    absent = np.full(len(result), np.inf)  # rows of the table that do not apply to 6-UPS
    margins = np.stack([result.margins.get(name, absent) for name in TABLE_NAMES])
    expected = constraints.relative_margins(example, margins).argmin(axis=0)
    np.testing.assert_array_equal(result.limiting_constraint, expected)
    zeros = np.zeros(len(result), dtype=np.int64)
    legs = np.stack([result.limiting_legs.get(name, zeros) for name in TABLE_NAMES])
    np.testing.assert_array_equal(result.limiting_leg, legs[expected, np.arange(len(result))])


def test_literal_definitions_agree_on_spot_checks(example, rng):
    """Independent evidence: the per-pose literal definitions (another segment distance)."""
    for name in ("per_leg_limits", "crossed_legs"):
        model = _design(example, name)
        angles = _random_poses(rng, 200)
        result = check(model, angles)
        for index in range(200):
            literal = pose_margins_literal(model, angles[index], model.position)
            for constraint in CONSTRAINT_NAMES:
                assert result.margins[constraint][index] == pytest.approx(
                    literal[constraint], abs=1e-9
                ), (name, constraint)


def test_huge_angles_and_degenerate_legs_take_the_exact_path(example):
    # |angle| beyond the fast sin/cos range: the same rotation as the wrapped angle.
    wrapped = np.array([[0.3, 0.4, -0.2]])
    turns = 2.0 * math.pi * np.array([[1e6, -3e5, 2e6]])
    far = check(example, wrapped + turns)
    near = check(example, wrapped)
    for name in CONSTRAINT_NAMES:
        assert far.margins[name][0] == pytest.approx(near.margins[name][0], abs=1e-8)
    # Parallel legs (a vertical design): the segment distance's parallel branch.
    parameters = example.to_parameters()
    base = np.reshape(parameters["geometry.base_joints"], (6, 3))
    platform = base.copy()
    platform[:, 2] = 0.0
    base[:, 2] += 1.3
    parameters["geometry.base_joints"] = base.ravel().tolist()
    parameters["geometry.platform_joints"] = platform.ravel().tolist()
    parameters["geometry.home_position"] = [0.0, 0.0, 0.0]
    parameters["pose.position"] = [0.0, 0.0, 0.0]
    parameters["limits.leg_diameter"] = 0.02
    vertical = manipulator_from_mapping(parameters, warn=False)
    angles = np.array([[0.0, 0.0, 0.0], [0.2, 0.05, 0.1]])
    result = check(vertical, angles)
    reference, _, _ = batched_margins(vertical, angles, vertical.position)
    margins = np.stack([result.margins[name] for name in BATCHED_NAMES])
    np.testing.assert_allclose(margins, reference, rtol=0.0, atol=1e-12)


def test_check_pose_equals_check(example, rng):
    angles = _random_poses(rng, 2000)
    batch = check(example, angles)
    for index in range(angles.shape[0]):
        one = check_pose(example, *angles[index])
        assert one.reachable == bool(batch.reachable[index])
        for k, name in enumerate(CONSTRAINT_NAMES):
            assert one.margins[k] == pytest.approx(batch.margins[name][index], abs=1e-12)
        assert one.limiting_constraint == batch.limiting_constraint[index]
    position = example.position + 0.01
    one = check_pose(example, 0.1, 0.2, 0.3, position)
    assert one.margins[0] == pytest.approx(
        check(example, [0.1, 0.2, 0.3], position).margins["leg_length"][0], abs=1e-12
    )


def test_check_pose_gives_plain_python_fields_equal_to_check(example, rng):
    """check_pose's fields come straight from the kernel's tuple: plain bool, float and int
    (what messages and JSON take), legs and pair 1-based as in check()."""
    angles = _random_poses(rng, 300)
    batch = check(example, angles)
    for index in range(angles.shape[0]):
        one = check_pose(example, *angles[index])
        assert type(one.reachable) is bool
        assert len(one.margins) == len(one.limiting_legs) == len(TABLE_NAMES)
        assert all(type(value) is float for value in one.margins)
        assert all(type(value) is int for value in one.limiting_legs)
        assert all(type(value) is int for value in one.limiting_pair)
        assert type(one.limiting_constraint) is int and type(one.limiting_leg) is int
        for name, legs in batch.limiting_legs.items():
            assert one.limiting_legs[TABLE_NAMES.index(name)] == legs[index], name
        assert one.limiting_pair == tuple(batch.limiting_pair[index].tolist())
        assert one.limiting_leg == batch.limiting_leg[index]


def test_check_pose_rejects_bad_input_like_check(example):
    with pytest.raises(InputError, match="angles: expected finite values, pose 0"):
        check_pose(example, 0.0, math.nan, 0.0)
    with pytest.raises(InputError, match="position: expected 3 finite values"):
        check_pose(example, 0.0, 0.1, 0.0, [0.0, 0.0])
    with pytest.raises(InputError, match="position: expected 3 finite values"):
        check_pose(example, 0.0, 0.1, 0.0, [0.0, math.inf, 0.0])


def test_check_input_errors_keep_their_order(example):
    # A non-finite angle is reported before a bad position, as before the kernels.
    with pytest.raises(InputError, match="angles: expected finite values, pose 1"):
        check(example, [[0.0, 0.1, 0.0], [math.inf, 0.0, 0.0]], [0.0, 0.0])
    with pytest.raises(InputError, match="angles: expected finite values, pose 1"):
        check(example, [[0.0, 0.1, 0.0], [0.0, math.nan, 0.0]], [0.0, math.nan, 0.0])
    with pytest.raises(InputError, match="position: expected 3 finite values"):
        check(example, [[0.0, 0.1, 0.0]], [0.0, math.nan, 0.0])


def test_threads_split_large_batches_without_changing_results(example, rng, monkeypatch):
    angles = _random_poses(rng, 3 * constraints.PARALLEL_POSES)
    monkeypatch.setattr(constraints, "_cores", lambda: 1)
    serial = check(example, angles)
    monkeypatch.setattr(constraints, "_cores", lambda: 3)
    threaded = check(example, angles)
    for name in CONSTRAINT_NAMES:
        np.testing.assert_array_equal(threaded.margins[name], serial.margins[name])
        np.testing.assert_array_equal(threaded.limiting_legs[name], serial.limiting_legs[name])
    np.testing.assert_array_equal(threaded.limiting_pair, serial.limiting_pair)
    np.testing.assert_array_equal(threaded.reachable, serial.reachable)
    bad = angles.copy()
    bad[-1, 2] = math.nan
    with pytest.raises(InputError, match=f"pose {bad.shape[0] - 1} "):
        check(example, bad)


def test_pose_margins_from_rotations_equal_check(example, rng):
    angles = _random_poses(rng, 5000)
    positions = example.position + rng.normal(scale=0.02, size=(5000, 3))
    batched = pose_margins(example, tt_to_matrix(angles), positions)
    for index in range(0, 5000, 250):
        single = check(example, angles[index], positions[index])
        for k, name in enumerate(CONSTRAINT_NAMES):
            assert batched.margins[k, index] == pytest.approx(single.margins[name][0], abs=1e-12)
    no_interference = pose_margins(example, tt_to_matrix(angles), positions, interference=False)
    assert np.all(np.isinf(no_interference.margins[3]))
    np.testing.assert_array_equal(no_interference.margins[:3], batched.margins[:3])


def test_lockstep_search_equals_rays_searched_alone(example):
    """The search evaluates all rays together; each ray must see the probes it would alone."""
    search = RaySearch(example, example.position)
    phi = np.linspace(-math.pi, math.pi, 37)
    origins = np.column_stack([phi, np.zeros(phi.size), 0.2 * np.sin(3.0 * phi)])
    together = search.rays("tt", origins, [0.0, 1.0, 0.0], math.pi, 1e-7)
    for index in range(phi.size):
        alone = search.rays("tt", origins[index], [0.0, 1.0, 0.0], math.pi, 1e-7)
        assert alone.feasible[0] == together.feasible[index]
        assert alone.violated[0] == together.violated[index]
        assert alone.limiting[0] == together.limiting[index]
    assert np.all(together.violated - together.feasible <= 1e-7)
    # Every reported boundary point is reachable, the first violation within the tolerance.
    boundary = np.column_stack([phi, together.feasible, origins[:, 2]])
    beyond = np.column_stack([phi, together.violated, origins[:, 2]])
    assert np.all(check(example, boundary).reachable)
    assert not np.any(check(example, beyond).reachable)


@pytest.mark.parametrize("name", ["example_gpm", "singularity", "example_pus", "example_rus"])
def test_block_decisions_equal_the_per_probe_functions(name):
    """The search reads a block's estimates, verdicts and (fixed base) certified steps from
    planes computed row by row; they must be the per-probe functions' values, bit for bit, on
    margins of every kind (negative, zero, NaN, +inf, tiny and huge)."""
    from hexapod_workspace.core.kernels import searches as search_kernels

    config = CONFIG.parent / f"{name if name.startswith('example') else 'example_gpm'}.yaml"
    machine = load_manipulator(config)
    if name == "singularity":
        parameters = machine.to_parameters()
        parameters["limits.singularity_min"] = 0.02
        machine = manipulator_from_mapping(parameters, warn=False)
    model = kernels.model_vector(machine)
    used = int(model[kernels.ROWS_USED])
    fixed = machine.architecture == "ups"
    block = block_kernels.BLOCK
    rng = np.random.default_rng(11)
    work = np.full(block_kernels._BLOCK_ROWS * block, np.inf)
    special = np.array([0.0, -0.0, np.nan, np.inf, 1e-300, -1e-300, 1e300, 5e-324])
    for c in range(used):
        # Mostly feasible (the steps matter there), some violated, some special values.
        row = np.abs(rng.normal(scale=0.05, size=block)) * rng.choice([1.0, 1e-6, 30.0], block)
        row[rng.random(block) < 0.05] *= -1.0
        picks = rng.random(block) < 0.12
        row[picks] = rng.choice(special, size=int(picks.sum()))
        work[c * block : (c + 1) * block] = row
    for m in range(4 * used):  # one NaN or +inf in each row in turn, the others feasible
        for c in range(used):
            work[c * block + m] = abs(work[c * block + m]) if m % used != c else special[2 + m % 2]
    estimates, verdicts, steps = np.empty(block), np.empty(block), np.full(block, -1.0)
    search_kernels._block_decisions(
        model, work, block, used, fixed, estimates, verdicts, steps, np.empty(2 * block)
    )
    out = np.full(pose_kernels.OUT_SIZE, np.inf)
    for m in range(block):
        out[:used] = work[m : used * block : block]
        expected = search_kernels._estimate(model, out)
        assert estimates[m] == expected or (math.isnan(estimates[m]) and math.isnan(expected))
        assert verdicts[m] == float(pose_kernels._feasible(out, used))
        if fixed:
            step = search_kernels.certified_step(model, out, None)
            assert steps[m] == step and math.copysign(1.0, steps[m]) == math.copysign(1.0, step)
    assert np.isnan(estimates).any() and (verdicts == 1.0).any() and (verdicts == 0.0).any()
    if fixed:
        assert (steps > 0.0).any() and (steps == 0.0).any()


def test_sincos_within_an_ulp_of_libm():
    x = np.concatenate(
        [np.linspace(-kernels.FAST_TRIG_LIMIT, kernels.FAST_TRIG_LIMIT, 200_001), [0.0, -0.0]]
    )
    rotations = np.empty((x.size, 9))
    for index in range(0, x.size, 997):
        trig_kernels._tt_matrix(x[index], 0.0, x[index], rotations[index])
        # R(φ, 0, φ) = Rz(φ): [cos, -sin, 0; sin, cos, 0; 0, 0, 1].
        assert rotations[index, 0] == pytest.approx(math.cos(x[index]), abs=2.3e-16)
        assert rotations[index, 3] == pytest.approx(math.sin(x[index]), abs=2.3e-16)


def test_warm_up_compiles_everything_and_says_how_long(example):
    # How long it takes is measured by benchmarks/speed.py (cold start), not asserted here.
    seconds = kernels.warm_up()
    assert isinstance(seconds, float) and math.isfinite(seconds) and seconds > 0.0
    assert kernels.cache_is_warm()


def test_compile_notice_only_when_compiling():
    said = []
    kernels.warm_up()
    with kernels.compile_notice(said.append):
        kernels.warm_up()  # already compiled in this process: nothing to say
    assert said == []


def _read_only_runner(probe_dir: Path) -> list[str]:
    """Command prefix under which a chmod'ed directory is really read-only.

    Root ignores permission bits through CAP_DAC_OVERRIDE. ``setpriv`` (util-linux) drops it
    (and CAP_DAC_READ_SEARCH, CAP_FOWNER) from the child's bounding set, so root stays root
    but obeys the bits, which works in containers without user namespaces; ``unshare -U``
    (an unprivileged user namespace) is the second choice. When neither makes ``probe_dir``
    read-only, the test fails and says why: it never skips silently.
    """
    if os.geteuid() != 0:
        return []
    candidates = []
    if setpriv := shutil.which("setpriv"):
        candidates.append([setpriv, "--bounding-set=-dac_override,-dac_read_search,-fowner", "--"])
    if unshare := shutil.which("unshare"):
        candidates.append([unshare, "-U", "--map-user=1000", "--map-group=1000"])
    probe_dir.mkdir()
    probe_dir.chmod(0o555)
    try:
        for runner in candidates:
            probe = subprocess.run(
                [*runner, "sh", "-c", f"! touch {str(probe_dir / 'x')!r} 2>/dev/null"],
                check=False,
            )
            if probe.returncode == 0:
                return runner
    finally:
        probe_dir.chmod(0o755)
    pytest.fail(
        "running as root, and neither setpriv (util-linux: drops CAP_DAC_OVERRIDE) nor "
        "unshare -U (user namespaces) makes a directory read-only here: install util-linux"
    )


def test_cache_works_in_a_read_only_install(tmp_path):
    """A read-only copy of the package (as colcon's install space or system site-packages):
    the first run compiles into the user cache and says so in one line; the second loads."""
    runner = _read_only_runner(tmp_path / "probe")
    site = tmp_path / "site"
    shutil.copytree(
        PACKAGE, site / "hexapod_workspace", ignore=shutil.ignore_patterns("__pycache__")
    )
    for path in [site, *site.rglob("*")]:
        mode = path.stat().st_mode
        path.chmod(mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
    cache = tmp_path / "cache"
    environment = {key: value for key, value in os.environ.items() if not key.startswith("NUMBA_")}
    environment.update(PYTHONPATH=str(site), XDG_CACHE_HOME=str(cache), HOME=str(tmp_path))
    script = (
        "import sys, hexapod_workspace as h; "
        f"assert h.__file__.startswith({str(site)!r}), h.__file__; "
        "sys.argv = ['hexapod-workspace', 'check', '--json', '--pose', '0', '10', '0', "
        f"'--config', {str(CONFIG)!r}]; "
        "from hexapod_workspace.cli import main; sys.exit(main())"
    )
    try:
        runs = [
            subprocess.run(
                [*runner, sys.executable, "-c", script],
                env=environment,
                cwd=tmp_path,
                capture_output=True,
                text=True,
                timeout=600,
                check=False,
            )
            for _ in range(2)
        ]
    finally:
        for path in [site, *site.rglob("*")]:
            path.chmod(path.stat().st_mode | stat.S_IWUSR)
    first, second = runs
    assert first.returncode == 0, first.stderr
    assert second.returncode == 0, second.stderr
    assert first.stdout == second.stdout
    lines = first.stderr.strip().splitlines()
    assert len(lines) == 1 and "compiling the numerical kernels" in lines[0], first.stderr
    assert str(cache / "hexapod_workspace" / "numba-") in lines[0]
    assert second.stderr == ""
    assert any((cache / "hexapod_workspace").rglob("numba-*/**/*.nbi"))
    assert not list(site.rglob("__pycache__/*.nbi"))


def _python(code: str, **environment: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, **environment},
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )


def test_one_signature_per_kernel_after_a_mixed_workload():
    """Inputs of every layout (strided views, read-only, integer, Fortran order, Python lists)
    are normalised at the boundary: each kernel of the variant has one compiled signature."""
    code = """
import numpy as np
from hexapod_workspace import check, example_manipulator, projected_workspace
from hexapod_workspace.core import kernels
from hexapod_workspace.core.evaluation.check import check_pose, pose_margins
from hexapod_workspace.core.workspaces.orientation import torsion_range
m = example_manipulator()
T = np.eye(4)
T[:3, 3] = m.position
angles = np.radians([[0, 10, 0], [30, 20, 5]])
frozen = angles.copy()
frozen.setflags(write=False)
check(m, angles, T[:3, 3])
check(m, frozen, tuple(m.position))
check(m, np.asfortranarray(np.tile(angles, (3, 1))), list(m.position))
check(m, np.zeros((2, 3), dtype=np.int64), m.position.astype(np.float32))
check(m, [[0.0, 0.1, 0.0]])
check_pose(m, 0, 0.1, 0, T[:3, 3])
check_pose(m, 0.0, 0.1, 0.0)
pose_margins(m, np.eye(3)[None], T[:3, 3])
pose_margins(m, np.asfortranarray(np.eye(3))[None], [0.0, 0.0, -1.3])
projected_workspace(m, T[:3, 3], method="exact", n_phi=8)
projected_workspace(m, list(m.position), method="torsion_zero", n_phi=8)
torsion_range(m, 0.3, 0.2, T[:3, 3])
for key, variant in kernels._VARIANTS.items():
    for name, dispatcher in variant._asdict().items():
        if name != "collide":
            print(key, name, len(dispatcher.signatures))
"""
    done = _python(code)
    assert done.returncode == 0, done.stderr
    counts = [line.rsplit(" ", 2) for line in done.stdout.splitlines()]
    assert counts, done.stdout
    assert len(counts) == 5 and all(count == "1" for *_, count in counts), done.stdout


def test_a_6ups_check_compiles_no_stage_it_does_not_use(tmp_path):
    """The switches leave the moving-base, collision and singularity stages out of the 6-UPS
    kernel: with a cold cache, a check of the packaged example compiles none of their helpers
    (each stage costs tens of seconds of compilation)."""
    code = """
import numpy as np
from hexapod_workspace import check, example_manipulator
from hexapod_workspace.core.kernels import blocks as block_kernels, collision as collision_kernels
from hexapod_workspace.core.kernels import pose as pose_kernels
check(example_manipulator(), np.radians([[0, 30, 0]]))
for name in ("_pose_moving", "_pose_collision", "_block_collision", "_block_singularity",
             "_pose_singularity", "_leg_planes_pus", "_leg_planes_rus"):
    owner = pose_kernels if hasattr(pose_kernels, name) else block_kernels
    print(name, len(getattr(owner, name).signatures))
print("collision_margin", len(collision_kernels.collision_margin.signatures))
print("_check_block", len(block_kernels._check_block.signatures))
"""
    done = _python(code, NUMBA_CACHE_DIR=str(tmp_path))
    assert done.returncode == 0, done.stderr
    counts = dict(line.split() for line in done.stdout.splitlines())
    assert counts.pop("_check_block") == "1", done.stdout
    assert set(counts.values()) == {"0"}, done.stdout


def test_kernel_sources_name_every_module_with_compiled_code():
    """The cache directory is named by a hash of KERNEL_SOURCES: a module with compiled code
    missing from it would be loaded stale from the cache after a change."""
    from hexapod_workspace.core.base import jit

    decorated = set()
    for path in PACKAGE.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        if any(mark in text for mark in ("@_jit", "@_helper", "@_inline", "numba.njit(")):
            decorated.add(path.resolve())
    assert decorated
    assert decorated <= {source.resolve() for source in jit.KERNEL_SOURCES}


def test_a_child_process_of_another_copy_uses_its_own_cache(tmp_path, monkeypatch):
    """The cache setting this process made (NUMBA_CACHE_DIR and its owner) is inherited by a
    child of the same tree, which shares it; a child running another copy of the package (the
    colcon install space, started from a test of the source tree) uses the copy's own cache,
    where its kernels were compiled; a directory the user set after that is the user's. (The
    child's decision, taken with the inherited environment and the copy's folder.)"""
    from hexapod_workspace.core.base import jit

    inherited = dict(os.environ)
    assert jit.CACHE_DIRECTORY is not None
    assert inherited["NUMBA_CACHE_DIR"] == str(jit.CACHE_DIRECTORY)
    assert inherited["HEXAPOD_WORKSPACE_CACHE_OWNER"].startswith(str(jit._CORE) + os.pathsep)
    assert jit._cache_directory() == jit.CACHE_DIRECTORY  # the same tree

    core = tmp_path / "install" / "hexapod_workspace" / "core"  # the other copy
    monkeypatch.setattr(jit, "_CORE", core)
    assert jit._cache_directory() == core / "__pycache__" / jit.CACHE_NAME
    users = tmp_path / "users"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(users))
    assert jit._cache_directory() == users / jit.CACHE_NAME
