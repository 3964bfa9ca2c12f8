"""``hexapod-workspace import-genhexkins``: a LinuxCNC genhexkins machine as a parameters file.

The reading and the conversion are :func:`hexapod_workspace.core.model.genhexkins.read_genhexkins`;
this writes the result as a ROS 2 parameters file (the one ``--config`` and the node read),
after building the model from it, so that a file it writes is one the package accepts.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..core.evaluation.loading import manipulator_from_mapping, require_usable
from ..core.model.genhexkins import read_genhexkins
from .inputs import CliError

__all__ = ["IMPORT_DESCRIPTION", "IMPORT_HELP", "cmd_import_genhexkins", "import_arguments"]

IMPORT_HELP = "convert a LinuxCNC genhexkins machine (HAL + INI files) to a parameters file"
IMPORT_DESCRIPTION = (
    "Reads the genhexkins pins set by the HAL files (base and platform joints, spindle and "
    "tool offsets) and the INI's units, home pose and strut limits, and writes a parameters "
    "file for --config and the node. Lengths on this command line are in the machine's linear "
    "unit ([TRAJ] LINEAR_UNITS); angles in degrees. Poses of that machine in A, B, C are "
    "--angles xyz-fixed. Exit 0 when the file is written, 2 for bad input."
)


def import_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--ini", required=True, metavar="FILE", help="the machine's INI file")
    parser.add_argument(
        "--hal",
        required=True,
        action="append",
        metavar="FILE",
        help="a HAL file that sets genhexkins pins (repeat for several, read in order)",
    )
    parser.add_argument(
        "--joint-max-angle-deg",
        required=True,
        type=float,
        nargs="+",
        metavar="DEG",
        help="largest angle between a joint axis and its leg: one value for base and platform "
        "joints, or two (base, platform); the axes are the legs' directions at HOME",
    )
    parser.add_argument(
        "--leg-length",
        type=float,
        nargs=2,
        metavar=("MIN", "MAX"),
        help="strut length limits instead of the INI's [JOINT_N] MIN_LIMIT/MAX_LIMIT",
    )
    parser.add_argument(
        "--tool-offset",
        type=float,
        metavar="L",
        help="the tool length to convert for, when a 'net' drives genhexkins.tool-offset",
    )
    parser.add_argument(
        "--leg-diameter", type=float, default=0.0, metavar="D", help="leg diameter (default 0)"
    )
    parser.add_argument(
        "--paired-joint-length",
        type=float,
        default=0.0,
        metavar="C",
        help="where legs share a joint: the length of each leg the joint occupies (default 0)",
    )
    parser.add_argument(
        "-o", "--output", required=True, metavar="FILE.yaml", help="the parameters file to write"
    )


def _read(path: str, what: str) -> tuple[str, str]:
    try:
        return path, Path(path).read_text(encoding="utf-8", errors="replace")
    except OSError as error:
        msg = f"{what} {path}: cannot read it ({error.strerror or error})"
        raise CliError(msg) from None


def _nested(parameters: dict[str, Any]) -> dict[str, Any]:
    nested: dict[str, Any] = {}
    for name, value in parameters.items():
        group, key = name.split(".", 1)
        nested.setdefault(group, {})[key] = value
    return nested


def _rounded(value: Any) -> Any:
    """A number or a list of numbers to twelve decimals (a new list: no YAML alias)."""
    if isinstance(value, list):
        return [round(float(v), 12) for v in value]
    return round(float(value), 12)


def cmd_import_genhexkins(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """Run ``import-genhexkins``; returns the exit code."""
    import yaml  # PyYAML: the package's configuration loader uses it too

    angles = options.joint_max_angle_deg
    if len(angles) not in (1, 2) or not all(0.0 < a < 180.0 for a in angles):
        msg = f"--joint-max-angle-deg: expected one or two angles in (0, 180), got {angles}"
        raise CliError(msg)
    for flag, value in (
        ("--leg-diameter", options.leg_diameter),
        ("--paired-joint-length", options.paired_joint_length),
        ("--tool-offset", options.tool_offset),
    ):
        if value is not None and not math.isfinite(value):
            msg = f"{flag}: expected a finite number, got {value}"
            raise CliError(msg)
    machine = read_genhexkins(
        [_read(path, "--hal") for path in options.hal],
        _read(options.ini, "--ini"),
        joint_max_angle=(math.radians(angles[0]), math.radians(angles[-1])),
        leg_length=tuple(options.leg_length) if options.leg_length else None,
        tool_offset=options.tool_offset,
        leg_diameter=options.leg_diameter,
        paired_joint_length=options.paired_joint_length,
    )
    model = require_usable(manipulator_from_mapping(machine.parameters, warn=False))
    # Twelve decimals (picometres, nanoradians): the file reads as written, not as binary noise
    # (0.33654999999999996 m for 13.25 in).
    parameters = {
        name: _rounded(value)
        for name, value in {
            **machine.parameters,
            "pose.position": machine.parameters["geometry.home_position"],
        }.items()
    }
    header = [
        "# A LinuxCNC genhexkins machine, written by hexapod-workspace import-genhexkins.",
        "# Lengths in m (converted from the machine's unit), angles in rad.",
        *(f"# {source}" for source in machine.sources),
        "# Poses in LinuxCNC's A, B, C (R = Rz(C)·Ry(B)·Rx(A)): --angles xyz-fixed.",
    ]
    document = {"hexapod_workspace": {"ros__parameters": _nested(parameters)}}
    text = "\n".join(header) + "\n" + yaml.safe_dump(document, default_flow_style=None)
    Path(options.output).write_text(text, encoding="utf-8")
    pair_i, pair_j = np.triu_indices(6, 1)
    shared = model.shared_base_pairs | model.shared_platform_pairs
    pairs = [[int(i) + 1, int(j) + 1] for i, j in zip(pair_i[shared], pair_j[shared], strict=True)]
    if options.json:
        summary = {
            "output": str(options.output),
            "linear_unit": machine.unit,
            "metres_per_unit": machine.scale,
            "joint_z_offset": machine.offset,
            "legs_sharing_a_joint": pairs,
            "passed_over": dict(sorted(machine.passed_over.items())),
            "sources": machine.sources,
        }
        out.write(json.dumps(summary, indent=2) + "\n")
        return 0
    out.write(f"wrote {options.output}: a genhexkins machine in {machine.unit}\n")
    out.write(f"  offset added to the joints' z: {machine.offset:g} {machine.unit}\n")
    shown = ", ".join(f"{i} and {j}" for i, j in pairs) or "none"
    out.write(f"  legs sharing a joint: {len(pairs)} pair(s) ({shown})\n")
    passed = ", ".join(f"{name} ({count})" for name, count in sorted(machine.passed_over.items()))
    out.write(f"  passed over (cannot change a strut length): {passed or 'none'}\n")
    return 0
