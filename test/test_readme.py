"""The examples of the README and of the documentation pages are what the code prints and
answers (the README's long sections now live in ``docs/``, and are checked there).

* every ``$ hexapod-workspace ...`` example of the README's *Command line* section and of the
  command-line page (``docs/cli.md``) is run, and its printed lines must be the page's, except
  for the measured times (masked: they are stated with their conditions, never asserted) and a
  ``...`` line, which stands for the rest;
* the demo table of the README and of ``docs/getting_started.md`` is what the demo prints;
* the node's Trigger, action and topic examples (``docs/ros.md``) carry the numbers the node
  computes: the same job the node's worker runs
  (:func:`hexapod_workspace.ros.worker.compute_fields`, no rclpy), with the node's default
  parameters.

The README's interface table and the node's parameters are checked against a live node in
``test/ros/test_ros_readme.py``; the atlas snippet (``docs/atlas.md``) in
``test_readme_atlas.py``; the README's links in ``test_readme_links.py``.
"""

from __future__ import annotations

import json
import math
import re
import shlex
from pathlib import Path

import numpy as np
import pytest
from cli_support import run_main

from hexapod_workspace.core.base import resolution
from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.core.evaluation.loading import example_manipulator
from hexapod_workspace.ros.worker import WorkspaceJob, compute_fields

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
#: The documentation pages whose examples are checked here.
CLI_PAGE = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
GETTING_STARTED = (ROOT / "docs" / "getting_started.md").read_text(encoding="utf-8")
ROS_PAGE = (ROOT / "docs" / "ros.md").read_text(encoding="utf-8")
#: A measured time in the CLI's output ("23.4 ms", "2.34 s"): stated in the README, not tested.
TIME = re.compile(r"\b\d+(?:\.\d+)? (?:ms|s)\b")


def section(title: str, text: str = README) -> str:
    """The text from the heading ``title`` to the next heading of the same level."""
    level = title.split(" ", 1)[0]
    start = text.index(f"\n{title}\n")
    end = text.find(f"\n{level} ", start + len(title) + 2)
    return text[start : end if end > 0 else None]


def _examples(text: str) -> list[tuple[str, list[str], int]]:
    """(command line, the lines shown after it, its exit status) of every CLI example of
    ``text``; the status is 0 unless an ``$ echo $?`` line follows with another."""
    examples: list[tuple[str, list[str], int]] = []
    for block in re.findall(r"```\n(.*?)```", text, re.DOTALL):
        lines = block.splitlines()
        for k, line in enumerate(lines):
            if line.startswith("$ echo $?"):
                command, shown, _ = examples[-1]
                examples[-1] = (command, shown, int(lines[k + 1]))
            elif line.startswith("$ "):
                shown = []
                for rest in lines[k + 1 :]:
                    if rest.startswith("$ "):
                        break
                    shown.append(rest)
                examples.append((line[2:], shown, 0))
    return [example for example in examples if example[0].startswith("hexapod-workspace ")]


README_EXAMPLES = _examples(section("## Command line"))
PAGE_EXAMPLES = _examples(CLI_PAGE)
EXAMPLES = README_EXAMPLES + PAGE_EXAMPLES


def test_the_cli_examples_are_found():
    commands = [command.split()[1:3] for command, _, _ in PAGE_EXAMPLES]
    assert len(PAGE_EXAMPLES) >= 7, commands
    assert [status for _, _, status in PAGE_EXAMPLES].count(1) == 1  # an unreachable pose
    assert [status for _, _, status in README_EXAMPLES] == [1]  # the README's one example


@pytest.mark.parametrize(("command", "shown", "status"), EXAMPLES, ids=[e[0] for e in EXAMPLES])
def test_a_cli_example_prints_what_the_readme_shows(command, shown, status):
    code, out, err = run_main(*shlex.split(command)[1:])
    assert code == status, err
    stderr = [line.split("  ")[0] for line in shown if line.endswith("(stderr)")]
    stdout = [line for line in shown if not line.endswith("(stderr)")]
    for line in stderr:
        assert line.strip() in err
    printed = out.splitlines()
    if "--json" in command:  # one JSON document: compare values (last digits may differ)
        _assert_close(json.loads(out), json.loads("\n".join(stdout)))
        return
    if stdout and stdout[-1] == "...":
        stdout = stdout[:-1]
        printed = printed[: len(stdout)]
    assert [TIME.sub("<time>", line) for line in printed] == [
        TIME.sub("<time>", line) for line in stdout
    ]


def _assert_close(got, shown, path: str = "") -> None:
    """JSON values equal, numbers to 1e-9 relative (the README shows 12 significant digits)."""
    if isinstance(shown, dict):
        assert isinstance(got, dict) and set(got) == set(shown), path
        for key in shown:
            _assert_close(got[key], shown[key], f"{path}.{key}")
    elif isinstance(shown, list):
        assert isinstance(got, list) and len(got) == len(shown), path
        for k, (a, b) in enumerate(zip(got, shown, strict=True)):
            _assert_close(a, b, f"{path}[{k}]")
    elif isinstance(shown, float) and not isinstance(shown, bool):
        assert got == pytest.approx(shown, rel=1e-9, abs=1e-12), path
    else:
        assert got == shown, path


def test_the_demo_table_is_what_the_demo_prints(tmp_path):
    """The demo table of the README and of Getting started, times aside (measured, stated
    with their conditions)."""
    code, out, err = run_main("demo", "--out", str(tmp_path / "demo"))
    assert code == 0, err

    def rows(text: str) -> list[list[str]]:
        return [
            line.split("|")[1:-2]  # every cell but the times
            for line in text.splitlines()
            if line.startswith(("| on_axis |", "| off_axis |"))
        ]

    for text in (README, GETTING_STARTED):
        assert len(rows(text)) == 2
        assert rows(text) == rows(out)


# ------------------------------------------------------------------------- the node's examples
def _node_job(kind: int, position, n_rays: int, tolerance: float = resolution.DEFAULT_TOLERANCE):
    job = WorkspaceJob(
        manipulator=example_manipulator(),
        kind=int(kind),
        position=np.asarray(position, dtype=float),
        n_rays=n_rays,
        psi_step=resolution.DEFAULT_PSI_STEP,
        tolerance=tolerance,
        stamp_ns=0,
        frame_id="base",
    )
    summary, _ = compute_fields(job)
    return summary


def _shown_number(text: str, name: str) -> float:
    match = re.search(rf"\b{name}: (-?[0-9.]+)", text)
    assert match, name
    return float(match.group(1))


def test_the_trigger_examples_are_what_the_node_answers():
    ros = ROS_PAGE
    example = example_manipulator()
    jobs = {
        "compute_projected_workspace": (
            WorkspaceKind.PROJECTED_TORSION_ZERO,
            resolution.DEFAULT_N_PHI,
        ),
        "compute_orientation_workspace": (WorkspaceKind.ORIENTATION, resolution.DEFAULT_N_RAYS),
    }
    for service, (kind, rays) in jobs.items():
        match = re.search(
            rf"ros2 service call /hexapod_workspace/{service} std_srvs/srv/Trigger\n"
            r"response: success: true, message: '([^']*)'",
            ros,
        )
        assert match, service
        assert match.group(1) == _node_job(kind, example.position, rays)["message"]


def test_the_action_and_topic_examples_carry_the_node_s_numbers():
    ros = ROS_PAGE
    action = ros.split("$ ros2 action send_goal", 1)[1].split("```", 1)[0]
    assert "kind: 1, position: {x: 0.2, y: 0.2, z: -0.95}, n_rays: 360, tolerance: 1.0e-6" in action
    summary = _node_job(WorkspaceKind.PROJECTED_TORSION_ZERO, [0.2, 0.2, -0.95], 360, 1e-6)
    assert f"message: '{summary['message']}'" in action
    for name in ("tilt_min", "tilt_max", "solid_angle"):
        assert _shown_number(action, name) == pytest.approx(summary[name], abs=1e-5), name
    request = ros.split("hexapod_workspace_msgs/msg/WorkspaceRequest \\\n", 1)[1].split("```")[0]
    assert "kind: 0, position: {x: 0.0, y: 0.0, z: -1.3}" in request
    solid = _node_job(WorkspaceKind.ORIENTATION, [0.0, 0.0, -1.3], resolution.DEFAULT_N_RAYS)
    for name in ("psi_min", "psi_max", "volume"):
        assert _shown_number(request, name) == pytest.approx(solid[name], abs=1e-4), name
    assert math.isclose(-solid["psi_min"], solid["psi_max"], rel_tol=1e-9)
