"""What a fresh clone meets before any computation: the Python and Node.js requirements, the DDS
domain of the tools' ROS environment and the install hint of the atlas extra. The tools/
scripts run for real, with stand-in interpreters where a version this machine does not have is
needed."""

from __future__ import annotations

import ast
import os
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BASH = shutil.which("bash") or "/bin/bash"


def _setup_keywords() -> dict[str, object]:
    """The literal keyword arguments of setup() in setup.py."""
    tree = ast.parse((ROOT / "setup.py").read_text(encoding="utf-8"))
    call = next(
        node
        for node in ast.walk(tree)
        if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "setup"
    )
    return {
        kw.arg: ast.literal_eval(kw.value)
        for kw in call.keywords
        if kw.arg in {"python_requires", "extras_require"}
    }


def _min_python() -> str:
    text = (ROOT / "tools" / "common.sh").read_text(encoding="utf-8")
    match = re.search(r"^MIN_PYTHON=(\d+\.\d+)$", text, re.MULTILINE)
    assert match, "tools/common.sh defines MIN_PYTHON"
    return match.group(1)


def _stand_in(folder: Path, name: str, output: str) -> Path:
    """An executable ``folder/name`` that prints ``output`` whatever it is asked."""
    path = folder / name
    path.write_text(f"#!{BASH}\necho {shlex.quote(output)}\n", encoding="utf-8")
    path.chmod(0o755)
    return path


# -------------------------------------------------------------------------------------- Python
def test_the_python_requirement_is_the_same_everywhere():
    minimum = _min_python()
    assert _setup_keywords()["python_requires"] == f">={minimum}"
    tools = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]
    assert tools["ruff"]["target-version"] == "py" + minimum.replace(".", "")
    assert tools["mypy"]["python_version"] == minimum
    for page in ("README.md", "docs/getting_started.md"):
        text = (ROOT / page).read_text(encoding="utf-8")
        stated = set(re.findall(r"Python (?:≥|>=) ?(\d+\.\d+)", text))
        assert stated == {minimum}, (page, stated)
    assert sys.version_info >= tuple(int(v) for v in minimum.split("."))


def test_venv_refuses_an_old_interpreter_with_one_line_before_pip(tmp_path):
    old = _stand_in(tmp_path, "python3.10", "3.10")
    venv = tmp_path / "venv"
    env = {**os.environ, "PYTHON": str(old), "VENV": str(venv)}
    done = subprocess.run(
        [BASH, str(ROOT / "tools" / "venv.sh"), "base"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
        check=False,
    )
    assert done.returncode == 1
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert "Python 3.10" in lines[0] and f">= {_min_python()}" in lines[0]
    assert "apsw" in lines[0]  # the cause: the pinned requirements
    assert not venv.exists()  # stopped before anything was created or downloaded
    # No such interpreter at all: one line too.
    env["PYTHON"] = str(tmp_path / "no-python")
    done = subprocess.run(
        [BASH, str(ROOT / "tools" / "venv.sh"), "base"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
        check=False,
    )
    assert done.returncode == 1 and len(done.stderr.splitlines()) == 1, done.stderr
    assert "no Python interpreter" in done.stderr


# ------------------------------------------------------------------------------------- Node.js
def _check_node(path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [BASH, str(ROOT / "tools" / "check_node.sh")],
        capture_output=True,
        text=True,
        env={**os.environ, "PATH": str(path)},
        timeout=30,
        check=False,
    )


@pytest.mark.parametrize(
    ("programs", "words"),
    [
        ({}, "needs Node.js >= 18 and npm"),
        ({"node": "v20.20.2"}, "needs Node.js >= 18 and npm"),  # npm missing
        ({"node": "v16.20.0", "npm": "8.19.4"}, "found node v16.20.0"),
    ],
)
def test_make_test_names_a_missing_or_old_nodejs_in_one_line(tmp_path, programs, words):
    for tool in ("dirname",):  # what the script itself needs besides bash
        (tmp_path / tool).symlink_to(shutil.which(tool) or f"/usr/bin/{tool}")
    for name, version in programs.items():
        _stand_in(tmp_path, name, version)
    done = _check_node(tmp_path)
    assert done.returncode == 1
    assert len(done.stderr.splitlines()) == 1 and words in done.stderr, done.stderr


def test_node_check_passes_here_and_make_test_runs_it_first():
    if shutil.which("node") is None:
        pytest.skip("no Node.js here")
    done = _check_node(Path(os.environ["PATH"]))
    assert (done.returncode, done.stderr) == (0, "")
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert re.search(r"^test: node-check ", makefile, re.MULTILINE)
    for page in ("README.md", "docs/getting_started.md"):
        text = (ROOT / page).read_text(encoding="utf-8")
        assert "Node.js ≥ 18 with npm" in text.split("## Command line")[0].split("## The demo")[0]


# ------------------------------------------------------------------------------- ROS_DOMAIN_ID
def _domain(script: str, env: dict[str, str]) -> str:
    done = subprocess.run(
        [BASH, "-c", script],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=30,
        check=True,
    )
    return done.stdout.strip()


@pytest.mark.skipif(not (ROOT / ".venv" / "bin" / "python").exists(), reason="needs .venv")
def test_node_and_client_shells_share_one_documented_domain():
    env = {k: v for k, v in os.environ.items() if k != "ROS_DOMAIN_ID"}
    env.pop("VENV", None)
    with_env = f"tools/with_ros_env.sh {BASH} -c 'echo $ROS_DOMAIN_ID'"
    sourced = "source tools/ros_env.sh && echo $ROS_DOMAIN_ID"
    # Two shells each (different PIDs): the node's and the client's.
    seen = {_domain(with_env, env), _domain(with_env, env), _domain(sourced, env)}
    seen.add(_domain(sourced, env))
    assert seen == {"0"}
    for page in ("README.md", "docs/ros.md"):
        text = (ROOT / page).read_text(encoding="utf-8")
        assert "otherwise use **0**, ROS 2's own default" in text, page
    # A domain the user chose is kept by both.
    env["ROS_DOMAIN_ID"] = "42"
    assert {_domain(with_env, env), _domain(sourced, env)} == {"42"}


# ------------------------------------------------------------------------------ the extra hint
def test_the_atlas_extra_is_named_once():
    from hexapod_workspace.atlas import EXTRA_REQUIREMENTS

    extras = _setup_keywords()["extras_require"]
    assert isinstance(extras, dict)
    assert tuple(extras["atlas"]) == EXTRA_REQUIREMENTS


def test_the_missing_extra_hint_is_a_command_that_works(tmp_path):
    """The hint, run as given from another folder (pip's --dry-run: nothing is changed), is
    accepted by the shell and by pip and is satisfied by this venv, which has the extra."""
    pytest.importorskip("dask")
    from hexapod_workspace.atlas import install_hint

    command = install_hint().split(" (")[0]
    words = shlex.split(command)
    assert words[:4] == [sys.executable, "-m", "pip", "install"]
    done = subprocess.run(
        [BASH, "-c", command.replace(" install ", " install --dry-run --no-index ", 1)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Would install" not in done.stdout  # every requirement already satisfied here


# ------------------------------------------------------------------------ declared ranges
def test_pip_install_works_at_both_ends_of_the_declared_ranges(tmp_path):
    """``pip install .`` in fresh venvs, with the newest releases pip resolves and with numpy
    and numba at setup.py's lower bounds: each imports, answers ``check`` as the pinned venv
    does and runs ``projected --method exact`` (tools/check_install.py; needs the package
    index, as every venv here does)."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "check_install.py"), "--keep", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=1800,
        check=False,
    )
    assert done.returncode == 0, done.stderr + done.stdout
    lines = done.stdout.splitlines()
    assert [line.split(":")[0] for line in lines] == ["newest", "lowest"], done.stdout
    bounds = {
        name: version
        for name, version in (
            re.match(r"^([a-z]+)>=([0-9.]+)$", item).groups()  # type: ignore[union-attr]
            for item in ("numpy>=1.26", "numba>=0.59")
        )
    }
    assert f"numpy {bounds['numpy']}.0, numba {bounds['numba']}.0" in lines[1], lines[1]
