"""``help()`` shows real signatures and docs for every public callable of the package.

Walks every public function, class and method of ``tvmd``, ``tvmd.sim`` and ``tvmd.gym`` and
checks that its docstring is there and not a pointer elsewhere ("See the stub"), that
``inspect.signature`` works (what ``help()``, Jupyter and IDEs show), and, where a ``.pyi`` stub
declares it, that the parameters (names, kinds, and defaults the stub gives as literals) are
the stub's. The docstrings of the callables the stubs document at length are the stubs' own
(``scripts/stub_docs.py`` writes them for the Rust side; see ``test_docstrings_are_the_stubs``).
"""

from __future__ import annotations

import ast
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

import tvmd
import tvmd.sim

gym = pytest.importorskip("tvmd.gym")

PACKAGE = Path(tvmd.__file__).parent
STUB_OF = {"tvmd": "_tvmd.pyi", "tvmd.sim": "sim.pyi"}
PLACEHOLDER = re.compile(r"see the stub|for arguments|\bsim\.pyi\b|\bTODO\b", re.IGNORECASE)
KINDS = {
    "posonlyargs": inspect.Parameter.POSITIONAL_ONLY,
    "args": inspect.Parameter.POSITIONAL_OR_KEYWORD,
    "kwonlyargs": inspect.Parameter.KEYWORD_ONLY,
}


def stub_tree(module_name):
    """``{qualname: [FunctionDef or ClassDef, ...]}`` of a module's stub (overloads in a list)."""
    tree = ast.parse((PACKAGE / STUB_OF[module_name]).read_text())
    found = {}

    def visit(body, prefix):
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                found.setdefault(prefix + node.name, []).append(node)
                if isinstance(node, ast.ClassDef):
                    visit(node.body, f"{prefix}{node.name}.")

    visit(tree.body, "")
    return found


STUBS = {name: stub_tree(name) for name in STUB_OF}


def public_callables():
    """``(module name, qualname, object)`` of every public function, class and method."""
    items = []
    for module in (tvmd, tvmd.sim, gym):
        names = getattr(module, "__all__", None) or [n for n in dir(module) if not n.startswith("_")]
        for name in names:
            obj = getattr(module, name)
            if inspect.ismodule(obj) or not callable(obj):
                continue
            items.append((module.__name__, name, obj))
            if inspect.isclass(obj) and not issubclass(obj, BaseException):
                for attr, value in vars(obj).items():
                    if attr.startswith("_") or isinstance(value, property) or inspect.isgetsetdescriptor(value):
                        continue
                    method = getattr(obj, attr)
                    if callable(method) and not inspect.isclass(method):
                        items.append((module.__name__, f"{name}.{attr}", method))
    return items


CALLABLES = public_callables()
IDS = [f"{m}.{q}" for m, q, _ in CALLABLES]


def test_the_walk_sees_the_package():
    # The walk is not vacuous: the package's main callables and their methods are in it.
    for expected in ("tvmd.Team", "tvmd.Team.wrench", "tvmd.Controller.step", "tvmd.allocate",
                     "tvmd.sim.run", "tvmd.sim.load", "tvmd.sim.Simulation.step_wrench",
                     "tvmd.sim.SimResult.to_pandas", "tvmd.sim.monte_carlo", "tvmd.gym.TeamEnv.step"):  # fmt: skip
        assert expected in IDS, expected
    assert len(CALLABLES) > 80


@pytest.mark.parametrize(("module", "qualname", "obj"), CALLABLES, ids=IDS)
def test_docstring_is_real(module, qualname, obj):
    doc = inspect.getdoc(obj)
    assert doc and len(doc) > 15, f"{module}.{qualname} has no docstring"
    assert not PLACEHOLDER.search(doc), f"{module}.{qualname}: {doc[:200]!r}"


def stub_params(node):
    """``[(name, kind, default node or None)]`` of a stub function, without ``self``/``cls``."""
    a = node.args
    positional = [(p, KINDS["posonlyargs"]) for p in a.posonlyargs] + [(p, KINDS["args"]) for p in a.args]
    defaults = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    params = [(p.arg, kind, d) for (p, kind), d in zip(positional, defaults)]
    if a.vararg:
        params.append((a.vararg.arg, inspect.Parameter.VAR_POSITIONAL, None))
    params += [(p.arg, KINDS["kwonlyargs"], d) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    if a.kwarg:
        params.append((a.kwarg.arg, inspect.Parameter.VAR_KEYWORD, None))
    decorators = {getattr(d, "id", getattr(d, "attr", None)) for d in node.decorator_list}
    if params and "staticmethod" not in decorators and params[0][0] in ("self", "cls"):
        params = params[1:]
    return params


def literal(node):
    """The value of a literal default, or ``...`` for anything else (not compared)."""
    if node is None:
        return ...
    try:
        value = ast.literal_eval(node)
    except ValueError:
        return ...
    return value


def tvmd_module(name):
    return {"tvmd": tvmd, "tvmd.sim": tvmd.sim, "tvmd.gym": gym}[name]


def stub_functions(module, qualname, obj):
    """The stub's declarations of ``obj`` (its ``__init__``/``__new__`` for a class)."""
    stubs = STUBS.get(module)
    if stubs is None:
        return None
    if inspect.isclass(obj):
        for init in ("__init__", "__new__"):
            if f"{qualname}.{init}" in stubs:
                return stubs[f"{qualname}.{init}"]
        return None
    return stubs.get(qualname)


@pytest.mark.parametrize(("module", "qualname", "obj"), CALLABLES, ids=IDS)
def test_signature_matches_the_stub(module, qualname, obj):
    if inspect.isclass(obj) and issubclass(obj, BaseException):
        pytest.skip("exceptions take the message only")
    stubs = stub_functions(module, qualname, obj)
    if inspect.isclass(obj) and stubs is None and module in STUBS:
        # A result type the package builds (no constructor in the stub): not callable from Python.
        with pytest.raises(TypeError):
            obj()
        return
    signature = inspect.signature(obj)
    if "." in qualname and not inspect.isclass(obj):
        # An unbound method: its receiver comes first (not in the stub).
        params = list(signature.parameters.values())
        if params and params[0].name in ("self", "$self", "cls", "$cls") and not isinstance(
            inspect.getattr_static(getattr(tvmd_module(module), qualname.split(".")[0]), qualname.split(".")[1]),
            staticmethod,
        ):
            signature = signature.replace(parameters=params[1:])
    if stubs is None:
        # Declared in Python without a stub (tvmd.gym), or a class built by a factory only.
        assert module == "tvmd.gym" or inspect.isclass(obj), f"{module}.{qualname} is not in the stub"
        return
    runtime = [(p.name, p.kind) for p in signature.parameters.values()]
    overloads = [stub_params(node) for node in stubs]
    assert any(runtime == [(n, k) for n, k, _ in params] for params in overloads), (
        f"{module}.{qualname}{signature} against the stub's {[[(n, k.name) for n, k, _ in p] for p in overloads]}"
    )
    if len(overloads) == 1:
        for (name, _, default), p in zip(overloads[0], signature.parameters.values()):
            expected = literal(default)
            if expected is not ...:
                assert p.default == expected and type(p.default) is type(expected), (
                    f"{module}.{qualname}: `{name}` defaults to {p.default!r}, the stub says {expected!r}"
                )


REPO = Path(__file__).resolve().parents[3]
DOCSTRINGS = REPO / "crates" / "tvmd-py" / "docstrings"


def test_the_docstring_files_are_the_stubs():
    # scripts/stub_docs.py --check: every file a Rust callable includes is its stub docstring,
    # and no file is left over.
    result = subprocess.run([sys.executable, str(REPO / "scripts" / "stub_docs.py"), "--check"],
                            capture_output=True, text=True, check=False)  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr


def public(name):
    """The object of a public name (``tvmd.Team.wrench``, ``tvmd.sim.run``)."""
    prefix = "tvmd.sim." if name.startswith("tvmd.sim.") else "tvmd."
    obj = tvmd.sim if prefix == "tvmd.sim." else tvmd
    for part in name[len(prefix) :].split("."):
        obj = getattr(obj, part)
    return obj


DOC_FILES = sorted(DOCSTRINGS.glob("*.txt"))


def test_every_placeholder_was_replaced_by_a_stub_docstring():
    assert len(DOC_FILES) >= 38


@pytest.mark.parametrize("path", DOC_FILES, ids=lambda p: p.stem)
def test_docstrings_are_the_stubs(path):
    # The built module shows the stub's docstring (help() strips the signature line).
    obj = public(path.stem)
    assert inspect.getdoc(obj) == inspect.cleandoc(path.read_text()), path.stem


@pytest.mark.parametrize("name", ["monte_carlo", "run_many", "relaxation_sweep"])
def test_python_functions_show_the_stub_docstrings(name):
    stub = stub_tree("tvmd.sim")[name]
    longest = max((ast.get_docstring(n) or "" for n in stub), key=len)
    assert inspect.getdoc(getattr(tvmd.sim, name)) == longest
