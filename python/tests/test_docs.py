"""The run-time docs say what the type stubs say: every documented function, method, property and
class of fairmesh/__init__.pyi has that docstring and (functions, methods) that signature in
`help()`, and every keyword the stubs name is taken, with the stubs' default meaning what
leaving it out means. The report dicts have the keys their TypedDicts name."""

import ast
import inspect
import typing
from pathlib import Path

import numpy as np
import pytest

import fairmesh
from conftest import REPOSITORY

STUBS = REPOSITORY / "python" / "fairmesh" / "__init__.pyi"
MUSHROOM = REPOSITORY / "tests" / "data" / "mushroom_open.obj"


def stub_definitions():
    """(qualified name, node) of every def and class of the stubs with a docstring; the
    parameters of a def are those of its documented overload, with the defaults any overload
    gives."""
    tree = ast.parse(STUBS.read_text())
    found = {}
    defaults = {}

    def visit(node, prefix):
        if isinstance(node, ast.ClassDef):
            if ast.get_docstring(node) is not None:
                found[prefix + node.name] = node
            for child in node.body:
                visit(child, prefix + node.name + ".")
        elif isinstance(node, ast.FunctionDef):
            key = prefix + node.name
            arguments = node.args
            positional = arguments.posonlyargs + arguments.args
            for argument, default in zip(positional[::-1], arguments.defaults[::-1]):
                defaults.setdefault(key, {})[argument.arg] = ast.literal_eval(default)
            for argument, default in zip(arguments.kwonlyargs, arguments.kw_defaults):
                if default is not None:
                    defaults.setdefault(key, {})[argument.arg] = ast.literal_eval(default)
            if ast.get_docstring(node) is not None:
                found[key] = node

    for node in tree.body:
        visit(node, "")
    return found, defaults


DEFINITIONS, DEFAULTS = stub_definitions()


def runtime(key):
    target = fairmesh
    for part in key.split("."):
        target = getattr(target, part) if not isinstance(target, type) else \
            target.__dict__[part]
    return target


def expected_parameters(key, node):
    arguments = node.args
    kinds = [(a, inspect.Parameter.POSITIONAL_OR_KEYWORD) for a in arguments.args] + \
        [(a, inspect.Parameter.KEYWORD_ONLY) for a in arguments.kwonlyargs]
    result = []
    for argument, kind in kinds:
        default = DEFAULTS.get(key, {}).get(argument.arg, inspect.Parameter.empty)
        result.append((argument.arg, kind, default))
    return result


def test_every_stub_with_a_docstring_is_found():
    # The functions, the two classes' methods and properties: a stubs file the parse misread
    # would give fewer.
    for key in ("fair", "noise", "compare", "hierarchy", "load", "save", "Mesh", "Mesh.save",
                "Mesh.vertices", "Hierarchy", "Hierarchy.multires", "Hierarchy.level"):
        assert key in DEFINITIONS, key
    assert len(DEFINITIONS) >= 25


@pytest.mark.parametrize("key", sorted(DEFINITIONS))
def test_the_run_time_doc_is_the_stubs(key):
    node = DEFINITIONS[key]
    target = runtime(key)
    assert inspect.cleandoc(target.__doc__) == ast.get_docstring(node)
    if isinstance(node, ast.FunctionDef) and not any(
            isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list):
        signature = inspect.signature(target)
        shown = [(p.name, p.kind, p.default) for p in signature.parameters.values()]
        expected = expected_parameters(key, node)
        if "." in key:  # a method: `self` (positional-only at run time) is left out
            expected = [p for p in expected if p[0] != "self"]
            shown = [p for p in shown if p[0] != "self"]
        assert shown == expected


def test_help_of_fair_lists_every_option():
    text = fairmesh.fair.__doc__
    signature = inspect.signature(fairmesh.fair)
    for name in signature.parameters:
        if name not in ("vertices", "faces"):
            assert f"``{name}``" in text, name
    assert "crease_angle=40.0" in str(signature) and "Ellipsis" not in str(signature)
    parameters = inspect.signature(fairmesh.hierarchy).parameters
    for name in parameters:
        if name not in ("vertices", "faces"):
            assert f"``{name}``" in fairmesh.hierarchy.__doc__, name


@pytest.fixture(scope="module")
def small():
    mesh = fairmesh.load(MUSHROOM)
    noisy = fairmesh.noise(mesh.vertices, mesh.faces, sigma=0.3, seed=9)
    return noisy, mesh.faces


def keyword_defaults(key):
    node = DEFINITIONS[key]
    return {a.arg: DEFAULTS[key][a.arg] for a in node.args.kwonlyargs
            if a.arg in DEFAULTS.get(key, {})}


def same(a, b):
    if isinstance(a, tuple):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            same(x, y)
    elif isinstance(a, dict):
        assert set(a) == set(b)
        for k in a:
            if k not in ("time_ms", "detection_ms", "phases_ms"):
                same(a[k], b[k])
    else:
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("key", ["fair", "noise", "hierarchy", "Hierarchy.multires"])
def test_every_default_the_stubs_give_is_the_one_the_call_takes(key, small):
    # The signature help() shows comes from the stubs; the one the call takes is the
    # extension's own. Each keyword given the stubs' default gives what leaving it out gives.
    vertices, faces = small
    levels = fairmesh.hierarchy(vertices, faces)
    calls = {
        "fair": lambda **kw: fairmesh.fair(vertices, faces, rounds=2, **kw),
        "noise": lambda **kw: fairmesh.noise(vertices, faces, **kw),
        "hierarchy": lambda **kw: fairmesh.hierarchy(vertices, faces, **kw).level_sizes,
        "Hierarchy.multires": lambda **kw: levels.multires(3, **kw),
    }
    defaults = keyword_defaults(key)
    if key == "fair":
        defaults.pop("rounds")
    assert defaults
    plain = calls[key]()
    for name, default in defaults.items():
        same(calls[key](**{name: default}), plain)


def test_the_reports_have_the_keys_of_their_typed_dicts(small):
    vertices, faces = small

    def keys(typed):
        return typed.__required_keys__, typed.__optional_keys__

    required, optional = keys(fairmesh.FairReport)
    _, report = fairmesh.fair(vertices, faces, rounds=1)
    assert set(report) == required
    _, measured = fairmesh.fair(vertices, faces, rounds=1, measure=True)
    assert set(measured) == required | optional
    assert set(report["phases_ms"]) == set(typing.get_type_hints(fairmesh.FairPhases))
    required, optional = keys(fairmesh.CompareReport)
    mesh = fairmesh.load(MUSHROOM)
    compared = fairmesh.compare(mesh.vertices, mesh.faces, vertices)
    assert required <= set(compared) <= required | optional
    assert {"rms", "max_distance", "normal_error_deg", "barycenter_drift"} <= set(compared)
    levels = fairmesh.hierarchy(vertices, faces, denoise="auto")
    assert set(levels.denoise) == set(typing.get_type_hints(fairmesh.DenoiseReport))
