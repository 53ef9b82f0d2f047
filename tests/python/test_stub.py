"""The type stub crates/ot-py/nanohaptics.pyi lists exactly what the module exports."""

import ast
import inspect
from pathlib import Path

import nanohaptics as nh

STUB = Path(__file__).resolve().parents[2] / "crates" / "ot-py" / "nanohaptics.pyi"
ALIASES = {"ArrayLike", "F64Array", "Method", "ThermalScheme", "NanoParams", "Member", "Target", "Buttons", "PathLike"}


def _stub():
    tree = ast.parse(STUB.read_text(encoding="utf-8"))
    names = {}
    for n in tree.body:
        if isinstance(n, (ast.FunctionDef, ast.ClassDef)):
            names[n.name] = n
        elif isinstance(n, ast.AnnAssign):
            names[n.target.id] = n
    return names


def _params(fn):
    a = fn.args
    return [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs if x.arg != "self"]


def test_stub_and_module_export_the_same_names():
    stub = _stub()
    exported = {k for k in dir(nh) if not k.startswith("_")} - {"nanohaptics"}
    assert exported == set(stub) - ALIASES - {"__version__"}
    for cls in ("GaussianTrap", "NanoWorld", "BrickWorld", "Session", "DeviceModel"):
        members = {k for k in dir(getattr(nh, cls)) if not k.startswith("_")}
        in_stub = {n.name for n in stub[cls].body if isinstance(n, ast.FunctionDef)} - {"__init__"}
        assert members == in_stub, cls


def test_stub_signatures_match_the_module():
    stub = _stub()
    for name, node in stub.items():
        if isinstance(node, ast.FunctionDef):
            assert _params(node) == list(inspect.signature(getattr(nh, name)).parameters), name
    for cls in ("GaussianTrap", "NanoWorld", "BrickWorld", "Session", "DeviceModel"):
        for node in stub[cls].body:
            if not isinstance(node, ast.FunctionDef) or any(
                isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list
            ):
                continue
            obj = getattr(nh, cls) if node.name == "__init__" else getattr(getattr(nh, cls), node.name)
            sig = [p for p in inspect.signature(obj).parameters if p != "self"]
            assert _params(node) == sig, f"{cls}.{node.name}"
