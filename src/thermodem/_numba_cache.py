"""Numba's on-disk cache, invalidated by what a kernel's module depends on.

Numba keys a cached kernel on the source of the file that defines it. thermodem's passes
inline model kernels, dispatchers and constants from other modules, so that stamp alone
would let an edited model run with the old machine code. This module gives Numba a cache
locator (Numba's ``NUMBA_CACHE_LOCATOR_CLASSES`` hook) whose source stamp for a file of the
package is a hash of the file **and of every package module it imports, transitively**
(found by reading the import statements). An edit to a model module therefore recompiles
the kernels that can inline it (the pair passes, the heat-term passes) and nothing else: the
neighbour search, the integrator, the mechanics-only passes stay in the cache, and an edit
to the orchestration (engine, run layer, CLI) recompiles nothing.

The cache lives in one directory, ``~/.cache/thermodem/numba`` (or
``$THERMODEM_CACHE_DIR/numba``); ``NUMBA_CACHE_DIR`` set by the user wins, and so does a
``NUMBA_CACHE_LOCATOR_CLASSES`` of the user's.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import json
import os
from pathlib import Path

PACKAGE_ROOT = Path(__file__).resolve().parent
PACKAGE = PACKAGE_ROOT.name


def _module_file(name: str, root: Path) -> Path | None:
    """The file of package module ``name`` (``thermodem.a.b``) under ``root``, if any."""
    parts = name.split(".")
    if parts[0] != PACKAGE:
        return None
    base = root.joinpath(*parts[1:])
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def imported_files(path: Path, root: Path = PACKAGE_ROOT) -> set[Path]:
    """Package files that ``path`` imports directly (any import statement, at any depth)."""
    tree = ast.parse(path.read_bytes(), filename=str(path))
    package = ".".join([PACKAGE, *path.parent.relative_to(root).parts])
    found: set[Path] = set()
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            names = [module] + [f"{module}.{a.name}" for a in node.names]
        for name in names:
            # the module and its parent packages (importing a.b runs a/__init__.py)
            parts = name.split(".")
            for k in range(2, len(parts) + 1):
                target = _module_file(".".join(parts[:k]), root)
                if target is not None and target != path:
                    found.add(target)
    return found


def cache_root() -> Path:
    """thermodem's cache directory: ``$THERMODEM_CACHE_DIR`` or ``~/.cache/thermodem``."""
    return Path(os.environ.get("THERMODEM_CACHE_DIR", Path.home() / ".cache" / "thermodem"))


class _ImportMemo:
    """The direct imports of each package file, kept on disk (``imports.json`` in the cache
    root) under the file's size and modification time: parsing the ~60 kernel-side files
    cost ~0.4 s at every process start; an entry whose file changed is parsed again."""

    def __init__(self) -> None:
        self.path = cache_root() / "imports.json"
        try:
            self.entries: dict[str, list] = json.loads(self.path.read_text())
        except (OSError, ValueError):
            self.entries = {}
        self.dirty = False

    def get(self, path: Path) -> frozenset[Path]:
        stat = path.stat()
        key = str(path)
        entry = self.entries.get(key)
        if entry is not None and entry[0] == stat.st_size and entry[1] == stat.st_mtime_ns:
            return frozenset(PACKAGE_ROOT / rel for rel in entry[2])
        found = imported_files(path, PACKAGE_ROOT)
        rel = sorted(f.relative_to(PACKAGE_ROOT).as_posix() for f in found)
        self.entries[key] = [stat.st_size, stat.st_mtime_ns, rel]
        self.dirty = True
        return frozenset(found)

    def save(self) -> None:
        if not self.dirty:
            return
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            tmp = self.path.with_name(f"{self.path.name}.{os.getpid()}.tmp")
            tmp.write_text(json.dumps(self.entries))
            os.replace(tmp, self.path)  # atomic: a concurrent process reads old or new
            self.dirty = False
        except OSError:
            pass  # a read-only cache: parsed again next time


_MEMO: _ImportMemo | None = None


@functools.cache
def _installed_imports(path: Path) -> frozenset[Path]:
    global _MEMO
    if _MEMO is None:
        _MEMO = _ImportMemo()
    return _MEMO.get(path)


def dependencies(path: Path, root: Path = PACKAGE_ROOT) -> list[Path]:
    """``path`` and every package file it imports, transitively (sorted)."""
    direct = _installed_imports if root == PACKAGE_ROOT else lambda f: imported_files(f, root)
    seen: set[Path] = set()
    todo = [Path(path).resolve()]
    while todo:
        current = todo.pop()
        if current in seen:
            continue
        seen.add(current)
        todo.extend(direct(current) - seen)
    return sorted(seen)


def compute_stamp(path: Path, root: Path = PACKAGE_ROOT) -> str:
    """SHA-256 over the relative path and contents of ``path`` and its dependencies."""
    digest = hashlib.sha256()
    for dep in dependencies(path, root):
        digest.update(dep.relative_to(root).as_posix().encode())
        digest.update(dep.read_bytes())
    return digest.hexdigest()


@functools.cache
def dependency_stamp(path: str) -> str:
    """:func:`compute_stamp` of a file of the installed package, once per process (the
    sources do not change while a process runs)."""
    stamp = compute_stamp(Path(path), PACKAGE_ROOT)
    if _MEMO is not None:
        _MEMO.save()
    return stamp


def _global_hash_directory(base: Path) -> Path:
    """The fallback for a Numba without cache locator classes: one directory per hash of all
    package sources (any edit recompiles everything)."""
    digest = hashlib.sha256()
    for path in sorted(PACKAGE_ROOT.rglob("*.py")):
        digest.update(path.relative_to(PACKAGE_ROOT).as_posix().encode())
        digest.update(path.read_bytes())
    return base / f"numba-{digest.hexdigest()[:16]}"


def _locator_class():  # noqa: ANN202 (numba imported lazily)
    from numba.core.caching import UserProvidedCacheLocator

    class DependencyCacheLocator(UserProvidedCacheLocator):
        """Numba cache locator for thermodem's files: the source stamp covers the file and
        the package modules it imports (see the module docstring)."""

        @classmethod
        def from_function(cls, py_func, py_file):  # noqa: ANN001, ANN206
            try:
                Path(py_file).resolve().relative_to(PACKAGE_ROOT)
            except ValueError:
                return None  # not ours: Numba's own locators decide
            return super().from_function(py_func, py_file)

        def get_source_stamp(self):  # noqa: ANN202
            return dependency_stamp(str(Path(self._py_file).resolve()))

    return DependencyCacheLocator


#: The locator class, importable by name for ``NUMBA_CACHE_LOCATOR_CLASSES``.
DependencyCacheLocator = None


def configure() -> None:
    """Point Numba's cache at thermodem's directory with the dependency-stamped locator."""
    global DependencyCacheLocator
    import numba

    locators = hasattr(numba.config, "CACHE_LOCATOR_CLASSES")
    if "NUMBA_CACHE_DIR" not in os.environ:
        base = cache_root()
        cache = base / "numba" if locators else _global_hash_directory(base)
        try:
            cache.mkdir(parents=True, exist_ok=True)
        except OSError:
            return  # Numba's default locations are kept
        numba.config.CACHE_DIR = str(cache)
    if not locators or os.environ.get("NUMBA_CACHE_LOCATOR_CLASSES"):
        return
    DependencyCacheLocator = _locator_class()
    numba.config.CACHE_LOCATOR_CLASSES = (
        f"{__name__}.DependencyCacheLocator,"
        "numba.core.caching.UserProvidedCacheLocator,"
        "numba.core.caching.InTreeCacheLocator,"
        "numba.core.caching.UserWideCacheLocator"
    )
