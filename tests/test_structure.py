"""The house's structure (issue 14): no import circles, no oversized files, no reaching into
another module's private names — checked over ``engine/``, ``quilt_gui/`` and ``benchmarks/``
from the source.

Every import counts, wherever it is written (module level, inside a function, under
``TYPE_CHECKING``): a lazy import is still an arrow between floors. ``from package import name``
points at ``package.name`` when that is a module, else at the package itself.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("engine", "quilt_gui", "benchmarks")
MAX_LINES = 800


def _modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the packages."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


MODULES = _modules()


def _resolve(name: str, level: int, current: str, is_package: bool) -> str:
    """The absolute dotted name of an import (relative ones resolved against ``current``)."""
    if not level:
        return name
    base = current.split(".")
    base = base if is_package else base[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join([*base, name] if name else base)


def _imports(module: str, tree: ast.AST):
    """(target module, imported name or None, line) of every import in ``tree``."""
    is_package = MODULES[module].name == "__init__.py"
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, None, node.lineno
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(node.module or "", node.level, module, is_package)
            for alias in node.names:
                yield base, alias.name, node.lineno


@cache
def _tree(module: str) -> ast.AST:
    """The parsed source of ``module`` (parsed once for all the tests here)."""
    return ast.parse(MODULES[module].read_text(encoding="utf-8"))


@cache
def _edges() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for module in MODULES:
        tree = _tree(module)
        for base, name, _ in _imports(module, tree):
            target = f"{base}.{name}" if name and f"{base}.{name}" in MODULES else base
            if target in MODULES and target != module:
                graph[module].add(target)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_module_finder_sees_the_packages():
    assert "engine.seams.spec" in MODULES and "quilt_gui.pipeline" in MODULES
    assert "benchmarks.wang" in MODULES
    graph = _edges()
    assert "engine.seams.spec" in graph["engine.seams.search"]
    assert "engine.settings" in graph["quilt_gui.params"]
    assert "benchmarks.quilting_jobs" in graph["benchmarks.fft_backends"]


def test_no_import_circles():
    cycles = _cycles(_edges())
    assert cycles == [], "import circles:\n" + "\n".join(" <-> ".join(c) for c in cycles)


def _long_files() -> dict[str, int]:
    return {
        str(p.relative_to(ROOT)): n
        for p in MODULES.values()
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }


def test_no_file_over_800_lines():
    long = _long_files()
    assert long == {}, f"files over {MAX_LINES} lines: {long}"


def _private(name: str | None) -> bool:
    return bool(name) and name.startswith("_") and not name.startswith("__")


def test_no_module_imports_another_modules_private_name():
    """``from m import _x`` and ``m._x`` (for an imported module ``m``) name another module's
    private name. Private *modules* (``engine._validate``) are the packages' own helpers and
    may be imported; their public names are their interface."""
    found = []
    for module, path in MODULES.items():
        tree = _tree(module)
        aliases = {}
        for base, name, line in _imports(module, tree):
            if name is None:
                continue
            if _private(name) and f"{base}.{name}" not in MODULES:
                found.append(f"{path.relative_to(ROOT)}:{line}: from {base} import {name}")
            elif f"{base}.{name}" in MODULES or base not in MODULES:
                aliases[name] = base
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    aliases[alias.asname or alias.name.split(".")[0]] = alias.name
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and _private(node.attr)
                and isinstance(node.value, ast.Name)
                and node.value.id in aliases
                and node.value.id not in ("self", "cls")
            ):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value.id}.{node.attr}")
    assert found == [], "private names of other modules:\n" + "\n".join(found)
