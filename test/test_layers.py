"""The import boundary is the architecture: every module is parsed, lazy imports included.

Layers, inner to outer (CONTRIBUTING.md, *Package layout*): ``core`` (numpy, numba, the standard
library; PyYAML only to read a parameters file) -> ``logs`` (adds mcap, rosbags) -> ``atlas``
(adds dask, xarray, zarr) -> the front ends ``cli`` (adds matplotlib) and ``ros`` (the only
place for rclpy and generated message modules). Nothing reaches back inward-to-outward, and no
module imports itself through a cycle. Every import counts: at module level, inside a function
(a lazy import) and inside ``if TYPE_CHECKING:`` (an annotation still names the module it needs,
so a cycle through annotations is a cycle of the design)."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE_DIR = Path(__file__).resolve().parents[1] / "hexapod_workspace"
PACKAGE = "hexapod_workspace"

#: Third-party roots every layer may use.
COMMON = {"numpy"}
#: Third-party roots each layer adds (the layers it may import from are in INWARD).
THIRD_PARTY = {
    "core": {"numba", "yaml"},
    "logs": {"mcap", "mcap_ros2", "rosbags", "yaml"},  # yaml: rosbag2 metadata.yaml
    "atlas": {"dask", "distributed", "xarray", "zarr", "numcodecs"},
    "cli": {"matplotlib", "mpl_toolkits"},
    "ros": {
        "rclpy",
        "rosidl_parser",
        "rosidl_runtime_py",
        "builtin_interfaces",
        "std_msgs",
        "std_srvs",
        "geometry_msgs",
        "sensor_msgs",
        "diagnostic_msgs",
        "visualization_msgs",
        "action_msgs",
        "rcl_interfaces",
        "nav_msgs",
        "hexapod_workspace_msgs",
    },
}
#: Package layers each layer may import from (top-level modules errors/_resources: everyone).
INWARD = {
    "top": {"core", "top"},  # hexapod_workspace/__init__.py etc.; atlas lazily, see below
    "core": {"core", "top"},
    "logs": {"core", "logs", "top"},
    "atlas": {"core", "logs", "atlas", "top"},
    "cli": {"core", "logs", "atlas", "cli", "top"},
    "ros": {"core", "logs", "atlas", "ros", "top"},
}
#: Edges allowed across front ends, lazily and for one purpose each.
ALLOWED_EXTRA = {
    # ``replay --publish`` hands a log to the ROS layer (rclpy is imported there, not here).
    ("hexapod_workspace.cli.replay", "hexapod_workspace.ros.republish"),
}
#: Top-level module names of the standard library.
STDLIB = set(sys.stdlib_module_names) | {"__future__"}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE_DIR.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def layer_of(module: str) -> str:
    if module == f"{PACKAGE}.__main__":
        return "cli"  # ``python -m hexapod_workspace`` is the command line
    parts = module.split(".")
    if len(parts) > 1 and (PACKAGE_DIR / parts[1]).is_dir():
        return parts[1]
    return "top"


def imports_of(path: Path, module: str | None = None) -> list[tuple[str, int]]:
    """Absolute names imported anywhere in a module (functions too), with their line."""
    module = module_name(path) if module is None else module
    is_package = path.name == "__init__.py"
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found: list[tuple[str, int]] = []

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.Import):
            found.extend((alias.name, node.lineno) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".")
                base = base if is_package else base[:-1]
                base = base[: len(base) - (node.level - 1)]
                prefix = ".".join(base + ([node.module] if node.module else []))
            else:
                prefix = node.module or ""
            for alias in node.names:
                candidate = f"{prefix}.{alias.name}"
                # "from pkg import submodule" names the submodule; otherwise the module itself.
                if prefix.startswith(PACKAGE) and _module_path(candidate) is not None:
                    found.append((candidate, node.lineno))
                else:
                    found.append((prefix, node.lineno))
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def _module_path(name: str) -> Path | None:
    relative = Path(*name.split(".")[1:]) if "." in name else Path()
    for candidate in (
        PACKAGE_DIR / relative.with_suffix(".py"),
        PACKAGE_DIR / relative / "__init__.py",
    ):
        if relative != Path() and candidate.is_file():
            return candidate
    return PACKAGE_DIR / "__init__.py" if name == PACKAGE else None


MODULES = sorted(PACKAGE_DIR.rglob("*.py"))
GRAPH = {module_name(path): imports_of(path) for path in MODULES}


def test_every_module_is_parsed() -> None:
    layers = {layer_of(name) for name in GRAPH}
    assert {"core", "logs", "cli", "ros", "top"} <= layers
    assert len(GRAPH) >= 30


@pytest.mark.parametrize("module", sorted(GRAPH))
def test_imports_respect_the_layers(module: str) -> None:
    layer = layer_of(module)
    problems = []
    for name, line in GRAPH[module]:
        root = name.split(".")[0]
        if root == PACKAGE:
            target = layer_of(name)
            if (module, name) in ALLOWED_EXTRA:
                continue
            if module == PACKAGE and target == "atlas":
                continue  # the public API re-exports workspace_atlas lazily (optional extra)
            if target not in INWARD[layer]:
                problems.append(f"line {line}: {layer} layer imports {name} ({target} layer)")
        elif root in STDLIB or root in COMMON:
            continue
        else:
            allowed = set().union(*(THIRD_PARTY.get(inner, set()) for inner in INWARD[layer]))
            if root not in allowed:
                problems.append(f"line {line}: {layer} layer imports third-party {name}")
    assert not problems, f"{module}:\n" + "\n".join(problems)


#: Sub-packages of the core, inner to outer (CONTRIBUTING.md, *Package layout*): each imports
#: only from itself and the ones before it.
CORE_LAYERS = (
    "base",
    "model",
    "constraints",
    "kernels",
    "evaluation",
    "workspaces",
    "motions",
    "cell",
)


def core_layer_of(module: str) -> str | None:
    """The core sub-package of a module (None outside the core or for the core package)."""
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "core" else None


def test_every_core_module_sits_in_a_layer() -> None:
    loose = sorted(
        module
        for module in GRAPH
        if layer_of(module) == "core" and module != f"{PACKAGE}.core"
        if core_layer_of(module) not in CORE_LAYERS
    )
    assert not loose, f"core modules outside the layers {CORE_LAYERS}: {loose}"


@pytest.mark.parametrize("module", sorted(m for m in GRAPH if core_layer_of(m) in CORE_LAYERS))
def test_core_layers_import_inward(module: str) -> None:
    layer = core_layer_of(module)
    assert layer is not None
    rank = CORE_LAYERS.index(layer)
    problems = []
    for name, line in GRAPH[module]:
        if name == f"{PACKAGE}.core":
            problems.append(f"line {line}: imports the core package itself")
        target = core_layer_of(name)
        if target in CORE_LAYERS and CORE_LAYERS.index(target) > rank:
            problems.append(f"line {line}: core.{layer} imports {name} (core.{target}, outer)")
    assert not problems, f"{module}:\n" + "\n".join(problems)


def test_core_reads_yaml_only_for_a_parameters_file() -> None:
    users = {
        module
        for module, names in GRAPH.items()
        if layer_of(module) == "core" and any(n.split(".")[0] == "yaml" for n, _ in names)
    }
    assert users <= {"hexapod_workspace.core.base.params"}, users


def test_no_import_cycles() -> None:
    edges = {
        module: {name for name, _ in names if name in GRAPH and name != module}
        for module, names in GRAPH.items()
    }
    # A package's __init__ re-exporting its own modules is not a cycle through them.
    for module, targets in edges.items():
        targets.difference_update(t for t in list(targets) if t.startswith(module + "."))
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []

    def strongly_connect(node: str) -> None:  # Tarjan
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in edges[node]:
            if target not in index:
                strongly_connect(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for node in sorted(edges):
        if node not in index:
            strongly_connect(node)
    assert not cycles, f"import cycles: {cycles}"


def test_the_checker_sees_lazy_and_relative_imports(tmp_path: Path) -> None:
    # The parser itself, on a module written for the purpose: an import inside a function,
    # a relative import two levels up, and an annotation-only import, which counts too.
    source = (
        "from __future__ import annotations\n"
        "from typing import TYPE_CHECKING\n"
        "from ..logs import writer\n"
        "if TYPE_CHECKING:\n"
        "    import rclpy\n"
        "def later():\n"
        "    import matplotlib.pyplot\n"
    )
    probe = tmp_path / "probe.py"
    probe.write_text(source, encoding="utf-8")
    names = [name for name, _ in imports_of(probe, "hexapod_workspace.core.probe")]
    assert "hexapod_workspace.logs.writer" in names
    assert "matplotlib.pyplot" in names
    assert "rclpy" in names


def test_core_imports_without_ros_or_the_outer_layers() -> None:
    # At run time too: block every outer dependency, then import the public API.
    code = (
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        root = name.split('.')[0]\n"
        "        if root in {'rclpy', 'rosidl_runtime_py', 'sensor_msgs', 'std_msgs', 'yaml',\n"
        "                    'matplotlib', 'mcap', 'rosbags', 'hexapod_workspace_msgs',\n"
        "                    'dask', 'distributed', 'xarray', 'zarr'}:\n"
        "            raise ImportError('blocked: ' + name)\n"
        "sys.meta_path.insert(0, Block())\n"
        "import hexapod_workspace\n"
        "from hexapod_workspace import Manipulator, check, projected_workspace\n"
        "loaded = sorted({m.split('.')[0] for m in sys.modules})\n"
        "print(' '.join(loaded))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert "rclpy" not in done.stdout.split()


#: The longest a module may be (lines): past it, a module holds more than one concept.
MODULE_LINES_MAX = 800


def test_no_module_is_longer_than_the_limit() -> None:
    lengths = {
        str(path.relative_to(PACKAGE_DIR)): len(path.read_text(encoding="utf-8").splitlines())
        for path in sorted(PACKAGE_DIR.rglob("*.py"))
    }
    assert len(lengths) > 100, "the package's modules were not found"
    longer = {name: count for name, count in lengths.items() if count > MODULE_LINES_MAX}
    assert not longer, f"modules over {MODULE_LINES_MAX} lines: {longer}"
