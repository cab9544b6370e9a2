"""The shape of the code: imports flow one way, private names stay home, modules stay readable.

These tests read the source (``ast``), they run none of it:

- no import circle among the modules of ``intervals``, ``certkin`` and ``proofs``, counting every
  import, at the top of a module or inside a function body;
- imports inside function bodies only for the optional dependencies (matplotlib, dask) and the few
  heavy modules that most commands never use (``DEFERRED``: imported at first use, so that a
  command's start-up does not pay for them): anything else is imported at the top of its module,
  where a reader sees it;
- no module imports a private name (``_name``) from another module, nor reaches one through a
  module it imported (``module._name``): what others need has a public name;
- ``proofs`` imports neither ``certkin`` nor ``intervals``, and ``intervals`` imports no ``certkin``;
- no module over ``MAX_LINES`` lines, no function over ``MAX_FUNCTION`` lines unless its docstring
  says it is one algorithm that reads best whole.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("intervals", "certkin", "proofs")
OPTIONAL = ("matplotlib", "dask", "distributed")      # optional dependencies: imported where used
DEFERRED = ("mpmath",                 # huge arguments of sin, cos, tan only (intervals.elementary)
            "proofs",                 # the checker: a batch that resumes, ``certkin check``
            "importlib.metadata",     # the version in a compiled model's cache key
            "certkin.fk.kernels", "certkin.fk.centred", "certkin.fk.cayley_menger",   # numba: spatial searches only
            "intervals.native",
            "certkin.report", "tqdm")  # reports and progress bars: only with --report, --progress
MAX_LINES = 620
MAX_FUNCTION = 100
WHOLE = "reads best whole"                              # the docstring phrase of a long algorithm kept whole


def _modules() -> dict[str, Path]:
    out = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


MODULES = _modules()
TREES = {name: ast.parse(path.read_text(), str(path)) for name, path in MODULES.items()}


def _package_of(name: str) -> str:
    return name if MODULES[name].name == "__init__.py" else name.rpartition(".")[0]


def _resolve(module: str, node: ast.ImportFrom) -> str:
    """The absolute module name of a ``from ... import`` (relative imports resolved)."""
    if not node.level:
        return node.module or ""
    base = _package_of(module).split(".")
    base = base[:len(base) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str):
    """(target module, imported names, inside a function, node) for every import of ``module``:
    ``from a.b import c`` counts as an import of ``a.b.c`` when that is a module, else of ``a.b``."""
    tree = TREES[module]
    local = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            for inner in ast.walk(node):
                if isinstance(inner, (ast.Import, ast.ImportFrom)):
                    local.add(id(inner))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, [], id(node) in local, node
        elif isinstance(node, ast.ImportFrom):
            target = _resolve(module, node)
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                if sub in MODULES:
                    yield sub, [], id(node) in local, node
                else:
                    yield target, [alias.name], id(node) in local, node


def _graph() -> dict[str, set[str]]:
    graph = {name: set() for name in MODULES}
    for name in MODULES:
        for target, _, _, _ in _imports(name):
            while target and target not in MODULES:       # ``import a.b.c`` of a name inside a module
                target = target.rpartition(".")[0]
            if target and target != name:
                graph[name].add(target)
    return graph


def _cycles(graph):
    """The strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_walk_sees_every_package():
    assert {"intervals.interval", "certkin.engine.search", "proofs.checker"} <= set(MODULES)
    assert sum(len(v) for v in _graph().values()) > 50


def test_no_import_circle():
    assert _cycles(_graph()) == []


def test_the_cycle_finder_finds_a_planted_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _cycles(graph) == [["a", "b", "c"]]


def test_imports_inside_functions_only_for_optional_dependencies():
    bad = [f"{name}:{node.lineno} imports {target}" for name in MODULES
           for target, _, inside, node in _imports(name)
           if inside and target.split(".")[0] not in OPTIONAL and target not in DEFERRED]
    assert bad == []


def test_no_private_name_crosses_a_module_boundary():
    bad = []
    for name, tree in TREES.items():
        aliases = {}
        for target, names, _, node in _imports(name):
            for n in names:
                if n.startswith("_") and not n.startswith("__"):
                    bad.append(f"{name}:{node.lineno} imports {target}.{n}")
            if isinstance(node, ast.Import):
                for alias in node.names:
                    aliases[alias.asname or alias.name.split(".")[0]] = alias.name
            elif target in MODULES and not names:
                for alias in node.names:
                    aliases[alias.asname or alias.name] = target
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                    and node.value.id in aliases and node.attr.startswith("_") and not node.attr.startswith("__"):
                bad.append(f"{name}:{node.lineno} uses {aliases[node.value.id]}.{node.attr}")
    assert bad == []


@pytest.mark.parametrize("package, forbidden", [("proofs", ("certkin", "intervals")), ("intervals", ("certkin",))])
def test_dependencies_point_one_way(package, forbidden):
    bad = [f"{name} imports {target}" for name in MODULES if name.split(".")[0] == package
           for target, _, _, _ in _imports(name) if target.split(".")[0] in forbidden]
    assert bad == []


def test_the_checker_stays_small_enough_to_audit():
    """``proofs`` (the trusted kernel) stays under 3000 lines in all (issue 17); it is a flat package."""
    files = sorted((ROOT / "proofs").rglob("*.py"))
    assert {f.parent for f in files} == {ROOT / "proofs"}
    assert sum(f.read_text().count("\n") for f in files) < 3000


def test_modules_and_functions_stay_readable():
    long_modules = [f"{name}: {MODULES[name].read_text().count(chr(10))} lines" for name in MODULES
                    if MODULES[name].read_text().count("\n") > MAX_LINES and not name.startswith("proofs")]
    long_functions = []
    for name, tree in TREES.items():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION and WHOLE not in (ast.get_docstring(node) or "") \
                        and not name.startswith("proofs"):
                    long_functions.append(f"{name}.{node.name}: {length} lines")
    assert long_modules == [] and long_functions == []
