"""eb_core's import graph, drawn from the code with ast (imports inside functions included; a submodule's
implicit import of its parent package is not an edge): the CLI and the modules it drives sit in no import cycle
(issue #27). ``cycles_in()`` is ready for the general check
(``assert not cycles_in(graph)``) once every module's cycle is broken."""

from __future__ import annotations

import ast
from pathlib import Path

import eb_core

ROOT = Path(eb_core.__file__).parent
#: No cycle may pass through these modules (the config path, the CLI and the commands it drives).
OWNED = ("eb_core.cli", "eb_core.compose", "eb_core.exceptions", "eb_core.report", "eb_core.paired", "eb_core.plot",
         "eb_core.prompt_view",
         "eb_core.html")


def module_name(path: Path, root: Path = ROOT) -> str:
    rel = path.relative_to(root.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def import_graph(root: Path = ROOT) -> dict[str, set[str]]:
    """``{module: modules of the same package it imports}``, relative imports resolved."""
    modules = {module_name(p, root): p for p in root.rglob("*.py")}
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for mod, path in modules.items():
        package = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")
                    anchor = anchor[: len(anchor) - (node.level - 1)]
                    base = ".".join([*anchor, base] if base else anchor)
                # `from pkg import module` imports that module; `from pkg import Name` runs pkg's __init__
                subs = [f"{base}.{a.name}" for a in node.names]
                targets = subs if all(s in modules for s in subs) else [base, *subs]
            for t in targets:
                while t and t not in modules:  # eb_core.report.render_report -> eb_core.report
                    t = t.rsplit(".", 1)[0] if "." in t else ""
                if t and t != mod:
                    graph[mod].add(t)
    return graph


def cycles_in(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
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
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _owned(mod: str) -> bool:
    return any(mod == o or mod.startswith(o + ".") for o in OWNED)


def test_the_graph_sees_lazy_imports():
    graph = import_graph()
    assert "eb_core.compose" in graph["eb_core.cli.run"]  # a module-level import
    assert "eb_core.report" in graph["eb_core.cli.report"]  # an import inside a function


def test_no_import_cycle_through_the_cli_and_the_modules_it_drives():
    cycles = [c for c in cycles_in(import_graph()) if any(_owned(m) for m in c)]
    assert not cycles, cycles


def test_cycles_are_found():
    assert cycles_in({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_import_cycle_anywhere_in_the_core():
    assert not cycles_in(import_graph()), cycles_in(import_graph())


def test_no_import_cycle_inside_any_installed_world_or_the_scene_kit():
    import importlib

    checked = 0
    for pkg in ("eb_navigation", "eb_alfred", "eb_habitat", "eb_manipulation", "eb_scenekit", "eb_models"):
        try:
            mod = importlib.import_module(pkg)
        except ImportError:
            continue
        root = Path(list(mod.__path__)[0])
        graph = import_graph(root)
        assert any(graph.values()), pkg  # the graph sees the package's own imports
        assert not cycles_in(graph), (pkg, cycles_in(graph))
        checked += 1
    assert checked >= 1
