"""numba set-up shared by every compiled kernel of the core: the cache directory and the decorators.

numba stores the compiled code next to the core modules (``__pycache__``) when that directory is
writable, otherwise in the user cache directory (``$XDG_CACHE_HOME/hexapod_workspace/numba``,
default ``~/.cache/hexapod_workspace/numba``), so a read-only install (colcon install space,
system site-packages) compiles once per user. This module must be imported before numba (every
kernel module imports it first): numba reads its cache directory once, at import.
:func:`compile_notice` says once when a kernel of the core really compiles.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

__all__ = ["CACHE_DIRECTORY", "compile_notice", "helper", "inline", "jit"]


def _writable(directory: Path) -> bool:
    """Whether files can be created in ``directory`` (created if missing)."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=directory):
            pass
    except OSError:
        return False
    return True


def _cache_directory() -> Path | None:
    """Where numba caches this module's compiled code (None: nowhere writable, no cache)."""
    configured = os.environ.get("NUMBA_CACHE_DIR")
    if configured:
        return Path(configured)
    in_tree = Path(__file__).resolve().parent / "__pycache__"
    if _writable(in_tree):
        return in_tree
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    user = Path(base) / "hexapod_workspace" / "numba"
    if _writable(user):
        # Must be set before numba is imported: numba reads it once, at import.
        os.environ["NUMBA_CACHE_DIR"] = str(user)
        return user
    return None


#: Directory of the compiled-code cache (None when no directory is writable: then every
#: process compiles, which takes seconds, and nothing is cached).
CACHE_DIRECTORY = _cache_directory()
if CACHE_DIRECTORY is not None and "numba" in sys.modules:
    # numba was imported earlier by someone else: point its configuration here as well.
    import numba.core.config

    if os.environ.get("NUMBA_CACHE_DIR"):
        numba.core.config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"]

import numba  # noqa: E402
import numba.core.event  # noqa: E402

_CACHE = CACHE_DIRECTORY is not None

#: The modules whose code ends up in the compiled kernels. numba keys a cached kernel on the
#: source file of its entry point only, so a changed helper in another module (a margin kernel
#: compiled into a search kernel) would be loaded stale from the cache; every kernel of the
#: core is therefore keyed on all of them together (numba's cache locators are internal API).
KERNEL_SOURCES = tuple(
    (Path(__file__).resolve().parent / name).resolve()
    for name in (
        "jit.py",
        "constraint_table.py",
        "model_layout.py",
        "collision_kernels.py",
        "collision/distance.py",
        "margin_kernels.py",
        "search_kernels.py",
        "planner_kernels.py",
    )
)


def _kernel_stamp() -> tuple[tuple[float, int], ...]:
    stamps = []
    for source in KERNEL_SOURCES:
        status = source.stat()
        stamps.append((status.st_mtime, status.st_size))
    return tuple(stamps)


def _kernel_locators() -> list[type]:
    """numba cache locators that stamp our kernels with every kernel module's stamp."""
    from numba.core import caching

    class _KernelStamp:
        def get_source_stamp(self) -> tuple[tuple[float, int], ...]:
            return _kernel_stamp()

    locators: list[type] = []
    for base in (
        caching._UserProvidedCacheLocator,
        caching._InTreeCacheLocator,
        caching._UserWideCacheLocator,
    ):

        def from_function(cls: type, py_func: Any, py_file: str, _base: Any = base) -> Any:
            if Path(py_file).resolve() not in KERNEL_SOURCES:
                return None
            return _base.from_function.__func__(cls, py_func, py_file)

        locators.append(
            type(
                f"_Kernel{base.__name__}",
                (_KernelStamp, base),
                {"from_function": classmethod(from_function)},
            )
        )
    return locators


if _CACHE:
    from numba.core import caching as _caching

    if not any(c.__name__.startswith("_Kernel") for c in _caching.CacheImpl._locator_classes):
        _caching.CacheImpl._locator_classes[:0] = _kernel_locators()

# numba ships no type information: the decorators below are typed as returning the function they
# compile, so that mypy checks the kernels' signatures at every call (the returned Dispatcher is
# called exactly like the function).
_F = TypeVar("_F", bound=Callable[..., Any])


def jit(function: _F) -> _F:
    """An entry point: nopython mode, releases the GIL, cached on disk (with its callees)."""
    compiled: _F = numba.njit(cache=_CACHE, nogil=True, error_model="numpy")(function)
    return compiled


def helper(function: _F) -> _F:
    """A function only kernels call: compiled into them, so not cached on its own (a process
    that loads the kernels from the cache then never touches it)."""
    compiled: _F = numba.njit(nogil=True, error_model="numpy")(function)
    return compiled


def inline(function: _F) -> _F:
    """A small helper inlined into its callers at the numba IR level."""
    compiled: _F = numba.njit(inline="always")(function)
    return compiled


_CORE_PACKAGE = __name__.rpartition(".")[0] + "."


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
            f"compiling the numerical kernels, once after install (about 10 s; cache: {where})"
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
