"""The public API is documented: type stubs name everything the module exports, with the same
keyword defaults, and every public function, class and method has a docstring."""

import ast
import inspect
import pathlib
import re

import clod
import clod._clod as core


def stub_tree():
    return ast.parse((pathlib.Path(core.__file__).parent / "_clod.pyi").read_text())


def test_stubs_name_every_export_and_nothing_else():
    tree = stub_tree()
    stubbed = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            stubbed.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            stubbed.add(node.target.id)
    exported = {name for name in dir(core) if not name.startswith("__")}
    helpers = {"ArrayLike", "F64", "U32", "Pose", "__version__"}
    assert exported == stubbed - helpers


def test_stub_defaults_match_the_module_signatures():
    # pybind11 writes each overload's signature as the docstring's first line: compare keyword
    # defaults of the functions and constructors with the stubs' (an independent text).
    def defaults_in_signature(doc):
        line = doc.strip().splitlines()[0]
        return {m.group(1): m.group(2) for m in re.finditer(r"(\w+): [\w.\[\], ]+ = ([^,)]+)", line)}

    tree = stub_tree()
    stubs = {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}
    for name in ("bake", "query", "query_batch"):
        actual = defaults_in_signature(getattr(core, name).__doc__)
        node = stubs[name]
        declared = {a.arg: d for a, d in zip(node.args.kwonlyargs, node.args.kw_defaults) if d is not None}
        for arg, default in declared.items():
            value = ast.literal_eval(default)
            shown = actual[arg].strip("'")
            assert shown == str(value) or (value is None and shown == "None") or float(shown) == value, (name, arg)


def test_everything_public_has_a_docstring():
    missing = []
    for name in clod.__all__:
        obj = getattr(clod, name)
        if inspect.isclass(obj) or callable(obj):
            if not (obj.__doc__ or "").strip():
                missing.append(name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attr, member in vars(obj).items():
                if attr.startswith("_") or not (callable(member) or isinstance(member, property)):
                    continue
                if not (getattr(member, "__doc__", "") or "").strip():
                    missing.append(f"{name}.{attr}")
    assert not missing
    for function in (clod.batch.bake_all, clod.batch.sweep, clod.experiment):
        assert len(function.__doc__) > 200
