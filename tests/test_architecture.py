"""Dependencies run one way (issue 18, item 5): the import graph of ``src/vfem`` (every
``from ... import``, at module level or inside a function; not those under ``if
TYPE_CHECKING:``, which only name types for annotations and never run) has no cycle. Nothing
under ``contact/`` imports the solver."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src" / "vfem"

#: The import cycles still there, each as its sorted modules (none since 2026-11-24: the result
#: types moved to vfem.result_types, the value checks to vfem.schema).
KNOWN_CYCLES: set[tuple[str, ...]] = set()


def import_graph() -> dict[str, set[str]]:
    modules = {}
    for f in ROOT.rglob("*.py"):
        name = "vfem." + ".".join(f.relative_to(ROOT).with_suffix("").parts)
        modules[name.removesuffix(".__init__")] = f
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for m, f in modules.items():
        package = m if f.name == "__init__.py" else m.rsplit(".", 1)[0]
        tree = ast.parse(f.read_text(encoding="utf-8"))
        typing_only = {id(n) for block in ast.walk(tree) if isinstance(block, ast.If)
                       and "TYPE_CHECKING" in ast.unparse(block.test)
                       for n in ast.walk(block)}
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom) or id(node) in typing_only:
                continue
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            for target in [base] + [f"{base}.{a.name}" for a in node.names]:
                if target in modules and target != m:
                    graph[m].add(target)
    return graph


def cycles(graph: dict[str, set[str]]) -> set[tuple[str, ...]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: set[tuple[str, ...]] = set()

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.add(tuple(sorted(component)))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_import_cycle_but_the_known_ones():
    assert cycles(import_graph()) == KNOWN_CYCLES


def test_the_cycle_finder_finds_a_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(graph) == {("a", "b", "c")}


def test_nothing_under_contact_imports_the_solver():
    graph = import_graph()
    assert not [m for m, targets in graph.items()
                if m.startswith("vfem.contact") and "vfem.solver" in targets]


def test_the_core_never_imports_the_tools():
    """Benchmarking and the CalculiX comparison are tools around the solver (vfem.tools): only
    the command line (its bench and study commands) and the tools themselves import them."""
    graph = import_graph()
    users = sorted(m for m, targets in graph.items()
                   if any(t.startswith("vfem.tools") for t in targets)
                   and not m.startswith("vfem.tools"))
    assert users == ["vfem.cli"]
