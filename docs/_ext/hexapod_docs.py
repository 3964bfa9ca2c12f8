"""Sphinx extension: reference pages generated from the code, so they cannot drift from it.

Directives (each renders reStructuredText built from a table of the package, then parsed):

``hexapod-cli``
    One section per command of ``hexapod-workspace``: its ``--help`` text, from
    :func:`hexapod_workspace.cli.main.build_parser` (the parser the command line runs).
``hexapod-interfaces``
    Every topic, service and action of the node, from
    :data:`hexapod_workspace.logs.interfaces.INTERFACES` (name, kind, type, QoS).
``hexapod-parameters``
    The node's parameters from :func:`hexapod_workspace.ros.parameters.parameter_specs`
    (option ``:group: model`` or ``node``): name, type, default, range, description.
``hexapod-interface-files``
    Every ``.msg``, ``.srv`` and ``.action`` file of ``msg_defs/``, verbatim.

At ``builder-inited`` the tutorial script (``docs/tutorial_two_positions.py``) runs and writes
its figures and its printed output to ``docs/_generated/tutorial/``: every figure of the site
comes from code in the repository.
"""

from __future__ import annotations

import argparse
import os
import re
import runpy
import sys
from contextlib import redirect_stdout
from pathlib import Path
from typing import Any

from docutils import nodes
from docutils.parsers.rst import directives
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

DOCS = Path(__file__).resolve().parents[1]
ROOT = DOCS.parent
GENERATED = DOCS / "_generated"


def _literal(text: str, language: str = "text") -> list[str]:
    body = [f"   {line}" if line else "" for line in text.rstrip("\n").splitlines()]
    return [f".. code-block:: {language}", "", *body, ""]


class _Generated(SphinxDirective):
    """Base: render :meth:`lines` as reStructuredText in place."""

    def lines(self) -> list[str]:
        raise NotImplementedError

    def run(self) -> list[nodes.Node]:
        container = nodes.section() if self.has_titles else nodes.container()
        content = StringList()
        source = f"<{self.name}>"
        for number, line in enumerate(self.lines()):
            content.append(line, source, number)
        nested_parse_with_titles(self.state, content, container)
        return list(container.children) if self.has_titles else [container]

    has_titles = False


class CliDirective(_Generated):
    """Every command's ``--help``, from the parser itself."""

    has_titles = True

    def lines(self) -> list[str]:
        from hexapod_workspace.cli.main import build_parser

        os.environ["COLUMNS"] = "100"  # argparse wraps to the terminal; fix it for the page
        parser = build_parser()
        out = ["``hexapod-workspace``", "-" * 40, "", *_literal(parser.format_help())]
        actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        for name, sub in actions[0].choices.items():
            title = f"``{name}``"
            out += [title, "-" * max(len(title), 10), "", *_literal(sub.format_help())]
        return out


class InterfacesDirective(_Generated):
    """Every topic, service and action of the node, one definition each."""

    def lines(self) -> list[str]:
        from hexapod_workspace.logs.interfaces import INTERFACES

        out: list[str] = []
        for row in INTERFACES:
            name = row.key if row.key.startswith("/") else f"~/{row.key}"
            type_name = row.type
            if row.kind == "action" and "/srv/" in row.type:
                type_name = row.type.replace("/srv/", "/action/")
            where = f" Added by :mod:`{row.extension}`." if row.extension else ""
            if row.condition:
                where += f" Only with {row.condition}."
            out += [
                f"``{name}``",
                f"   {row.kind} · ``{type_name}`` · QoS: {row.qos_text}",
                "",
                f"   {row.summary[0].upper()}{row.summary[1:]}.{where}",
                "",
            ]
        return out


class ParametersDirective(_Generated):
    """The node's parameters (the model's or the node's own), one definition each."""

    option_spec = {"group": directives.unchanged_required}  # noqa: RUF012

    def lines(self) -> list[str]:
        from hexapod_workspace.ros.parameters import MODEL_DESCRIPTIONS, parameter_specs

        group = self.options.get("group", "node")
        out: list[str] = []
        for spec in parameter_specs().values():
            if (spec.name in MODEL_DESCRIPTIONS) != (group == "model"):
                continue
            kind = "any (list of 18 floats or empty)" if spec.dynamic_typing else _kind(spec)
            facts = [kind, f"default ``{_value_text(spec.default)}``"]
            if spec.float_range is not None or spec.int_range is not None:
                low, high = spec.float_range or spec.int_range  # type: ignore[misc]
                facts.append(f"range {low:g} .. {high:g}")
            if spec.constraints:
                facts.append(spec.constraints)
            if spec.read_only:
                facts.append("read-only")
            out += [
                f"``{spec.name}``",
                f"   {', '.join(facts)}",
                "",
                f"   {_escape_bars(spec.description)}",
                "",
            ]
        return out


def _kind(spec: Any) -> str:
    return str(spec.type_.name).lower().replace("_", " ")


def _value_text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list) and len(value) > 6:
        return f"[{', '.join(f'{v:g}' for v in value[:3])}, ... ({len(value)} values)]"
    if isinstance(value, list):
        return "[" + ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return repr(value) if isinstance(value, str) else str(value)


class InterfaceFilesDirective(_Generated):
    """Every interface definition of ``msg_defs/``, verbatim."""

    has_titles = True

    def lines(self) -> list[str]:
        out: list[str] = []
        for folder in ("msg", "srv", "action"):
            for path in sorted((ROOT / "msg_defs" / folder).glob(f"*.{folder}")):
                title = f"``hexapod_workspace_msgs/{folder}/{path.stem}``"
                self.env.note_dependency(str(path))
                out += [title, "~" * len(title), ""]
                out += _literal(path.read_text(encoding="utf-8"))
        return out


_LITERAL = re.compile(r"(``.*?``)")
_UNDERLINE = re.compile(r"^\s*([-=~^])\1{2,}\s*$")


def _escape_bars(line: str) -> str:
    """Escape ``|`` (norms, |x|) outside inline literals: reStructuredText reads |x| as a
    substitution. A line block (``| `` first on the line) is left alone."""
    if line.lstrip().startswith("| "):
        return line
    parts = _LITERAL.split(line)
    return "".join(p if p.startswith("``") else p.replace("|", "\\|") for p in parts)


def _plain_docstring(
    app: Sphinx, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    """Docstrings are written for readers of the code (|x| is a norm): make them valid
    reStructuredText without changing their text. Section underlines shorter than their title
    (titles with combining characters) are lengthened."""
    for index, line in enumerate(lines):
        match = _UNDERLINE.match(line)
        if match and index > 0 and lines[index - 1].strip():
            title = lines[index - 1]
            lines[index] = match.group(1) * max(len(line.strip()), len(title.strip()))
            continue
        lines[index] = _escape_bars(line)


def _resolve_own(app: Sphinx, env: Any, node: Any, contnode: Any) -> Any:
    """Our own short or re-exported names: ``:func:`check``` in a module of the package, or
    ``hexapod_workspace.Manipulator`` (re-exported), resolve to the one documented object of
    that name. A name that exists in the package but is not documented publicly (a private
    helper, a constant outside ``__all__``) is shown as code without a link. Anything else stays
    unresolved, and the nitpicky build fails on it."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    module = node.get("py:module") or ""
    if not (module.startswith("hexapod_workspace") or target.startswith("hexapod_workspace")):
        return None
    domain = env.get_domain("py")
    tail = target.removeprefix("hexapod_workspace.")
    found = [
        name
        for name, _ in domain.objects.items()
        if name.startswith("hexapod_workspace.") and (name == target or name.endswith("." + tail))
    ]
    if len(found) > 1:  # prefer the object of the referring module's package
        local = [name for name in found if name.startswith(module.rsplit(".", 1)[0])]
        found = local if len(local) == 1 else found
    if len(found) == 1:
        return domain.resolve_xref(
            env, node["refdoc"], app.builder, node["reftype"], found[0], node, contnode
        )
    owner = node.get("py:class") or ""
    for candidate in (f"{module}.{owner}.{target}", f"{module}.{target}", target):
        if _exists(candidate.replace("..", ".")):
            return contnode
    return None


def _exists(dotted: str) -> bool:
    """Whether ``dotted`` names a module of the package or an attribute reachable from one."""
    import importlib

    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            if not hasattr(obj, attr):
                if isinstance(obj, type) and _assigned_in_init(obj, attr):
                    return True
                annotations = getattr(obj, "__annotations__", {})
                fields = getattr(obj, "__dataclass_fields__", {})
                return attr in annotations or attr in fields
            obj = getattr(obj, attr)
        return dotted.startswith("hexapod_workspace")
    return False


def _assigned_in_init(cls: type, attr: str) -> bool:
    """Whether ``cls.__init__`` sets the instance attribute ``attr`` (``self.attr = ...``)."""
    import inspect

    try:
        source = inspect.getsource(cls.__init__)
    except (OSError, TypeError):
        return False
    return re.search(rf"self\.{re.escape(attr)}\s*[:=]", source) is not None


def _run_script(script_name: str, folder: str) -> None:
    """Run a docs script with its output folder as argument: its figures and its printed
    output (``output.txt``) go to ``_generated/<folder>/``."""
    out_dir = GENERATED / folder
    out_dir.mkdir(parents=True, exist_ok=True)
    script = DOCS / script_name
    argv = sys.argv
    try:
        sys.argv = [str(script), str(out_dir)]
        with (
            (out_dir / "output.txt").open("w", encoding="utf-8") as handle,
            redirect_stdout(handle),
        ):
            runpy.run_path(str(script), run_name="__main__")
    finally:
        sys.argv = argv


def _run_tutorial(app: Sphinx) -> None:
    """Run the tutorial script: figures and printed output into _generated/tutorial/."""
    _run_script("tutorial_two_positions.py", "tutorial")


def _run_scene(app: Sphinx) -> None:
    """Run docs/scene_figure.py: the collision page's scene figure into _generated/scene/."""
    _run_script("scene_figure.py", "scene")


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("hexapod-cli", CliDirective)
    app.add_directive("hexapod-interfaces", InterfacesDirective)
    app.add_directive("hexapod-parameters", ParametersDirective)
    app.add_directive("hexapod-interface-files", InterfaceFilesDirective)
    app.connect("builder-inited", _run_tutorial)
    app.connect("builder-inited", _run_scene)
    app.connect("autodoc-process-docstring", _plain_docstring)
    app.connect("missing-reference", _resolve_own)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
