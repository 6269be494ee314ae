"""No import cycles among uvnav's modules, counting imports inside functions too.

The graph is read from the source with ``ast`` (nothing is imported): every ``import x`` and
``from x import y`` anywhere in a module is an edge, except those under ``if TYPE_CHECKING:``
(they never run). ``from pkg import name`` is an edge to ``pkg`` and, when ``pkg.name`` is a
module, to ``pkg.name`` as well. A strongly connected component of more than one module is a
cycle; the test prints each with the import lines that close it.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
ROOT_PACKAGE = "uvnav"

#: (importing module, imported module) -> line numbers of the import statements.
Graph = dict[str, dict[str, list[int]]]


def _module_name(path: Path, src: Path) -> str:
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def discover_modules(src: Path = SRC) -> dict[str, Path]:
    """Every module under ``src/uvnav``, by dotted name (packages by their own name)."""
    return {_module_name(p, src): p for p in sorted((src / ROOT_PACKAGE).rglob("*.py"))}


def _is_type_checking(test: ast.expr) -> bool:
    if isinstance(test, ast.Name):
        return test.id == "TYPE_CHECKING"
    return isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"


def _runtime_imports(node: ast.AST) -> Iterator[ast.Import | ast.ImportFrom]:
    """Import statements under ``node`` that can run (the ``if TYPE_CHECKING:`` body excluded)."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.Import | ast.ImportFrom):
            yield child
        elif isinstance(child, ast.If) and _is_type_checking(child.test):
            for sub in child.orelse:
                yield from _runtime_imports_of_stmt(sub)
        else:
            yield from _runtime_imports(child)


def _runtime_imports_of_stmt(stmt: ast.stmt) -> Iterator[ast.Import | ast.ImportFrom]:
    if isinstance(stmt, ast.Import | ast.ImportFrom):
        yield stmt
    else:
        yield from _runtime_imports(stmt)


def _resolve_base(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    """The absolute name ``from <base> import ...`` refers to."""
    if node.level == 0:
        return node.module or ""
    package = module.split(".") if is_package else module.split(".")[:-1]
    anchor = package[: len(package) - (node.level - 1)]
    return ".".join(anchor + ([node.module] if node.module else []))


def _targets(
    module: str, is_package: bool, node: ast.Import | ast.ImportFrom, known: set[str]
) -> Iterator[str]:
    if isinstance(node, ast.Import):
        for alias in node.names:
            yield alias.name
        return
    base = _resolve_base(module, is_package, node)
    yield base
    for alias in node.names:
        candidate = f"{base}.{alias.name}"
        if candidate in known:
            yield candidate


def import_graph(modules: dict[str, Path]) -> Graph:
    """Edges between uvnav modules; an edge to a missing name goes to its nearest known parent."""
    known = set(modules)
    graph: Graph = {name: {} for name in modules}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        is_package = path.name == "__init__.py"
        for node in _runtime_imports(tree):
            for target in _targets(name, is_package, node, known):
                while target and target not in known:
                    target = target.rpartition(".")[0]
                if target and target != name:
                    graph[name].setdefault(target, []).append(node.lineno)
    return graph


def strongly_connected(graph: Graph) -> list[list[str]]:
    """Tarjan's components, iteratively; each sorted, the list sorted by its first member."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    components: list[list[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work: list[tuple[str, Iterator[str]]] = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                components.append(sorted(component))
    return sorted(components)


def cycles(graph: Graph) -> list[list[str]]:
    return [c for c in strongly_connected(graph) if len(c) > 1]


def describe(graph: Graph, component: list[str]) -> str:
    members = set(component)
    lines = [f"cycle of {len(component)} modules: {', '.join(component)}"]
    for source in component:
        for target, linenos in sorted(graph[source].items()):
            if target in members:
                where = ", ".join(str(n) for n in linenos)
                lines.append(f"    {source} -> {target}  (line {where})")
    return "\n".join(lines)


def _graph_of(sources: dict[str, str], tmp_path: Path) -> Graph:
    for rel, text in sources.items():
        path = tmp_path / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return import_graph(discover_modules(tmp_path))


def test_no_import_cycles_among_uvnav_modules() -> None:
    graph = import_graph(discover_modules())
    assert len(graph) > 100, "the module walk found too few modules"
    found = cycles(graph)
    assert found == [], "import cycles in uvnav:\n" + "\n".join(describe(graph, c) for c in found)


def test_function_level_and_relative_imports_count(tmp_path: Path) -> None:
    graph = _graph_of(
        {
            "uvnav/__init__.py": "",
            "uvnav/pkg/__init__.py": "from uvnav.pkg.a import f\n",
            "uvnav/pkg/a.py": "def f():\n    from . import b\n    return b\n",
            "uvnav/pkg/b.py": (
                "from .. import pkg\nclass C:\n    def m(self):\n        import uvnav.pkg.a\n"
            ),
        },
        tmp_path,
    )
    assert graph["uvnav.pkg.a"] == {"uvnav.pkg": [2], "uvnav.pkg.b": [2]}
    assert graph["uvnav.pkg.b"] == {"uvnav": [1], "uvnav.pkg": [1], "uvnav.pkg.a": [4]}
    assert cycles(graph) == [["uvnav.pkg", "uvnav.pkg.a", "uvnav.pkg.b"]]
    text = describe(graph, cycles(graph)[0])
    assert "uvnav.pkg.b -> uvnav.pkg.a  (line 4)" in text


def test_type_checking_imports_do_not_count(tmp_path: Path) -> None:
    graph = _graph_of(
        {
            "uvnav/__init__.py": "",
            "uvnav/a.py": "import uvnav.b\n",
            "uvnav/b.py": (
                "import typing\nif typing.TYPE_CHECKING:\n    from uvnav import a\n"
                "else:\n    from uvnav import c\n"
            ),
            "uvnav/c.py": "",
        },
        tmp_path,
    )
    assert graph["uvnav.b"] == {"uvnav": [5], "uvnav.c": [5]}
    assert cycles(graph) == []
