"""Dependencies run one way (issue 18, item 5; issue 38): the import graph of ``src/vfem``
(every ``import`` and ``from ... import``, at module level or inside a function) has no cycle,
those under ``if TYPE_CHECKING:`` counted too (they never run, but a circle of type hints is a
circle of knowledge: neither side can change alone); and every module imports only from its
own layer or the layers below (:data:`LAYERS`: data flows mesh -> body -> contact -> solver ->
results, and so do the imports). Nothing under ``contact/`` imports the solver; inside it, the
pipeline's stages (:data:`CONTACT_STAGES`) import downwards only, each other through their
faces."""

import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "src" / "vfem"

#: The import cycles still there, each as its sorted modules (none since 2026-11-24: the result
#: types moved to vfem.result_types, the value checks to vfem.schema; none with the type hints
#: counted since 2026-11-30: the model and one body's results moved below the solver and
#: contact, vfem.model and vfem.bodies.results).
KNOWN_CYCLES: set[tuple[str, ...]] = set()

#: The layers, lowest first; a module is in the layer of the longest prefix listed that names it
#: (its package's), and imports from that layer or those below only.
LAYERS: tuple[tuple[str, ...], ...] = (
    ("vfem._version", "vfem.errors", "vfem.threads", "vfem.memory", "vfem.schema",
     "vfem.kinematics", "vfem.executor"),
    ("vfem.linalg", "vfem.mesh", "vfem.materials"),
    ("vfem.nonlinear", "vfem.bodies"),  # one body: its mechanics, assembly, results
    ("vfem.contact",),
    ("vfem.model", "vfem.parallel", "vfem.result_types"),
    ("vfem.solver",),
    ("vfem.config",),
    ("vfem.io",),
    ("vfem.cli", "vfem.__main__", "vfem"),
)


#: Inside contact, the pipeline's stages, lowest first (issue 38): a subpackage of
#: ``vfem.contact`` each, whose ``__init__`` is its public face. A module imports only from its
#: own stage or those below, and from another stage only through that stage's face. The modules
#: directly under ``vfem.contact`` are the data every stage passes on (:data:`CONTACT_DATA`).
CONTACT_STAGES: tuple[str, ...] = (
    "search",  # candidates, closest points
    "geometry",  # facet kinds, surfaces and a body's flexibility on them, pairing, transfer
    "laws",  # the thesis's two corrections, node by node
    "solvers",  # the contact-set iteration, complementarity, bordered and matrix-free solves
    "formulations",  # the paired and thesis variants, the baselines: compositions of the above
    "invariants",  # the checks of every converged state
)
CONTACT_DATA: tuple[str, ...] = ("settings", "state", "capabilities")

#: the most lines a module of ``contact/`` or ``bodies/`` may have (issue 38), and those still
#: over it (none since the large-kinematics formulation's follower stiffness and ``Body``'s
#: responsibilities moved to modules of their own)
MODULE_LINES = 600
KNOWN_LONG: set[str] = set()


@functools.cache
def import_graph(typing: bool = True) -> dict[str, set[str]]:
    """Module -> the modules of ``vfem`` it imports (``typing``: those under ``TYPE_CHECKING``
    too); parsed once per process (the rules below share it: a second each, not one per
    rule), so the callers do not change what it returns."""
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
            if isinstance(node, ast.Import) and (typing or id(node) not in typing_only):
                for a in node.names:
                    target = a.name
                    while target and target not in modules:  # vfem.x.y -> the module vfem.x
                        target = target.rpartition(".")[0]
                    if target and target != m:
                        graph[m].add(target)
                continue
            if not isinstance(node, ast.ImportFrom) or (not typing and id(node) in typing_only):
                continue
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            for a in node.names:  # a submodule by name, else a name of the module itself
                target = f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base
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
    assert cycles(import_graph(typing=False)) <= KNOWN_CYCLES


def layer(module: str) -> int:
    best, found = -1, None
    for k, members in enumerate(LAYERS):
        for name in members:
            if (module == name or module.startswith(name + ".")) and len(name) > best:
                best, found = len(name), k
    assert found is not None, f"{module} is in no layer: name it in LAYERS"
    return found


def upward(graph: dict[str, set[str]]) -> list[str]:
    """Each import from a layer above the importer's."""
    return sorted(f"{m} (layer {layer(m)}) imports {t} (layer {layer(t)})"
                  for m, targets in graph.items() for t in targets if layer(t) > layer(m))


def test_no_module_imports_from_a_layer_above_its_own():
    assert not upward(import_graph()), "\n".join(upward(import_graph()))


def stage(module: str) -> int:
    """0 for contact's data, k for the k-th of :data:`CONTACT_STAGES` (its face or a module)."""
    parts = module.split(".")
    assert parts[:2] == ["vfem", "contact"] and len(parts) >= 3, module
    if parts[2] in CONTACT_STAGES:
        return CONTACT_STAGES.index(parts[2]) + 1
    assert len(parts) == 3 and parts[2] in CONTACT_DATA, (
        f"{module} is in no stage: move it into one of {CONTACT_STAGES}, or name it in "
        "CONTACT_DATA")
    return 0


def test_contact_imports_only_from_its_own_stage_or_those_below():
    graph = import_graph()
    inside = [m for m in graph if m.startswith("vfem.contact.")]
    back = sorted(f"{m} (stage {stage(m)}) imports {t} (stage {stage(t)})" for m in inside
                  for t in graph[m] if t.startswith("vfem.contact.") and stage(t) > stage(m))
    assert not back, "\n".join(back)


def reaching_in(graph: dict[str, set[str]]) -> list[str]:
    """Each import of a stage's module (not its face) from outside that stage."""
    def stem(t: str) -> str:  # vfem.contact.<stage>
        return ".".join(t.split(".")[:3])

    return sorted(f"{m} imports {t}" for m, targets in graph.items() for t in targets
                  if t.startswith("vfem.contact.") and len(t.split(".")) == 4
                  and t.split(".")[2] in CONTACT_STAGES
                  and not (m == stem(t) or m.startswith(stem(t) + ".")))


def test_a_stage_is_reached_through_its_face():
    """Outside a stage (the rest of contact, the solver, the writers, the examples) its names
    come from its face, ``vfem.contact.<stage>``: what a stage offers is what its
    ``__init__`` lists, and its modules can be split or merged without touching the callers."""
    assert not reaching_in(import_graph()), "\n".join(reaching_in(import_graph()))
    assert reaching_in({"vfem.solver": {"vfem.contact.geometry.surface"},
                        "vfem.contact.geometry.pairing": {"vfem.contact.geometry.surface"},
                        "vfem.contact.formulations.paired": {"vfem.contact.geometry"}}) == [
        "vfem.solver imports vfem.contact.geometry.surface"]
    for name in CONTACT_STAGES:
        face = ROOT / "contact" / name / "__init__.py"
        assert face.is_file() and "__all__" in face.read_text(encoding="utf-8"), face


def test_the_layer_rule_finds_an_upward_import():
    assert upward({"vfem.contact.formulations.paired": {"vfem.parallel", "vfem.bodies"},
                   "vfem.bodies": set(), "vfem.parallel": {"vfem.bodies"}}) == [
        "vfem.contact.formulations.paired (layer 3) imports vfem.parallel (layer 4)"]
    assert layer("vfem.bodies.results") == 2 and layer("vfem") == 8


def test_the_cycle_finder_finds_a_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(graph) == {("a", "b", "c")}


def test_nothing_under_contact_imports_the_solver():
    graph = import_graph()
    assert not [m for m, targets in graph.items()
                if m.startswith("vfem.contact") and "vfem.solver" in targets]


def outside_imports(module_path: Path) -> set[str]:
    """The top-level packages other than ``vfem`` a module imports (at module level or inside
    a function, those under ``TYPE_CHECKING`` too)."""
    tree = ast.parse(module_path.read_text(encoding="utf-8"))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            out.add(node.module.split(".")[0])
    return out - {"vfem"}


#: the packages beside the library (issue 38): the built-in examples and the tools around the
#: solver (benchmarks, the CalculiX comparison), which only the command line loads
BESIDE = ("vfem_examples", "vfem_tools")


@pytest.mark.slow
def test_the_library_never_imports_the_examples_or_the_tools():
    """The examples and the tools are packages beside the library (``src/vfem_examples``,
    ``src/vfem_tools``), out of its import path: nothing under ``vfem`` imports them but the
    command line (``vfem run hertz``, ``vfem bench``), which loads them; they import the
    library, never the other way."""
    users = sorted(f.relative_to(ROOT).as_posix() for f in ROOT.rglob("*.py")
                   if outside_imports(f) & set(BESIDE))
    assert users and all(u.startswith("cli/") for u in users), users
    assert not (ROOT / "examples").exists() and not (ROOT / "tools").exists()


def test_the_examples_never_import_the_tools():
    """The tools use the examples (the bench times Hertz and the sphere), not the other way."""
    examples = ROOT.parent / "vfem_examples"
    assert not [f.name for f in examples.rglob("*.py") if "vfem_tools" in outside_imports(f)]


def test_no_module_of_contact_or_bodies_is_longer_than_600_lines_but_the_known_ones():
    """A module that grows past :data:`MODULE_LINES` is split along what it does (issue 38);
    one split below it leaves :data:`KNOWN_LONG` (equality: the list shrinks with the code)."""
    long = {f.relative_to(ROOT).as_posix() for package in ("contact", "bodies")
            for f in (ROOT / package).rglob("*.py")
            if len(f.read_text(encoding="utf-8").splitlines()) > MODULE_LINES}
    assert long == KNOWN_LONG


def inheritance_depths(sources: dict[str, str]) -> dict[str, int]:
    """Class name -> the levels of classes of ``sources`` (module -> text) above it: 0 for a
    class that derives from none of them, 1 for one that derives from such a class, and so on.
    A protocol (a class deriving from ``Protocol``) is not counted as a base, and error classes
    (those whose bases reach ``Exception``) are left out: a protocol's implementer reuses
    nothing, an error's kind is its class."""
    bases: dict[str, list[str]] = {}
    for text in sources.values():
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                bases[node.name] = [ast.unparse(b).split(".")[-1].split("[")[0]
                                    for b in node.bases]

    def error(name: str, seen: tuple[str, ...] = ()) -> bool:
        return any(b == "Exception" or (b in bases and b not in seen
                                        and error(b, seen + (name,)))
                   for b in bases.get(name, ()))

    def counted(b: str, seen: tuple[str, ...]) -> bool:  # a class of sources, not a protocol
        return b in bases and b not in seen and "Protocol" not in bases[b]

    def depth(name: str, seen: tuple[str, ...] = ()) -> int:
        return max((1 + depth(b, seen + (name,)) for b in bases.get(name, ())
                    if counted(b, seen)), default=0)

    return {name: depth(name) for name in bases if not error(name)}


@pytest.mark.slow
def test_no_class_derives_more_than_one_level_for_reuse():
    """Issue 38: formulations are composed of parts (the surface group, the friction part, the
    pairs' making), not one class per combination built on the one before; a class of the
    library derives at most from one class of it (a protocol's implementer or an error's kind
    is not reuse)."""
    sources = {str(f.relative_to(ROOT)): f.read_text(encoding="utf-8")
               for f in ROOT.rglob("*.py")}
    deep = {name: d for name, d in inheritance_depths(sources).items() if d > 1}
    assert not deep, deep
    # the count sees a chain, not a protocol or an error's kind
    assert inheritance_depths({"m": "class A: pass\nclass B(A): pass\nclass C(B): pass\n"
                               "class P(Protocol): pass\nclass Q(P): pass\nclass R(Q): pass\n"
                               "class E(Exception): pass\nclass F(E): pass\nclass G(F): pass"}
                              ) == {"A": 0, "B": 1, "C": 2, "P": 0, "Q": 0, "R": 1}
