"""numba set-up shared by every compiled kernel of the core: the cache directory, the decorators
and the compile-time switches.

**The cache.** numba keys a cached kernel on the source file of its entry point only (its
modification time and size), so a changed helper in another module (a margin kernel compiled into a
search kernel) would be loaded stale from the cache. The kernels are therefore cached in a
directory named by a hash of the *contents* of every module whose code ends up in a kernel
(:data:`KERNEL_SOURCES`): a change to any of them selects a new, empty directory. This uses numba's
public configuration only (``NUMBA_CACHE_DIR``, set before numba is imported, or
``numba.config.CACHE_DIR`` when it already was). The directory lies next to the core modules
(``__pycache__/numba-<hash>``) when that is writable, otherwise in the user cache directory
(``$XDG_CACHE_HOME/hexapod_workspace/numba-<hash>``, default ``~/.cache/...``), so a read-only
install (colcon install space, system site-packages) compiles once per user. A directory given in
``NUMBA_CACHE_DIR`` is used as the parent of ``numba-<hash>``. The setting this module makes is
inherited by child processes (numba reads it from the environment), together with
``HEXAPOD_WORKSPACE_CACHE_OWNER``, the core folder that made it and the value: a child of the same
tree shares the directory, a child running another copy of the package (the colcon install space
started from a test of the source tree) ignores it and uses its own, which is where its kernels
were compiled (numba keys a cached kernel by the full path of its source file, so the other tree's
directory holds none of them). This module must be imported before numba (every kernel module
imports it first). Other numba users in the same process share the directory (numba has one cache
setting per process).

**The switches.** A kernel is compiled for one *variant* of the model: fixed or moving base
joints (``moving``), slides or cranks (``cranks``), a collision scene (``collide``), an evaluated
singularity margin (``singular``). Each switch is ``None`` (off) or ``1`` (on) and is passed
down to every helper as an argument: numba removes a branch on ``switch is None`` or ``switch is
not None`` where the argument's type is ``none`` before it types the function (its dead-branch
pruning), so a 6-UPS model without a scene compiles none of the moving-base, collision or
singularity stages. With a switch on, the model's own flag still decides at run time (the ray
search evaluates a copy of the model with its scene off). :func:`switches` reads them off the
packed model; :mod:`hexapod_workspace.core.kernels` builds one set of entry points per variant.
:func:`compile_notice` says once when a kernel of the core really compiles.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TypeVar

__all__ = [
    "CACHE_DIRECTORY",
    "KERNEL_SOURCES",
    "OFF",
    "ON",
    "Collide",
    "Switches",
    "compile_notice",
    "entry",
    "entry_points",
    "first_class",
    "helper",
    "inline",
    "jit",
]

#: The core package folder: the owner of the in-tree cache and the root of KERNEL_SOURCES.
_CORE = Path(__file__).resolve().parent.parent

#: The modules whose code ends up in the compiled kernels (relative to the core package). A test
#: checks that every module of the package that defines a kernel is listed.
KERNEL_SOURCES: tuple[Path, ...] = tuple(
    _CORE / name
    for name in (
        "base/jit.py",
        "constraints/table.py",
        "kernels/layout.py",
        "kernels/scene_layout.py",
        "kernels/collision.py",
        "model/collision/distance.py",
        "model/collision/scene.py",
        "kernels/trig.py",
        "kernels/singularity.py",
        "kernels/segments.py",
        "kernels/moving_base.py",
        "kernels/pose.py",
        "kernels/blocks.py",
        "kernels/margins.py",
        "kernels/steps.py",
        "kernels/lazy_collision.py",
        "kernels/searches.py",
        "kernels/planner.py",
    )
)


def _sources_hash() -> str:
    """The first 16 hex digits of the SHA-256 of every kernel source, in order."""
    digest = hashlib.sha256()
    for source in KERNEL_SOURCES:
        digest.update(source.name.encode())
        digest.update(source.read_bytes())
    return digest.hexdigest()[:16]


#: Name of this version's cache directory.
CACHE_NAME = f"numba-{_sources_hash()}"


#: ``<core folder><os.pathsep><directory>``: the copy of the package whose set-up put
#: ``NUMBA_CACHE_DIR`` in the environment, and the value it put there (a value set after that,
#: by the user, is the user's and is kept).
_OWNER_VARIABLE = "HEXAPOD_WORKSPACE_CACHE_OWNER"


def _writable(directory: Path) -> bool:
    """Whether files can be created in ``directory`` (created if missing)."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            pass
    except OSError:
        return False
    return True


def _prune(parent: Path) -> None:
    """Remove the cache directories of earlier kernel sources in ``parent`` (the in-tree
    cache belongs to this source tree alone; best effort)."""
    for stale in parent.glob("numba-*"):
        if stale.name != CACHE_NAME and stale.is_dir():
            shutil.rmtree(stale, ignore_errors=True)


def _cache_directory() -> Path | None:
    """Where numba caches the kernels (None: nowhere writable, no cache)."""
    configured = os.environ.get("NUMBA_CACHE_DIR")
    owner, _, directory = os.environ.get(_OWNER_VARIABLE, "").partition(os.pathsep)
    if configured and configured == directory and owner != str(_CORE):
        configured = None  # set by another copy of the package for itself (module docstring)
    if configured:
        given = Path(configured)
        # Inherited from a parent process that ran this set-up: already ours.
        target = given if given.name == CACHE_NAME else given / CACHE_NAME
        return target if _writable(target) else None
    in_tree = _CORE / "__pycache__"  # beside the core's sub-packages
    if _writable(in_tree / CACHE_NAME):
        _prune(in_tree)
        return in_tree / CACHE_NAME
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    user = Path(base) / "hexapod_workspace" / CACHE_NAME
    return user if _writable(user) else None


#: Directory of the compiled-code cache (None when no directory is writable: then every
#: process compiles, and nothing is cached).
CACHE_DIRECTORY = _cache_directory()
if CACHE_DIRECTORY is not None:
    os.environ["NUMBA_CACHE_DIR"] = str(CACHE_DIRECTORY)  # read by numba at import
    os.environ[_OWNER_VARIABLE] = f"{_CORE}{os.pathsep}{CACHE_DIRECTORY}"
    if "numba" in sys.modules:  # imported earlier by someone else: its runtime setting
        import numba

        numba.config.CACHE_DIR = str(CACHE_DIRECTORY)

import numba  # noqa: E402
import numba.core.event  # noqa: E402

_CACHE = CACHE_DIRECTORY is not None

#: The two values of a compile-time switch (module docstring).
ON: int = 1
OFF: None = None
#: The switches of one kernel variant: (moving, cranks, collide, singular).
Switches = tuple[int | None, int | None, int | None, int | None]
#: The ``collide`` switch as the kernels take it: None (no scene), or the first-class
#: collision function of :func:`hexapod_workspace.core.kernels.collision.collision_function`.
Collide = Callable[..., tuple[float, float, float]] | None

# numba ships no type information: the decorators below are typed as returning the function they
# compile, so that mypy checks the kernels' signatures at every call (the returned Dispatcher is
# called exactly like the function).
_F = TypeVar("_F", bound=Callable[..., object])


def jit(function: _F) -> _F:
    """An entry point: nopython mode, releases the GIL, cached on disk (with its callees)."""
    compiled: _F = numba.njit(cache=_CACHE, nogil=True, error_model="numpy")(function)
    return compiled


def helper(function: _F) -> _F:
    """A function only kernels call: compiled into them, so not cached on its own (a process
    that loads the kernels from the cache then never touches it)."""
    compiled: _F = numba.njit(nogil=True, error_model="numpy")(function)
    return compiled


def first_class(function: _F, signature: object) -> _F:
    """A function compiled once for ``signature`` (and cached), for kernels that take it as an
    argument of numba's ``FunctionType`` and call it through its address (its code is not
    compiled again into theirs)."""
    compiled: _F = numba.njit(signature, cache=_CACHE, nogil=True, error_model="numpy")(function)
    return compiled


def entry(function: _F, signature: object) -> _F:
    """An entry point compiled eagerly for one ``signature`` (and cached): for the kernels that
    take a first-class function, whose argument type numba infers only from a signature
    (``signature``: a tuple of argument types, the return type inferred)."""
    compiled: _F = numba.njit([signature], cache=_CACHE, nogil=True, error_model="numpy")(function)
    return compiled


def entry_points(
    signatures: dict[str, tuple[object, ...]] | None,
) -> Callable[[str], Callable[[_F], _F]]:
    """The decorator of each entry point of a variant, by name: :func:`jit` (compiled lazily,
    for the types of its first call) without ``signatures``, else :func:`entry` for
    ``signatures[name]``."""

    def decorate(name: str) -> Callable[[_F], _F]:
        if signatures is None:
            return jit
        signature = signatures[name]
        return lambda function: entry(function, signature)

    return decorate


def inline(function: _F) -> _F:
    """A small helper inlined into its callers at the numba IR level."""
    compiled: _F = numba.njit(inline="always")(function)
    return compiled


# hexapod_workspace.core. : every kernel module of the core's sub-packages (this is core.base.jit).
_CORE_PACKAGE = __name__.rsplit(".", 2)[0] + "."

#: What the first compilation of a 6-UPS check costs, measured by ``benchmarks/compile.py`` on a
#: 2-core virtual machine (CPU seconds, cold cache; the range of one day's runs, the machine's
#: speed varying): the notice quotes it instead of a guess.
MEASURED_FIRST_CHECK_S = (8, 14)


class _CompileAnnouncer(numba.core.event.Listener):  # type: ignore[misc]  # numba: no stubs
    """Calls ``announce`` once, when the first kernel of the core (margins, searches or the torsion
    planner) starts compiling."""

    def __init__(self, announce: Callable[[str], object]) -> None:
        self.announce = announce
        self.announced = False

    def on_start(self, event: numba.core.event.Event) -> None:
        dispatcher = (event.data or {}).get("dispatcher")
        function = getattr(dispatcher, "py_func", None)
        module = str(getattr(function, "__module__", ""))
        if self.announced or not module.startswith(_CORE_PACKAGE):  # ours: kernels, planner
            return
        self.announced = True
        where = CACHE_DIRECTORY if CACHE_DIRECTORY is not None else "nowhere writable: not cached"
        self.announce(
            "compiling the numerical kernels for this machine model, once after install "
            f"(measured: {MEASURED_FIRST_CHECK_S[0]}-{MEASURED_FIRST_CHECK_S[1]} s of CPU for a "
            "6-UPS check, about 2 minutes for every kernel of a model with a scene; "
            f"cache: {where})"
        )

    def on_end(self, event: numba.core.event.Event) -> None:
        """Nothing to do when a compilation ends."""


@contextlib.contextmanager
def compile_notice(announce: Callable[[str], object]) -> Iterator[None]:
    """While active, ``announce(message)`` is called once if a kernel has to be compiled.

    Loading compiled kernels from the cache says nothing; only a real compilation (the first
    run after install, or after an upgrade) does. For the CLI's one line on stderr.
    """
    with numba.core.event.install_listener("numba:compile", _CompileAnnouncer(announce)):
        yield
