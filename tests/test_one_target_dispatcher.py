"""One target dispatcher: only ``pendverify.targets`` turns a model, a URDF and parameters into targets.

``check`` (CLI and API), ``certify``, ``mutate``, the scenes' Pinocchio side and the diagnosis
benchmark choose what to verify through ``pendverify.targets`` (``select_targets`` and the
builders it calls), so the same arguments mean the same pair everywhere and a mistake gets one
sentence.  The test reads every module's syntax tree outside ``verify/targets.py`` and lists:

* the dispatcher's error sentences (a string literal holding one of ``SENTENCES``, or the
  name ``PARAMS_HINT``): written a second time, they drift apart;
* a function that both reads parameters (``READERS``) and builds a Pinocchio system from a
  description (``BUILDERS``): a target made by hand beside the dispatcher;
* a function that calls two or more of the dispatcher's builders (``TARGET_BUILDERS``): a
  second dispatcher choosing between them.

Docstrings (examples of usage) are not code and are skipped.
"""

from __future__ import annotations

import ast
from pathlib import Path

from tests.source_scan import docstring_ids

REPO = Path(__file__).resolve().parents[1]
HOME = "verify/targets.py"
SCANNED = ("verify", "viz")
SENTENCES = ("give the parameter set", "the URDF to verify", "the URDF to certify", "name the model (")
READERS = {"parameter_values", "plugin_parameters", "load_parameter_file"}
BUILDERS = {"for_model", "for_params", "from_urdf"}
TARGET_BUILDERS = {"default_target", "model_target", "params_target", "erd_target", "plugin_target"}


def _called(node: ast.AST) -> set[str]:
    names = set()
    for call in ast.walk(node):
        if isinstance(call, ast.Call):
            f = call.func
            names.add(f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", ""))
    return names


def second_dispatchers(source: str) -> list[str]:
    """What in one module's source chooses targets beside ``pendverify.targets`` (module docstring)."""
    tree = ast.parse(source)
    docstrings = docstring_ids(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            found += [f"line {node.lineno}: the sentence {s!r}" for s in SENTENCES if s in node.value]
        elif isinstance(node, ast.Name | ast.alias) and "PARAMS_HINT" in {
            getattr(node, "id", None),
            node.__dict__.get("name"),
        }:
            found.append(f"line {getattr(node, 'lineno', '?')}: PARAMS_HINT")
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            called = _called(node)
            if called & READERS and called & BUILDERS:
                found.append(f"line {node.lineno}: {node.name} reads parameters and builds a system")
            if len(called & TARGET_BUILDERS) >= 2:
                found.append(
                    f"line {node.lineno}: {node.name} chooses between {sorted(called & TARGET_BUILDERS)}"
                )
    return found


def test_second_dispatchers_are_found_in_a_planted_module():
    planted = '''
from pendverify.targets import PARAMS_HINT, default_target, plugin_target

def certification_input(params_file, urdf, model):
    """Mentions "give the parameter set" in a docstring: not code."""
    if urdf is None:
        raise ValueError(f"{model}: give the URDF to certify {model} against")
    params = load_parameter_file(params_file)
    return PinocchioSystem.from_urdf(model, urdf).geometry.params

def _model_targets(model, urdf, params):
    return [default_target(model)] if urdf is None else [plugin_target(model, urdf, params)]
'''
    found = sorted(second_dispatchers(planted), key=lambda f: int(f.split()[1].rstrip(":")))
    assert [f.split(": ", 1)[1] for f in found] == [
        "PARAMS_HINT",
        "certification_input reads parameters and builds a system",
        "the sentence 'the URDF to certify'",
        "_model_targets chooses between ['default_target', 'plugin_target']",
    ], found


def test_targets_are_chosen_in_one_module():
    found = []
    for folder in SCANNED:
        for path in sorted((REPO / folder).rglob("*.py")):
            rel = path.relative_to(REPO).as_posix()
            if rel != HOME:
                found += [f"{rel}, {where}" for where in second_dispatchers(path.read_text(encoding="utf-8"))]
    assert not found, "target selection outside pendverify.targets:\n" + "\n".join(found)
