"""The atlas engine on real Dask clusters (scheduler + worker processes on 127.0.0.1 only) and
its Zarr store: same values as per-position calls, same store locally and distributed, a killed
worker, an interrupted run resumed, and the CLI's bad-input exits.

Every cluster here is started by the test: ``LocalCluster(host='127.0.0.1', processes=True,
n_workers=2, threads_per_worker=1, dashboard_address=None)``. Every wait is bounded.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from cli_support import cli_command, run_cli
from distributed import Client, LocalCluster

from hexapod_workspace import (
    AtlasError,
    AtlasGrid,
    AtlasOptions,
    __version__,
    workspace_atlas,
)
from hexapod_workspace.atlas.store import MARKER, open_atlas
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping
from hexapod_workspace.core.workspaces.atlas import ATLAS_VARIABLES, position_capability

OPTIONS = AtlasOptions(n_phi=24, tolerance=1e-3)
#: 3 × 2 × 3 = 18 positions around the home position, in 6 chunks of 3 (one z column each).
GRID = AtlasGrid.box([-0.1, 0.1, 0.0, 0.1, -1.35, -1.15], 0.1)
CHUNK = (1, 1, 3)
#: The same job for the CLI (its default n_phi/tolerance differ: pass them).
CLI_JOB = [
    "atlas",
    "--box",
    "-0.1",
    "0.1",
    "0.0",
    "0.1",
    "-1.35",
    "-1.15",
    "--step",
    "0.1",
    "--n-phi",
    "24",
    "--tol-deg",
    str(np.degrees(1e-3)),
    "--chunk",
    *map(str, CHUNK),
]


def _cluster() -> LocalCluster:
    return LocalCluster(
        host="127.0.0.1",
        processes=True,
        n_workers=2,
        threads_per_worker=1,
        dashboard_address=None,
    )


@pytest.fixture(scope="module")
def reference(example, tmp_path_factory) -> xr.Dataset:
    """The atlas computed in this process, without Dask (workers=0)."""
    store = tmp_path_factory.mktemp("atlas") / "reference.zarr"
    run = workspace_atlas(example, GRID, store=store, options=OPTIONS, workers=0, chunk=CHUNK)
    assert run.chunks_computed == run.chunks_total == 6
    return run.dataset


def test_store_layout_and_values_equal_per_position_calls(reference, example):
    assert reference.sizes["x"] == 3 and reference.sizes["y"] == 2 and reference.sizes["z"] == 3
    np.testing.assert_allclose(reference["z"].values, [-1.35, -1.25, -1.15])
    for name in ("x", "y", "z"):
        assert reference[name].attrs["units"] == "m"
    for variable in ATLAS_VARIABLES[:-1]:  # orientation_volume is off by default
        attrs = reference[variable.name].attrs
        assert attrs["units"] == variable.units and attrs["long_name"] == variable.long_name
    assert "orientation_volume" not in reference
    assert reference.attrs["software_version"] == __version__
    assert reference.attrs["complete"] is True
    stored = manipulator_from_mapping(json.loads(reference.attrs["manipulator_parameters"]))
    assert stored == example
    assert np.all(reference[MARKER].values == 1)
    rng = np.random.default_rng(20261123)
    for index in rng.choice(GRID.size, size=4, replace=False):
        i, j, k = np.unravel_index(index, GRID.shape)
        expected = position_capability(example, [GRID.x[i], GRID.y[j], GRID.z[k]], OPTIONS)
        for name, value in expected.items():
            np.testing.assert_equal(float(reference[name].values[i, j, k]), value, err_msg=name)
    assert reference["reference_reachable"].values.all()  # all near home: reachable


def test_distributed_cluster_gives_the_identical_store(reference, example, tmp_path):
    with _cluster() as cluster:
        run = workspace_atlas(
            example,
            GRID,
            store=tmp_path / "distributed.zarr",
            options=OPTIONS,
            scheduler=cluster.scheduler_address,
            chunk=CHUNK,
        )
    assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
    assert run.workers == 2
    xr.testing.assert_identical(run.dataset, reference)


#: Heavier per chunk (a 3-D workspace per position) so that a chunk is still computing when the
#: first one reports: with the compiled kernels the light OPTIONS finish before a kill lands.
HEAVY = AtlasOptions(n_phi=24, tolerance=1e-3, volume=True)


def test_a_worker_killed_mid_run_does_not_fail_the_job(example, tmp_path):
    reference = workspace_atlas(
        example, GRID, store=tmp_path / "heavy.zarr", options=HEAVY, workers=0, chunk=CHUNK
    ).dataset
    killed: list[int] = []
    with _cluster() as cluster:
        with Client(cluster) as observer:  # closed before the job: one client at a time
            pids = sorted(observer.run(os.getpid).values())
        assert len(pids) == 2

        def kill_a_worker(done: int, total: int) -> None:
            # After the first chunk, 5 of 6 (heavy) chunks are left for 2 workers: both are
            # computing. SIGKILL one of them; the nanny restarts it, the scheduler reruns its task.
            if killed or done == 0 or done >= total:
                return
            os.kill(pids[0], signal.SIGKILL)
            killed.append(pids[0])

        run = workspace_atlas(
            example,
            GRID,
            store=tmp_path / "killed.zarr",
            options=HEAVY,
            scheduler=cluster.scheduler_address,
            chunk=CHUNK,
            progress=kill_a_worker,
        )
    assert killed, "the job ended before a worker could be killed: nothing was tested"
    assert run.chunks_computed == 6
    xr.testing.assert_identical(run.dataset, reference)


def _chunk_files(store: Path) -> dict[str, int]:
    """Modification times (ns) of every data chunk file of the store."""
    return {
        str(path.relative_to(store)): path.stat().st_mtime_ns
        for path in store.rglob("*")
        if path.is_file() and "/c/" in f"/{path.relative_to(store).as_posix()}"
    }


def test_interrupted_run_resumes_with_only_the_missing_chunks(reference, example, tmp_path):
    store = tmp_path / "interrupted.zarr"

    def interrupt_after_two(done: int, total: int) -> None:
        if done >= 6:  # two chunks of 3 positions written
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        workspace_atlas(
            example,
            GRID,
            store=store,
            options=OPTIONS,
            workers=0,
            chunk=CHUNK,
            progress=interrupt_after_two,
        )
    partial = open_atlas(store).load()
    assert partial.attrs["complete"] is False
    assert int(partial[MARKER].values.sum()) == 2
    before = _chunk_files(store)
    # No silent overwrite; the refusal says what the store holds and what to do.
    with pytest.raises(AtlasError, match=r"incomplete \(2 of 6 chunks done.*resume=True"):
        workspace_atlas(example, GRID, store=store, options=OPTIONS, workers=0, chunk=CHUNK)
    with _cluster() as cluster:
        run = workspace_atlas(
            example,
            GRID,
            store=store,
            options=OPTIONS,
            scheduler=cluster.scheduler_address,
            chunk=CHUNK,
            resume=True,
        )
    assert (run.chunks_computed, run.positions_computed) == (4, 12)
    after = _chunk_files(store)
    # The data chunks of the two finished atlas chunks were not written again.
    done_before = np.flatnonzero(partial[MARKER].values.ravel() == 1)
    for chunk_id in done_before:
        i, j, _ = np.unravel_index(chunk_id, (3, 2, 1))
        for name in ("tilt_capability", "psi_max"):
            key = f"{name}/c/{i}/{j}/0"
            assert after[key] == before[key], key
    xr.testing.assert_identical(run.dataset, reference)


def test_resume_refuses_another_run(example, tmp_path):
    store = tmp_path / "a.zarr"
    small = AtlasGrid.box([0, 0, 0, 0, -1.3, -1.3], 0.1)
    workspace_atlas(example, small, store=store, options=OPTIONS, workers=0)
    other = AtlasOptions(n_phi=36, tolerance=1e-3)
    with pytest.raises(AtlasError, match="atlas options"):
        workspace_atlas(example, small, store=store, options=other, workers=0, resume=True)


# ---------------------------------------------------------------------------- CLI
def test_cli_json_plots_and_dexterous_volume(reference, tmp_path):
    plots = tmp_path / "plots"
    done = run_cli(
        "--json",
        *CLI_JOB,
        "--out",
        str(tmp_path / "cli.zarr"),
        "--workers",
        "2",
        "--tilt-required-deg",
        "30",
        "--tilt-required-deg",
        "35",
        "--plot",
        str(plots),
        timeout=180,
    )
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    assert document["positions"] == 18 and document["reachable_positions"] == 18
    assert document["workers"] == 2
    capability = np.degrees(reference["tilt_capability"].values)
    assert document["tilt_capability_deg"]["min"] == pytest.approx(capability.min())
    assert document["tilt_capability_deg"]["mean"] == pytest.approx(capability.mean())
    for tilt in (30, 35):
        count = int((capability >= tilt).sum())
        assert document["dexterous_volume_m3"][str(tilt)] == pytest.approx(count * 0.1**3)
    assert 0 < document["dexterous_volume_m3"]["35"] < document["dexterous_volume_m3"]["30"]
    assert document["store"] == str(tmp_path / "cli.zarr")
    for name in ("atlas_tilt_slices.png", "atlas_dexterous.png"):
        assert (plots / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    xr.testing.assert_identical(open_atlas(tmp_path / "cli.zarr").load(), reference)


def test_cli_interrupted_by_sigint_then_resumed(reference, tmp_path):
    """A real interruption: SIGINT to the CLI (on its local cluster) once a chunk marker is on
    disk, then --resume (in process)."""
    store = tmp_path / "sigint.zarr"
    env = dict(os.environ, MPLBACKEND="Agg")
    process = subprocess.Popen(
        [*cli_command(), *CLI_JOB, "--out", str(store), "--workers", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and process.poll() is None:
            if any((store / MARKER / "c").rglob("*")) if (store / MARKER / "c").exists() else False:
                break
            time.sleep(0.05)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(timeout=10)
    assert process.returncode == 130, stderr
    assert stderr.strip() == "hexapod-workspace: interrupted"
    markers = int(open_atlas(store)[MARKER].values.sum())
    assert 1 <= markers < 6
    done = run_cli("--json", *CLI_JOB, "--out", str(store), "--workers", "0", "--resume")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["chunks_computed"] == 6 - markers
    xr.testing.assert_identical(open_atlas(store).load(), reference)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.mark.parametrize(
    ("arguments", "words"),
    [
        (["--box", "0.1", "-0.1", "0", "0", "-1.3", "-1.3", "--step", "0.1"], "empty"),
        (["--box", "0", "0", "0", "0", "-1.3", "-1.3", "--step", "0"], "step"),
        (["--box", "-1", "1", "-1", "1", "-2", "0", "--step", "0.01"], "--force"),
        (["--box", "0", "0", "0", "0", "-1.3", "-1.3", "--step", "0.1", "--workers", "-1"], "0 or"),
    ],
)
def test_cli_bad_input_exits_2_with_one_line(arguments, words, tmp_path):
    done = run_cli("atlas", *arguments, "--out", str(tmp_path / "a.zarr"), timeout=60)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and words in done.stderr, done.stderr
    assert not (tmp_path / "a.zarr").exists()


def test_cli_unreachable_scheduler_exits_2(tmp_path):
    address = f"tcp://127.0.0.1:{_free_port()}"  # nothing listens there
    done = run_cli(
        "atlas",
        *CLI_JOB[1:],
        "--out",
        str(tmp_path / "a.zarr"),
        "--scheduler",
        address,
        timeout=60,
    )
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "cannot reach the Dask scheduler" in done.stderr
    assert not (tmp_path / "a.zarr").exists()


def test_cli_existing_store_without_resume_exits_2_and_keeps_it(tmp_path):
    store = tmp_path / "a.zarr"
    job = ["atlas", "--box", "0", "0", "0", "0", "-1.3", "-1.3", "--step", "0.1", "--n-phi", "12"]
    first = run_cli(*job, "--out", str(store), "--workers", "0")
    assert first.returncode == 0, first.stderr
    again = run_cli(*job, "--out", str(store), "--workers", "0")
    assert again.returncode == 2 and again.stderr.count("\n") == 1
    assert "already exists and is complete (1 of 1 chunks)" in again.stderr
    assert open_atlas(store).attrs["complete"] is True


def test_explicit_positions_with_the_optional_volume(example, tmp_path):
    positions = [[0.0, 0.0, -1.3], [0.2, 0.2, -0.95], [0.0, 0.0, -0.7]]  # the last: unreachable
    options = AtlasOptions(n_phi=24, tolerance=1e-3, volume=True, n_rays=24)
    run = workspace_atlas(
        example,
        AtlasGrid.from_positions(positions),
        store=tmp_path / "points.zarr",
        options=options,
        workers=0,
        chunk=(2,),
    )
    dataset = run.dataset
    assert dict(dataset["tilt_capability"].sizes) == {"position": 3}
    np.testing.assert_allclose(dataset["z"].values, [-1.3, -0.95, -0.7])
    assert dataset["orientation_volume"].attrs["units"] == "rad^3"
    assert dataset["reference_reachable"].values.tolist() == [True, True, False]
    assert np.isnan(dataset["orientation_volume"].values[2])
    for row, position in enumerate(positions[:2]):
        expected = position_capability(example, position, options)
        for name, value in expected.items():
            np.testing.assert_equal(float(dataset[name].values[row]), value, err_msg=name)
    assert run.chunks_total == 2 and run.dexterous_volume(0.1) is None  # points sample no volume
