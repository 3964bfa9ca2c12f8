"""The installed console script in a real subprocess: a few smoke tests (the rest of the CLI is
tested in-process through ``main(argv, out=, err=)``)."""

from __future__ import annotations

import json

from cli_support import run_cli


def test_help_and_version():
    done = run_cli("--help")
    assert done.returncode == 0
    for name in ("check", "projected", "orientation", "torsion-range", "replay", "demo"):
        assert name in done.stdout
    assert run_cli("--version").stdout.startswith("hexapod-workspace ")


def test_check_json_and_exit_codes():
    done = run_cli("--json", "check", "--pose", "0", "0", "0")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["poses"][0]["reachable"] is True
    done = run_cli("check", "--pose", "0", "60", "0")
    assert done.returncode == 1
    assert done.stderr == "hexapod-workspace: 1 of 1 poses unreachable\n"


def test_bad_input_is_one_line_on_stderr_never_a_traceback(tmp_path):
    for args in (
        ["check", "--pose", "0", "0", "0", "--position", "0", "0", "-1e300"],
        ["projected", "--plot", str(tmp_path / "x.txt")],
        ["orientation", "--tol-deg", "10"],
    ):
        done = run_cli(*args)
        assert done.returncode == 2, args
        assert done.stdout == ""
        assert len(done.stderr.strip().splitlines()) == 1, done.stderr
        assert done.stderr.startswith("hexapod-workspace: error: ")


def test_poses_through_a_pipe():
    """/dev/stdin through a pipe, and ``-``, are read once, whole."""
    for name in ("/dev/stdin", "-"):
        done = run_cli("--json", "check", "--poses-file", name, input="10,20,5\n0,0,0\n")
        assert done.returncode == 0, done.stderr
        assert len(json.loads(done.stdout)["poses"]) == 2
