"""The type stubs (safecass/__init__.pyi) name every public class, function and method of the
module, and nothing it does not have."""

import ast
import inspect
from pathlib import Path

import safecass

STUB = Path(safecass.__file__).with_name("__init__.pyi")


def stub_tree():
    classes, functions = {}, set()
    for node in ast.parse(STUB.read_text()).body:
        if isinstance(node, ast.ClassDef):
            members = set()
            for item in node.body:
                if isinstance(item, (ast.FunctionDef, ast.AnnAssign)):
                    members.add(item.name if isinstance(item, ast.FunctionDef) else item.target.id)
            bases = [b.id for b in node.bases if isinstance(b, ast.Name)]
            classes[node.name] = (members, bases)
        elif isinstance(node, ast.FunctionDef):
            functions.add(node.name)
    return classes, functions


def members_of(classes, name):
    members, bases = classes[name]
    for base in bases:
        if base in classes:
            members = members | members_of(classes, base)
    return members


def public(obj):
    return {n for n in dir(obj) if not n.startswith("_")}


def test_every_public_name_of_the_module_is_in_the_stubs():
    classes, functions = stub_tree()
    for name in safecass.__all__:
        assert name in classes or name in functions, f"{name} is not in {STUB.name}"


def test_every_public_member_of_each_class_is_in_its_stub_and_no_more():
    classes, _ = stub_tree()
    for name in safecass.__all__:
        obj = getattr(safecass, name)
        if not inspect.isclass(obj) or issubclass(obj, BaseException) or name == "Result":
            continue
        have = public(obj)
        if obj.__module__ == "safecass":  # a Python class: its instance attributes are set in __init__
            source = inspect.getsource(obj)
            have |= {m for m in members_of(classes, name) if f"self.{m} " in source or f"self.{m}:" in source}
        stubbed = {m for m in members_of(classes, name) if not m.startswith("_")}
        assert have - stubbed == set(), f"{name}: not in the stubs: {sorted(have - stubbed)}"
        assert stubbed - have == set(), f"{name}: in the stubs, not in the module: {sorted(stubbed - have)}"


def test_the_stubs_parse_and_every_function_has_a_docstring():
    _, functions = stub_tree()
    for name in functions:
        assert getattr(safecass, name).__doc__, f"{name} has no docstring"
