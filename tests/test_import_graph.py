"""No import cycles among the modules of hfgpu (``hfgpu/`` and ``kernels/``, installed as ``hfgpu.kernels``).

The graph is built statically from the source (ast, nothing imported, so neither Taichi nor any hfgpu module
is loaded): an edge A -> B for each ``import B``, ``from B import name`` and relative import (resolved against
A's package) found anywhere in A, module level or inside a function, a method or an ``if TYPE_CHECKING``
block. A function-level import only postpones the cycle to the first call: the two modules still need each
other, so it counts as a cycle of the design. ``from P import name`` where ``P.name`` is a module is an edge to
that module, not to P's ``__init__``; the parent packages that Python runs first on any import are no edges
(every module would otherwise need its package's ``__init__``). Each strongly connected component of more
than one module (or a module importing itself) is a cycle; the test names them all.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: package name -> source folder (pyproject.toml [tool.setuptools] package-dir)
PACKAGES = {"hfgpu": ROOT / "hfgpu", "hfgpu.kernels": ROOT / "kernels"}



def modules() -> dict[str, Path]:
    """Every module of hfgpu: dotted name -> file (a package as its ``__init__.py``)."""
    found = {}
    for package, folder in PACKAGES.items():
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder).with_suffix("").parts
            found[".".join((package, *parts[:len(parts) - (parts[-1] == "__init__")]))] = path
    return found


def imported(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The hfgpu modules that module ``name`` (at ``path``) imports, anywhere in its body."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    targets = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            for alias in node.names:  # a submodule by its name, else an attribute of the module ``base``
                targets.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base)
    edges = set()
    for target in targets:
        while target and target not in known:  # hfgpu.x.y.attribute -> hfgpu.x.y
            target = target.rpartition(".")[0]
        if target:
            edges.add(target)
    return edges


def import_graph() -> dict[str, set[str]]:
    """Module -> the hfgpu modules it imports."""
    known = modules()
    return {name: imported(name, path, known) for name, path in known.items()}


def cycles(graph: dict[str, set[str]]) -> list[tuple[str, ...]]:
    """The strongly connected components with a cycle (Tarjan), each as a sorted tuple of module names."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for succ in graph[node]:
            if succ not in index:
                visit(succ)
                low[node] = min(low[node], low[succ])
            elif succ in on_stack:
                low[node] = min(low[node], index[succ])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1 or node in graph[node]:
                found.append(tuple(sorted(component)))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(found)


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    return import_graph()


def test_graph_covers_both_folders(graph):
    assert "hfgpu.kernels.runtime" in graph and "hfgpu.proppant.simulator" in graph
    assert "hfgpu.kernels.runtime" in graph["hfgpu.kernels.engine"]
    assert "hfgpu.kernels.momentum" in graph["hfgpu.proppant.fluid"]  # a function-level import


def test_no_import_cycles(graph):
    found = cycles(graph)
    assert not found, "import cycles (each a set of modules that import one another):\n" + "\n".join(
        " <-> ".join(c) for c in found)


def test_kernels_import_no_other_hfgpu_package(graph):
    """kernels/ is the bottom layer: hfgpu.proppant drives the kernels, never the reverse, so no cycle runs
    through the two folders (the constants both sides read live in kernels/, e.g. kernels/closures/wall_friction.py)."""
    outside = {(module, target) for module, targets in graph.items() if module.startswith("hfgpu.kernels")
               for target in targets if not target.startswith("hfgpu.kernels")}
    assert not outside, f"kernels/ imports hfgpu modules outside it: {sorted(outside)}"
