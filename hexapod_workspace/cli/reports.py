"""Everything the CLI prints: tables and JSON documents of results, logs and the demo.

One module for the rendering, so that every command speaks the same units and words: angles in
degrees (JSON keys carry the unit, ``theta_deg``), lengths in m (tables: mm for margins), and
margins always called margins (signed distance to the limit: >= 0 holds, < 0 violated).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from ..core.constraints.table import CONSTRAINTS, SINGULARITY
from ..core.evaluation.check import CheckResult
from ..core.evaluation.loads import LoadRows
from ..core.model.manipulator import Manipulator
from ..core.workspaces.orientation import OrientationWorkspace, TorsionRange
from ..core.workspaces.projected import ProjectedWorkspace

__all__ = [
    "check_json",
    "check_table",
    "demo_table",
    "orientation_json",
    "orientation_text",
    "projected_json",
    "projected_text",
    "torsion_range_json",
    "torsion_range_text",
    "unreachable_json",
    "write_json",
]


def _degrees(values: Any) -> Any:
    """Radians to degrees as plain Python floats (lists for arrays)."""
    converted = np.degrees(values)
    return converted.tolist() if isinstance(converted, np.ndarray) else float(converted)


def _optional_degrees(values: NDArray[np.float64] | None) -> list[float] | None:
    """Radians to a list of degrees; None stays None."""
    return None if values is None else _degrees(values)


def _triple(values: NDArray[np.float64] | None) -> str:
    """A T&T pose (rad) as ``(φ, θ, ψ)`` in degrees, 4 decimals; ``(unknown)`` for None."""
    if values is None:
        return "(unknown)"
    return "(" + ", ".join(f"{v:.4f}" for v in np.degrees(values)) + ")"


def _number(value: float, width: int, decimals: int) -> str:
    """A number in a fixed-width column: fixed-point when it fits, else scientific."""
    text = f"{value:{width}.{decimals}f}"
    return (
        text if len(text) <= width else f"{value:{width}.{max(decimals, 3)}e}"[:width].rjust(width)
    )


def write_json(document: Any, out: IO[str]) -> None:
    """One JSON document on a line (NaN and infinities refused: callers map them to null)."""
    out.write(json.dumps(document, allow_nan=False) + "\n")


# ---------------------------------------------------------------------------- check
def reported_names(result: CheckResult) -> tuple[str, ...]:
    """The constraints a report lists: those of the model (its architecture's rows, ``collision``
    only where a scene is declared), in table order."""
    return tuple(result.margins)


def _write_rows(out: IO[str], template: str, columns: Sequence[Sequence[Any]], sep: str) -> None:
    """Write ``template % row`` for the rows of ``columns`` joined by ``sep``, in blocks."""
    block = 65536
    count = len(columns[0])
    for start in range(0, count, block):
        rows = zip(*(column[start : start + block] for column in columns), strict=True)
        text = sep.join([template % row for row in rows])
        out.write(text if start + block >= count else text + sep)


def _verdicts(
    result: CheckResult, loads: LoadRows | None
) -> tuple[NDArray[np.bool_], list[list[str]]]:
    """Per pose, whether every row holds and the names of the violated ones: the geometric
    rows, then the loads' rows the parameters file sets."""
    if loads is None:
        return result.reachable, result.violated
    violated = [a + b if b else a for a, b in zip(result.violated, loads.violated, strict=True)]
    return result.reachable & loads.holds, violated


def _load_cells(loads: LoadRows, template: str) -> list[str]:
    """Per pose, the margins of the loads' rows formatted into ``template`` (null: -inf)."""

    def number(value: float) -> str:
        return f"{value:.12g}" if math.isfinite(value) else "null"

    columns = [[number(v) for v in margin.tolist()] for margin in loads.margins.values()]
    if "actuator_force" in loads.margins:
        columns.append([str(k) for k in loads.limiting_actuator.tolist()])
    return [template % row for row in zip(*columns, strict=True)]


def check_json(
    result: CheckResult,
    out: IO[str],
    degrees: NDArray[np.float64],
    given: tuple[list[str], NDArray[np.float64]] | None = None,
    loads: LoadRows | None = None,
) -> None:
    """Write ``{"position": [...], "poses": [...]}`` for a check result, streaming.

    One object per pose in input order with ``phi_deg, theta_deg, psi_deg`` (as the user gave
    them, or converted from the convention given), ``reachable, violated, margins{...}``
    (signed, SI: m, rad; null when a check is disabled) and ``limiting_leg``; a pose given in
    another convention than T&T starts with its own numbers (``u_deg, v_deg, w_deg``,
    ``qx, qy, qz, qw``). Numbers carry 12 significant digits.

    Parameters
    ----------
    result : CheckResult
    out : text stream
    degrees : ndarray, shape (N, 3)
        The poses in T&T angles, degrees (as the user gave them for T&T).
    given : (list of str, ndarray of shape (N, k)), optional
        The JSON keys and the values of the convention the poses were given in, when not T&T.
    loads : LoadRows, optional
        The loads' rows the parameters file sets: ``"loads": {"actuator_force": …,
        "limiting_actuator": …, "deflection": …, "accuracy": …}`` (the rows set; N or N·m, m;
        null for −inf at a singular pose) after the margins, and ``reachable`` and
        ``violated`` count them.
    """
    reachable, violated_names = _verdicts(result, loads)
    texts: dict[tuple[str, ...], str] = {}
    violated = [texts.setdefault(tuple(v), json.dumps(v)) for v in violated_names]
    names = reported_names(result)
    finite = {name: bool(np.all(np.isfinite(result.margins[name]))) for name in names}
    margins = [
        result.margins[name].tolist()
        if finite[name]
        else ["null" if not math.isfinite(v) else repr(v) for v in result.margins[name].tolist()]
        for name in names
    ]
    # 12 significant digits: exact to 1e-12 relative, and twice as fast to format as repr().
    margin_fields = ", ".join(f'"{name}": {"%.12g" if finite[name] else "%s"}' for name in names)
    pair = ', "collision_pair": %s' if result.collision_pairs else ""
    load_field = ', "loads": %s' if loads is not None else ""
    given_fields = "".join(f'"{key}": %.12g, ' for key in given[0]) if given else ""
    template = (
        f'{{{given_fields}"phi_deg": %.12g, "theta_deg": %.12g, "psi_deg": %.12g, '
        '"reachable": %s, "violated": %s, '
        f'"margins": {{{margin_fields}}}, "limiting_leg": %d{load_field}{pair}}}'
    )
    columns = [
        *(np.asarray(given[1]).T.tolist() if given else []),
        *np.asarray(degrees).T.tolist(),
        np.where(reachable, "true", "false").tolist(),
        violated,
        *margins,
        result.limiting_leg.tolist(),
    ]
    if loads is not None:
        fields = [f'"{name}": %s' for name in loads.margins]
        if "actuator_force" in loads.margins:
            fields.append('"limiting_actuator": %s')
        columns.append(_load_cells(loads, "{" + ", ".join(fields) + "}"))
    if result.collision_pairs:
        quoted = {name: json.dumps(name) for name in ("", *result.collision_pairs)}
        columns.append([quoted[name] for name in result.collision_pair])
    out.write(f'{{"position": {json.dumps(result.position.tolist())}, "poses": [\n')
    _write_rows(out, template, columns, ",\n")
    out.write("]}\n")


def check_table(
    result: CheckResult,
    out: IO[str],
    degrees: NDArray[np.float64],
    manipulator: Manipulator,
    given: tuple[list[str], NDArray[np.float64]] | None = None,
    loads: LoadRows | None = None,
) -> None:
    """Write a readable table: angles in degrees, margins (distance to each limit) in mm and
    degrees, the limiting leg and the violated constraints (and, with a force limit, the actuator
    that limits the force margin).

    Parameters are those of :func:`check_json`, and the model the result is of (the unit of a
    row can depend on it: the ``actuator`` stroke in mm for slides, deg for cranks). Poses given
    in another convention than T&T get their own columns first (``u``, ``v``, ``w`` [deg],
    ``qx`` ... [1]), then the T&T angles they denote. The loads' rows the file sets follow the
    geometric ones (``force`` in N or N·m, ``deflection`` and ``accuracy`` in mm; -inf at a
    singular pose) and count in ``reachable`` and ``violated``.
    """
    reachable, violated = _verdicts(result, loads)
    x, y, z = result.position
    out.write(f"position: ({x:.4f}, {y:.4f}, {z:.4f}) m\n")
    # The singularity margin is a column only where it was evaluated (enforced by
    # limits.singularity_min > 0 or asked for with --singularity); otherwise it is +inf. The
    # collision margin is one only where the model declares a scene.
    reported = reported_names(result)
    shown = [
        row
        for row in CONSTRAINTS
        if row.name in reported
        and (
            row is not CONSTRAINTS[SINGULARITY] or not np.all(np.isposinf(result.margins[row.name]))
        )
    ]
    report = [row.report(manipulator) for row in shown]  # (unit, factor), read once
    columns_shown = [row.column for row in shown]
    load_report: list[tuple[str, float]] = []
    if loads is not None:
        for name in loads.margins:
            columns_shown.append("force" if name == "actuator_force" else name)
            load_report.append((loads.force_unit, 1.0) if name == "actuator_force" else ("mm", 1e3))
    names = " ".join(f"{column:>11}" for column in columns_shown)
    units = " ".join(f"{'[' + unit + ']':>11}" for unit, _ in [*report, *load_report])
    given_names, given_units, given_format, given_columns = "", "", "", []
    if given is not None:
        keys, values = given
        angular = keys[0].endswith("_deg")
        given_names = "".join(f"{key.removesuffix('_deg'):>9} " for key in keys)
        given_units = "".join(f"{'[deg]' if angular else '[1]':>9} " for _ in keys)
        given_format = ("%9.3f " if angular else "%9.6f ") * len(keys)
        given_columns = np.asarray(values).T.tolist()
    by_actuator = loads is not None and "actuator_force" in loads.margins
    force_name, force_unit = (f"  {'force':>8}", f"  {'actuator':>8}") if by_actuator else ("", "")
    header = (
        f"{' ' * len(given_names)}"
        f"{'':>9} {'':>9} {'':>9}  {'':<9}  {'margin to each limit (>= 0 holds, < 0 violated)'}",
        f"{given_names}{'phi':>9} {'theta':>9} {'psi':>9}  {'reachable':<9}  {names}  "
        f"{'limiting':>8}{force_name}  violated"
        + ("  closest pair" if result.collision_pairs else ""),
        f"{given_units}{'[deg]':>9} {'[deg]':>9} {'[deg]':>9}  {'':<9}  {units}  {'leg':>8}"
        f"{force_unit}",
    )
    out.write("".join(line.rstrip() + "\n" for line in header))
    degrees = np.asarray(degrees)
    wide = bool(np.any(np.abs(degrees) >= 1e5))
    angle_columns = (
        [[_number(v, 9, 3) for v in column] for column in degrees.T.tolist()]
        if wide
        else degrees.T.tolist()
    )
    angle_format = given_format + ("%s %s %s" if wide else "%9.3f %9.3f %9.3f")
    columns = [
        *given_columns,
        *angle_columns,
        np.where(reachable, "yes", "NO").tolist(),
        *(
            (result.margins[row.name] * factor).tolist()
            for row, (_, factor) in zip(shown, report, strict=True)
        ),
        *(
            (margin * factor).tolist()
            for margin, (_, factor) in zip(
                loads.margins.values() if loads is not None else (), load_report, strict=True
            )
        ),
        result.limiting_leg.tolist(),
        *([loads.limiting_actuator.tolist()] if loads is not None and by_actuator else []),
        [",".join(v) or "-" for v in violated],
    ]
    count = len(columns_shown)
    template = angle_format + "  %-9s  " + " ".join(["%11.3f"] * count) + "  %8d"
    template += "  %8d  %s" if by_actuator else "  %s"
    if result.collision_pairs:
        template += "  %s"
        columns.append(result.collision_pair)
    _write_rows(out, template, columns, "\n")
    held = int(np.count_nonzero(reachable))
    what = "reachable and within the loads' limits" if loads is not None else "reachable"
    out.write(f"\n{held}/{len(result)} poses {what}\n")


# ---------------------------------------------------------------------------- workspaces
def unreachable_json(position: Any, reason: str) -> dict[str, Any]:
    """The JSON document of an empty workspace (reference orientation unreachable)."""
    return {
        "position": np.asarray(position, dtype=float).tolist(),
        "reference_reachable": False,
        "reason": reason,
    }


def projected_json(workspace: ProjectedWorkspace) -> dict[str, Any]:
    """The JSON document of a projected workspace (angles in degrees)."""
    document: dict[str, Any] = {
        "method": workspace.method,
        "position": workspace.position.tolist(),
        "reference_reachable": True,
        "phi_deg": _degrees(workspace.phi),
        "theta_deg": _degrees(workspace.theta),
        "psi_deg": _degrees(workspace.psi),
        "limiting": workspace.limiting,
        "tilt_min_deg": _degrees(workspace.tilt_min),
        "tilt_max_deg": _degrees(workspace.tilt_max),
        "solid_angle_sr": workspace.solid_angle,
        "tolerance_deg": _degrees(workspace.tolerance),
        "elapsed_s": workspace.elapsed,
    }
    if workspace.gap is not None:
        document["torsion_zero_gap_deg"] = _degrees(workspace.gap)
        document["torsion_zero_gap_max_deg"] = _degrees(float(workspace.gap.max()))
        document["torsion_zero_gap_mean_deg"] = _degrees(float(workspace.gap.mean()))
    return document


#: Rows of the projected table (every k-th azimuth); ``--json`` gives all of them.
PROJECTED_TABLE_ROWS = 12


def projected_text(workspace: ProjectedWorkspace, out: IO[str]) -> None:
    """A readable summary of a projected workspace and a thinned table of its boundary."""
    x, y, z = workspace.position
    out.write(
        f"projected orientation workspace ({workspace.method}) at ({x:.4f}, {y:.4f}, {z:.4f}) m\n"
        f"  azimuths: {workspace.n_phi} rays from theta = 0, "
        f"tolerance {math.degrees(workspace.tolerance):.2e} deg, "
        f"{workspace.elapsed * 1e3:.1f} ms\n"
        f"  tilt range: {math.degrees(workspace.tilt_min):.4f} .. "
        f"{math.degrees(workspace.tilt_max):.4f} deg (least and largest boundary tilt over "
        "the azimuths)\n"
        f"  solid angle of attainable directions: {workspace.solid_angle:.5f} sr\n"
    )
    if workspace.gap is not None:
        worst = int(np.argmax(workspace.gap))
        out.write(
            f"  torsion_zero lies inside by up to {math.degrees(workspace.gap[worst]):.4f} deg "
            f"(phi {math.degrees(workspace.phi[worst]):.1f} deg, "
            f"mean {math.degrees(float(workspace.gap.mean())):.4f} deg)\n"
        )
    step = max(1, math.ceil(workspace.n_phi / PROJECTED_TABLE_ROWS))
    shown = range(0, workspace.n_phi, step)
    if step > 1:
        out.write(
            f"  boundary, every {step}th of the {workspace.n_phi} azimuths "
            f"({len(shown)} rows; --json gives all):\n"
        )
    else:
        out.write(f"  boundary ({workspace.n_phi} azimuths):\n")
    out.write(f"  {'phi [deg]':>10} {'theta [deg]':>12} {'psi [deg]':>10}  limiting\n")
    for k in shown:
        out.write(
            f"  {_number(math.degrees(workspace.phi[k]), 10, 2)} "
            f"{_number(math.degrees(workspace.theta[k]), 12, 4)} "
            f"{_number(math.degrees(workspace.psi[k]), 10, 3)}  {workspace.limiting[k] or '-'}\n"
        )


def orientation_json(workspace: OrientationWorkspace) -> dict[str, Any]:
    """The JSON document of a 3-D orientation workspace (angles in degrees)."""
    return {
        "position": workspace.position.tolist(),
        "reference_reachable": True,
        "psi_min_deg": _degrees(workspace.psi_min),
        "psi_max_deg": _degrees(workspace.psi_max),
        # the reachable poses [φ, θ, ψ] that attain the torsion extremes (``check`` them)
        "psi_min_witness_deg": _optional_degrees(workspace.psi_min_witness),
        "psi_max_witness_deg": _optional_degrees(workspace.psi_max_witness),
        "volume": workspace.volume,
        "volume_unit": "rad^3",
        "n_rays": workspace.n_rays,
        "psi_step_deg": _degrees(workspace.psi_step),
        "tolerance_deg": _degrees(workspace.tolerance),
        "slices": [
            {
                "psi_deg": _degrees(piece.psi),
                "center_deg": _degrees(piece.center),
                "phi_deg": _degrees(piece.phi),
                "theta_deg": _degrees(piece.theta),
            }
            for piece in workspace.slices
        ],
        "elapsed_s": workspace.elapsed,
    }


def orientation_text(workspace: OrientationWorkspace, out: IO[str]) -> None:
    """A readable summary of an orientation workspace, saying what each number is."""
    x, y, z = workspace.position
    areas = [piece.area() for piece in workspace.slices]
    middle = min(range(len(workspace.slices)), key=lambda k: abs(workspace.slices[k].psi))
    zero = workspace.slices[middle]
    # rounded as printed, + 0.0: a centre 1e-17 below the axis prints 0.000, not -0.000
    cx, cy = (round(float(v), 3) + 0.0 for v in np.degrees(zero.center))
    out.write(
        f"orientation workspace at ({x:.4f}, {y:.4f}, {z:.4f}) m\n"
        f"  {len(workspace.slices)} slices of {workspace.n_rays} rays, "
        f"step {math.degrees(workspace.psi_step):g} deg, "
        f"tolerance {math.degrees(workspace.tolerance):.2e} deg, {workspace.elapsed:.2f} s\n"
        f"  torsion range: {math.degrees(workspace.psi_min):.4f} .. "
        f"{math.degrees(workspace.psi_max):.4f} deg\n"
        f"    psi_min reached at (phi, theta, psi) = {_triple(workspace.psi_min_witness)} deg\n"
        f"    psi_max reached at (phi, theta, psi) = {_triple(workspace.psi_max_witness)} deg\n"
        f"  volume (cylindrical coordinates): {workspace.volume:.5f} rad^3\n"
        f"  psi = {math.degrees(zero.psi):g} slice: area {areas[middle]:.5f} rad^2, tilt "
        f"{math.degrees(zero.theta.min()):.3f} .. {math.degrees(zero.theta.max()):.3f} deg over "
        f"its {zero.phi.size} boundary points\n"
        f"    (rays from the slice centre ({cx:.3f}, {cy:.3f}) deg; `projected` samples the same "
        "boundary along\n"
        "    azimuths from theta = 0, so its tilt range differs by the sampling)\n"
    )


def torsion_range_json(found: TorsionRange, direction_deg: Sequence[float]) -> dict[str, Any]:
    """The JSON document of a torsion range: the direction as typed, intervals in degrees."""
    return {
        "direction_deg": [float(v) for v in direction_deg],
        "intervals_deg": np.degrees(found.intervals).tolist(),
    }


def torsion_range_text(found: TorsionRange, direction_deg: Sequence[float], out: IO[str]) -> None:
    """A readable list of the feasible torsion intervals."""
    x, y, z = found.position
    phi, theta = direction_deg
    out.write(
        f"torsion range for direction phi {phi:g} deg, theta {theta:g} deg "
        f"at ({x:.4f}, {y:.4f}, {z:.4f}) m\n"
    )
    if not len(found.intervals):
        out.write("  no feasible torsion\n")
    for low, high in np.degrees(found.intervals).tolist():
        out.write(f"  psi in [{low:.4f}, {high:.4f}] deg\n")


def _deg(value: float) -> float | None:
    return None if not math.isfinite(value) else math.degrees(value)


def demo_table(rows: list[dict[str, Any]], log_name: str) -> str:
    lines = [
        "| case | position [m] | tilt θ (ψ = 0) [deg] | tilt θ (exact) [deg] "
        "| max gap [deg] | ψ range [deg] | volume [rad³] | time tz / exact / 3-D [s] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        position = "({:g}, {:g}, {:g})".format(*row["position"])
        if "error" in row:
            lines.append(f"| {row['case']} | {position} | {row['error']} | | | | | |")
            continue
        elapsed = row["elapsed_s"]
        lines.append(
            f"| {row['case']} | {position} "
            f"| {row['tilt_min_deg']:.2f} – {row['tilt_max_deg']:.2f} "
            f"| {row['exact_tilt_min_deg']:.2f} – {row['exact_tilt_max_deg']:.2f} "
            f"| {row['torsion_zero_gap_max_deg']:.2f} "
            f"| {row['psi_min_deg']:.2f} – {row['psi_max_deg']:.2f} "
            f"| {row['volume_rad3']:.4f} "
            f"| {elapsed['torsion_zero']:.3f} / {elapsed['exact']:.3f} / "
            f"{elapsed['orientation']:.2f} |"
        )
    lines.append("")
    lines.append(f"Log of every result: `{log_name}` (`hexapod-workspace replay {log_name}`).")
    return "\n".join(lines) + "\n"
