"""A LinuxCNC ``genhexkins`` machine as this package's parameters.

LinuxCNC's generalised hexapod kinematics (``src/emc/kinematics/genhexkins.c``) reads the
machine from HAL pins, usually set in a HAL file, and from the INI file:

* ``genhexkins.base.N.{x,y,z}``: base joint N in the base (world) frame, and
  ``genhexkins.platform.N.{x,y,z}``: platform joint N in the platform frame (N = 0..5), in the
  machine's linear units. genhexkins's own code names the platform joints ``a[i]`` and the base
  joints ``b[i]``, the opposite of Bonev & Ryu's a_i (base) and b_i (platform) that this package
  keeps; the pins' names (base, platform) are what is read, so the naming cannot swap them.
* ``genhexkins.spindle-offset`` and ``genhexkins.tool-offset``: o = their sum is added to the z
  of *both* joint sets before the inverse kinematics, ``strut_i = q + R·(a_i + o·z) − (b_i +
  o·z)`` with q the commanded position (genhexkins_math.c): the controlled point lies o below
  the platform joints' plane along the platform's z. Written here as base joints b_i + o·z and
  platform joints a_i + o·z with the tool centre point at q: the same strut vectors, the same
  world frame. A ``tool-offset`` connected to ``motion.tooloffset.z`` by a ``net`` changes with
  the tool, so the tool length must be given (``tool_offset``): the parameters are for that tool.
* ``R = Rz(C)·Ry(B)·Rx(A)`` (``pmRpyMatConvert``): poses in A, B, C are ``--angles xyz-fixed``.
* ``genhexkins.screw-lead`` ≠ 0 turns on a strut-length correction for non-captive screws
  (with ``base-n`` and ``platform-n``), which this package does not model: refused. The forward
  kinematics' iteration controls (``convergence-criterion``, ``limit-iterations``,
  ``max-error``) and, with the correction off, ``base-n``/``platform-n`` cannot change a strut
  length: passed over and reported. Any other ``genhexkins`` pin is refused with its line.
* INI ``[KINS] KINEMATICS`` must be ``genhexkins``; ``[TRAJ] LINEAR_UNITS`` (``inch``, ``in``,
  ``imperial``, ``mm``, ``metric``) gives the unit; ``[TRAJ] HOME = x y z a b c`` the home pose
  (its orientation must be the identity: this package's home pose has none); ``[JOINT_N]
  MIN_LIMIT``/``MAX_LIMIT`` the strut lengths, unless given (LinuxCNC's simulation leaves them
  open, ±1000, which is no stroke and is refused with the hint).

genhexkins knows nothing of joint cones or leg diameters: the joint angle limits must be given,
the diameter and the paired-joint length may be (LinuxCNC's default machine has three pairs of
base joints: :mod:`~hexapod_workspace.core.base.validation`, *Paired joints*).
"""

from __future__ import annotations

import configparser
import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from ...errors import ConfigError

__all__ = ["LINEAR_UNITS", "GenhexMachine", "read_genhexkins"]

#: [TRAJ] LINEAR_UNITS as LinuxCNC spells them, metres per unit.
LINEAR_UNITS = {"inch": 0.0254, "in": 0.0254, "imperial": 0.0254, "mm": 1e-3, "metric": 1e-3}
#: Pins that cannot change a strut length (with ``screw-lead`` 0): passed over, reported.
PASSED_OVER = ("convergence-criterion", "limit-iterations", "max-error", "base-n", "platform-n")
_AXES = "xyz"


@dataclass
class GenhexMachine:
    """What :func:`read_genhexkins` read and made of it.

    Attributes
    ----------
    parameters : dict
        Dotted model parameters in SI units (m, rad), ready for
        :func:`~hexapod_workspace.core.evaluation.loading.manipulator_from_mapping`.
    unit : str
        The machine's linear unit as the INI spells it; ``scale`` metres per unit.
    scale : float
    offset : float
        o = spindle-offset + tool-offset added to the joints' z, in the machine's unit.
    passed_over : collections.Counter
        Pins passed over (they cannot change a strut length), by name.
    sources : list of str
        Where each group of values came from (file and line, or the caller), for the header of
        the written file.
    """

    parameters: dict[str, Any]
    unit: str
    scale: float
    offset: float
    passed_over: Counter[str] = field(default_factory=Counter)
    sources: list[str] = field(default_factory=list)


def _number(text: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        msg = f"{where}: expected a number, got {text!r}"
        raise ConfigError(msg) from None
    if not math.isfinite(value):
        msg = f"{where}: expected a finite number, got {text!r}"
        raise ConfigError(msg)
    return value


def _hal_pins(hal: Sequence[tuple[str, str]]) -> tuple[dict[str, tuple[float, str]], set[str]]:
    """``setp genhexkins.*`` values with their file and line, and the pins a ``net`` drives."""
    values: dict[str, tuple[float, str]] = {}
    driven: set[str] = set()
    for name, text in hal:
        for number, raw in enumerate(text.splitlines(), start=1):
            line = raw.split("#", 1)[0].strip()
            where = f"{name}:{number}"
            words = line.replace("=", " ").split()
            if not words:
                continue
            if words[0] == "setp" and len(words) >= 2 and words[1].startswith("genhexkins."):
                if len(words) != 3:
                    msg = f"{where}: expected 'setp PIN VALUE', got {line!r}"
                    raise ConfigError(msg)
                values[words[1][len("genhexkins.") :]] = (_number(words[2], where), where)
            elif words[0] == "net":
                driven.update(w[len("genhexkins.") :] for w in words if w.startswith("genhexkins."))
    return values, driven


def _joints(
    pins: dict[str, tuple[float, str]], group: str, offset: float, scale: float
) -> list[float]:
    """18 floats, m: the six joints of ``group`` with o added to z."""
    joints = []
    for n in range(6):
        for axis in _AXES:
            pin = f"{group}.{n}.{axis}"
            if pin not in pins:
                msg = (
                    f"genhexkins.{pin}: not set by a 'setp' line of the HAL files (genhexkins "
                    "would use its compiled-in default); set it"
                )
                raise ConfigError(msg)
            value = pins[pin][0] + (offset if axis == "z" else 0.0)
            joints.append(value * scale)
    return joints


def _ini(text: str, name: str) -> configparser.ConfigParser:
    ini = configparser.ConfigParser(
        strict=False, interpolation=None, inline_comment_prefixes=("#", ";")
    )
    ini.optionxform = str  # type: ignore[assignment,method-assign]  # keep LinuxCNC's case
    try:
        ini.read_string(text, source=name)
    except configparser.Error as error:
        msg = f"{name}: not an INI file ({' '.join(str(error).split())})"
        raise ConfigError(msg) from None
    return ini


def _ini_value(ini: configparser.ConfigParser, section: str, key: str, name: str) -> str:
    if not ini.has_option(section, key):
        msg = f"{name}: [{section}] {key} is missing"
        raise ConfigError(msg)
    return ini.get(section, key).strip()


def read_genhexkins(
    hal: Sequence[tuple[str, str]],
    ini: tuple[str, str],
    *,
    joint_max_angle: tuple[float, float],
    leg_length: tuple[float, float] | None = None,
    tool_offset: float | None = None,
    leg_diameter: float = 0.0,
    paired_joint_length: float = 0.0,
) -> GenhexMachine:
    """The parameters of a genhexkins machine from its HAL and INI files.

    Parameters
    ----------
    hal : sequence of (str, str)
        (name, text) of each HAL file, read in order (a later ``setp`` wins, as in halcmd).
    ini : (str, str)
        (name, text) of the INI file.
    joint_max_angle : (float, float)
        Largest angle between each base and platform joint axis and its leg, rad (the axes are
        the legs' directions at the home pose).
    leg_length : (float, float), optional
        Strut length limits, in the machine's linear unit, instead of the INI's ``[JOINT_N]``.
    tool_offset : float, optional
        The tool length, in the machine's unit, when a ``net`` drives
        ``genhexkins.tool-offset`` (refused then without it; refused with it otherwise: the
        HAL files' value is the one genhexkins uses).
    leg_diameter, paired_joint_length : float
        ``limits.leg_diameter`` and ``geometry.paired_joint_length``, in the machine's unit.

    Returns
    -------
    GenhexMachine

    Raises
    ------
    ConfigError
        One line naming the file and line, the pin or the INI key: what was expected and given.
    """
    ini_name, ini_text = ini
    parsed = _ini(ini_text, ini_name)
    kinematics = _ini_value(parsed, "KINS", "KINEMATICS", ini_name).split()
    if not kinematics or kinematics[0] != "genhexkins":
        msg = f"{ini_name}: [KINS] KINEMATICS: expected genhexkins, got {' '.join(kinematics)!r}"
        raise ConfigError(msg)
    unit = _ini_value(parsed, "TRAJ", "LINEAR_UNITS", ini_name)
    if unit.lower() not in LINEAR_UNITS:
        msg = (
            f"{ini_name}: [TRAJ] LINEAR_UNITS: expected one of {', '.join(LINEAR_UNITS)}, "
            f"got {unit!r}"
        )
        raise ConfigError(msg)
    scale = LINEAR_UNITS[unit.lower()]
    pins, driven = _hal_pins(hal)
    sources = [f"units: {ini_name} [TRAJ] LINEAR_UNITS = {unit} ({scale:g} m)"]

    lead = pins.get("screw-lead", (0.0, ""))
    if lead[0] != 0.0:
        msg = (
            f"{lead[1]}: genhexkins.screw-lead {lead[0]:g}: the strut length correction of "
            "non-captive screws is not modelled (the strut lengths would differ); set it to 0"
        )
        raise ConfigError(msg)
    passed: Counter[str] = Counter()
    for pin in pins:
        head = pin.split(".", 1)[0]
        if head in PASSED_OVER:
            passed[f"genhexkins.{head}"] += 1
        elif head not in ("base", "platform", "spindle-offset", "tool-offset", "screw-lead"):
            msg = f"{pins[pin][1]}: genhexkins.{pin}: not a pin this reader knows"
            raise ConfigError(msg)
    for pin in sorted(driven - {"tool-offset"}):
        msg = (
            f"genhexkins.{pin}: driven by a 'net' (its value is set at run time, not in the files)"
        )
        raise ConfigError(msg)
    spindle = pins.get("spindle-offset", (0.0, ""))[0]
    if "tool-offset" in driven:
        if tool_offset is None:
            msg = (
                "genhexkins.tool-offset: driven by a 'net' (motion.tooloffset.z: it changes "
                "with the tool); give the tool length to convert for"
            )
            raise ConfigError(msg)
        tool = tool_offset
        sources.append(f"tool offset: given, {tool:g} {unit}")
    else:
        if tool_offset is not None:
            msg = (
                "tool offset: given, but no 'net' drives genhexkins.tool-offset (the HAL files' "
                f"value, {pins.get('tool-offset', (0.0, ''))[0]:g}, is the one genhexkins uses)"
            )
            raise ConfigError(msg)
        tool = pins.get("tool-offset", (0.0, ""))[0]
    offset = spindle + tool

    home_words = _ini_value(parsed, "TRAJ", "HOME", ini_name).split()
    if len(home_words) < 3:
        msg = f"{ini_name}: [TRAJ] HOME: expected 'x y z a b c', got {' '.join(home_words)!r}"
        raise ConfigError(msg)
    home = [_number(w, f"{ini_name}: [TRAJ] HOME") for w in home_words]
    if any(v != 0.0 for v in home[3:]):
        msg = (
            f"{ini_name}: [TRAJ] HOME: expected a home pose without rotation (a b c = 0), got "
            f"{' '.join(home_words[3:])}"
        )
        raise ConfigError(msg)
    sources.append(f"home position: {ini_name} [TRAJ] HOME")

    if leg_length is None:
        limits = []
        for n in range(6):
            section = f"JOINT_{n}"
            low = _number(_ini_value(parsed, section, "MIN_LIMIT", ini_name), ini_name)
            high = _number(_ini_value(parsed, section, "MAX_LIMIT", ini_name), ini_name)
            if low <= 0.0:
                msg = (
                    f"{ini_name}: [{section}] MIN_LIMIT = {low:g}: expected the shortest strut "
                    "length (> 0), got an open limit; give the strut lengths instead"
                )
                raise ConfigError(msg)
            limits.append((low, high))
        length_min = [low * scale for low, _ in limits]
        length_max = [high * scale for _, high in limits]
        sources.append(f"strut lengths: {ini_name} [JOINT_0..5] MIN_LIMIT, MAX_LIMIT")
    else:
        length_min = [leg_length[0] * scale]
        length_max = [leg_length[1] * scale]
        sources.append(f"strut lengths: given, {leg_length[0]:g} to {leg_length[1]:g} {unit}")

    parameters: dict[str, Any] = {
        "geometry.base_joints": _joints(pins, "base", offset, scale),
        "geometry.platform_joints": _joints(pins, "platform", offset, scale),
        "geometry.home_position": [v * scale for v in home[:3]],
        "limits.leg_length_min": length_min,
        "limits.leg_length_max": length_max,
        "limits.base_joint_max_angle": [joint_max_angle[0]],
        "limits.platform_joint_max_angle": [joint_max_angle[1]],
        "limits.leg_diameter": leg_diameter * scale,
        "geometry.paired_joint_length": paired_joint_length * scale,
    }
    sources.append(
        "joints: genhexkins.base.N and genhexkins.platform.N of "
        + ", ".join(name for name, _ in hal)
        + f", z + {offset:g} {unit} (spindle-offset + tool-offset)"
    )
    return GenhexMachine(parameters, unit, scale, offset, passed, sources)
