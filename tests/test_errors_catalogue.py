"""docs/errors.md lists every message vfem can stop with (issue 7).

Every module under ``src/vfem`` is parsed (nothing is imported or run) and each place that makes
a message for the user is found:

* ``InputError``, ``AnalysisError``, ``RindViolation``, ``VfemError`` and the private
  ``_Inverted`` (an ``AnalysisError``): their first argument;
* ``_Problem(where, message)`` of the input-file reader and the wedge example's
  ``need(ok, message)``: their second argument (both become an ``InputError``);
* ``raise ValueError/RuntimeError(...)``: the mesh shapes' parameter checks (shown as
  ``mesh shape '<shape>': ...``) and internal guards;
* ``SolveResult(False, ..., message)``: a contact solve that failed (shown through
  ``diagnosis()`` when the analysis stops);
* the text returned by ``diagnosis()``, ``fixed_point_message()`` and ``_platen_off()``
  (solver.py) and by ``CycleWatch`` (contact/formulations/algorithm.py), and what the CLI prints on
  stderr.

From each message the first literal fragment of at least 12 characters (ends trimmed of spaces
and punctuation, whitespace normalised) must occur in ``docs/errors.md``; a message with no
fragment that long is checked by its longest one if that has at least 8. A message without
either is a wrapper of another message (``f"{path}: {exc}"``): those are listed in
:data:`WRAPPERS` with the reason, and a wrapper that is no longer in the code must leave the
list too.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "vfem"
#: the packages beside the library whose messages the user reads too (module names relative to
#: ``src``): the built-in examples and the tools
BESIDE = ("vfem_examples", "vfem_tools")
CATALOGUE = ROOT / "docs" / "errors.md"

#: call -> index of the argument holding the message
MESSAGE_ARGUMENT = {"failure": 0, "InputError": 0, "AnalysisError": 0, "RindViolation": 0,
                    "VfemError": 0, "_Inverted": 0, "_Problem": 1, "need": 1, "ContactCycling": 0,
                    "ContactNotConverged": 0, "ElementInverted": 0, "NewtonNotConverged": 0,
                    "PlatenUnheld": 0, "PlatenUnpaired": 0, "SingularSystem": 0,
                    "ActiveSetNotSettled": 0, "PlatenOffForce": 0}
#: exceptions whose message counts only where they are raised (they are common names)
RAISED = {"ValueError", "RuntimeError"}
#: functions whose every string is user-facing text (module relative to src/vfem, name):
#: the stop message and its remedies, and CycleWatch.__call__'s message
MESSAGE_FUNCTIONS = {("solver.py", "diagnosis"), ("contact/state.py", "__call__"),
                     ("solver.py", "fixed_point_message"), ("solver.py", "_platen_off")}

FRAGMENT = 12  # characters a fragment must have
SHORT_FRAGMENT = 8  # ... or, failing that, the longest fragment of the message

#: messages with no fragment of their own, (module, message source as written) -> why
_WRAPPERS_AS_WRITTEN = {
    ("cli/run.py", 'f"{path}{changes}: {exc}"'):
        "vfem check/run prefix the input file's path (and its --set changes) to a model error "
        "(catalogued at its source)",
    ("cli/commands.py", 'f"vfem: {why}"'):
        "vfem plot: the line vfem.io.replot.unfinished_example makes on an example's unfinished "
        "run (catalogued under 'Results directories and vfem plot')",
    ("config.py", 'f"body {self.name!r}: {exc}"'):
        "names the body in front of a mesh error (mesh shape, mesh file, mesh.curve)",
    ("io/input.py", 'f"{source}: {exc}"'):
        "names the input file in front of a _Problem message (catalogued at each _Problem)",
    ("io/input.py", "message"):
        "_Problem(where, str(exc)): a configuration class whose constructor refuses its values "
        "(the shape-parameter checks of config.py, catalogued where they raise)",
    ("vfem_examples/wedge.py", 'f"wedge: {message}"'):
        "prefixes 'wedge: ' to the need(...) messages of wedge.validate (catalogued there)",
    ("vfem_examples/wedge.py", 'f"wedge: {exc}"'):
        "prefixes 'wedge: ' to a mesh shape's ValueError (catalogued in mesh/shapes.py)",
    ("solver.py", "message"):
        "failure(message): a failed contact solve's SolveResult message (with the platen's "
        "clause where it ends off its force, _platen_off), raised as its failure kind",
    ("contact/solvers/iteration.py", "cycling"):
        "SolveResult(False, ..., cycling): the CycleWatch message (catalogued from CycleWatch)",
    ("contact/solvers/iteration.py", "c.unconverged()"):
        "SolveResult(False, ..., c.unconverged()): each formulation's 'no convergence in' "
        "message, made by its check (catalogued as 'no convergence in')",
    ("contact/formulations/baselines.py", "str(exc)"):
        "SingularSystem(str(exc)): the linear solver's factorization failure "
        "(catalogued at vfem.linalg.factorize)",
}


def _source(text: str) -> str:
    """Python source as ``ast.unparse`` writes it (so quotes and spacing do not matter)."""
    return ast.unparse(ast.parse(text, mode="eval"))


#: the same, keyed by the source as ``ast.unparse`` writes it
WRAPPERS = {(module, _source(text)): why for (module, text), why in _WRAPPERS_AS_WRITTEN.items()}


def normalise(text: str) -> str:
    return re.sub(r"\s+", " ", text)


def _pieces(node: ast.AST) -> list[list[str | None]]:
    """The alternatives a message expression can produce, each a list of its literal parts
    (None for a formatted part). Concatenations are flattened; a conditional at the top gives
    one alternative per branch, one inside a concatenation is a formatted part."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [[node.value]]
    if isinstance(node, ast.JoinedStr):
        return [[v.value if isinstance(v, ast.Constant) else None for v in node.values]]
    if isinstance(node, ast.IfExp):
        return _pieces(node.body) + _pieces(node.orelse)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _pieces(node.left), _pieces(node.right)
        return [_merge([*(left[0] if len(left) == 1 else [None]),
                        *(right[0] if len(right) == 1 else [None])])]
    return [[None]]


def _merge(parts: list[str | None]) -> list[str | None]:
    """Adjacent literal parts joined (``"a" + "b"`` is one literal)."""
    out: list[str | None] = []
    for p in parts:
        if p is not None and out and out[-1] is not None:
            out[-1] += p
        else:
            out.append(p)
    return out


def _trim(text: str) -> str:
    return normalise(text).strip(" :;,.(")


def fragment(parts: list[str | None]) -> str | None:
    """The first literal part of at least FRAGMENT characters, else the longest if it has
    SHORT_FRAGMENT, else None (a wrapper)."""
    texts = [_trim(p) for p in parts if p is not None]
    for t in texts:
        if len(t) >= FRAGMENT:
            return t
    longest = max(texts, key=len, default="")
    return longest if len(longest) >= SHORT_FRAGMENT else None


def _name(func: ast.AST) -> str | None:
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        return func.attr
    return None


def _is_stderr_print(call: ast.Call) -> bool:
    return _name(call.func) == "print" and any(
        k.arg == "file" and ast.unparse(k.value) == "sys.stderr" for k in call.keywords)


def _function_strings(module: str, func: ast.FunctionDef):
    """The strings of a message function with a fragment (not its docstring, not the parts
    of an f-string, which is taken whole, nor short words such as ``"cycles"``)."""
    inner = {id(v) for n in ast.walk(func) if isinstance(n, ast.JoinedStr) for v in n.values}
    inner |= {id(n.format_spec) for n in ast.walk(func)
              if isinstance(n, ast.FormattedValue) and n.format_spec is not None}
    body = func.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        inner.add(id(body[0].value))  # the docstring
    for sub in ast.walk(func):
        if id(sub) in inner:
            continue
        if isinstance(sub, ast.JoinedStr) or (isinstance(sub, ast.Constant)
                                              and isinstance(sub.value, str)):
            text = fragment(_pieces(sub)[0])
            if text is not None and len(text) >= FRAGMENT:
                yield module, sub.lineno, sub


def message_sites():
    """(module, line, message expression) of every message (see the module docstring)."""
    paths = [(path, path.relative_to(SRC).as_posix()) for path in sorted(SRC.rglob("*.py"))]
    paths += [(path, path.relative_to(SRC.parent).as_posix()) for package in BESIDE
              for path in sorted((SRC.parent / package).rglob("*.py"))]
    for path, module in paths:
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        raised = {id(n.exc) for n in ast.walk(tree) if isinstance(n, ast.Raise) and n.exc}
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and (
                    module, node.name) in MESSAGE_FUNCTIONS:
                yield from _function_strings(module, node)
            if not isinstance(node, ast.Call):
                continue
            name = _name(node.func)
            index = MESSAGE_ARGUMENT.get(name)
            if name in RAISED and id(node) in raised:
                index = 0
            if name == "SolveResult" and node.args and isinstance(node.args[0], ast.Constant) \
                    and node.args[0].value is False:
                message = [k.value for k in node.keywords if k.arg == "message"]
                if len(node.args) > 4:
                    yield module, node.lineno, node.args[4]
                elif message:
                    yield module, node.lineno, message[0]
                continue
            if module.startswith("cli/") and _is_stderr_print(node) and node.args:
                yield module, node.lineno, node.args[0]
                continue
            if index is not None and len(node.args) > index:
                yield module, node.lineno, node.args[index]


@pytest.fixture(scope="module")
def sites() -> list:
    """Every message site, scanned once when a test asks (not at collection: the scan parses
    every module of the package, seconds that each worker would spend before any test)."""
    return list(message_sites())


def test_the_scan_finds_the_messages(sites):
    """A guard on the scan itself: the catalogue test below is only as good as what it sees."""
    assert len(sites) > 150
    modules = {m for m, _, _ in sites}
    assert {"cli/run.py", "config.py", "solver.py", "bodies/validation.py", "io/input.py",
            "mesh/imports.py", "mesh/shapes.py", "contact/formulations/paired.py",
            "nonlinear.py", "vfem_examples/wedge.py"} <= modules


def test_every_message_is_in_the_catalogue(sites):
    catalogue = normalise(CATALOGUE.read_text(encoding="utf-8"))
    missing, wrappers_seen = [], set()
    for module, line, expr in sites:
        source = ast.unparse(expr)
        for parts in _pieces(expr):
            text = fragment(parts)
            if text is None:
                key = (module, source)
                if key in WRAPPERS:
                    wrappers_seen.add(key)
                    continue
                missing.append(f"src/vfem/{module}:{line}: the message {source} has no literal "
                               f"fragment of {SHORT_FRAGMENT}+ characters; give it one, or list "
                               "it in WRAPPERS with the reason")
            elif text not in catalogue:
                missing.append(f"src/vfem/{module}:{line}: {text!r} is not in docs/errors.md")
    stale = sorted(set(WRAPPERS) - wrappers_seen)
    assert not missing, "add to docs/errors.md (cause and remedy):\n" + "\n".join(missing)
    assert not stale, f"WRAPPERS lists messages no longer in the code: {stale}"


@pytest.mark.parametrize(("expr", "expected"), [
    ('f"{where}: order must be 1 or 2, got {order!r}"', "order must be 1 or 2, got"),
    ('f"expected {len(args)} values, got {len(value)}"', "values, got"),
    ('f"{path}: {exc}"', None),
    ('"a" + f" constant part {x} here"', "a constant part"),
])
def test_fragment(expr, expected):
    assert fragment(_pieces(ast.parse(expr, mode="eval").body)[0]) == expected
