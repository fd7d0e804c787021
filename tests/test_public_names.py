"""The front door: what is public is ``pendverify.__all__``, ``pendverify.analytic.__all__`` and
``pendverify.api.__all__`` (with ``pendverify.testing``), and docs/reference/api.md says so.

* every name of each ``__all__`` imports, and ``dir(pendverify)`` is exactly ``pendverify.__all__``;
* the page's "What is public" section lists the same names as each ``__all__`` (``pendverify.api``'s:
  the members the page documents plus the argument types the section names);
* every other package of the distribution is internal: its ``__init__`` assigns an empty
  ``__all__`` (read with ``ast``), and the page names it among the internal sub-packages.
"""

from __future__ import annotations

import ast
import importlib
import re
import subprocess
import sys
import textwrap

import pytest

from tests.test_import_graph import REPO, installed_modules, package_names

PAGE = REPO / "docs" / "reference" / "api.md"
#: the namespaces whose ``__all__`` is public; every other package's is empty
PUBLIC = ("pendverify", "pendverify.analytic", "pendverify.api", "pendverify.testing")
#: packages that hold data, not code: not named in the page's sentence about sub-packages
DATA = ("pendverify.urdf", "pendverify.examples", "pendverify.scenes", "pendverify.sweeps")


def section(text: str) -> str:
    """The page's "What is public" section."""
    found = re.search(r"^## What is public\n(.*?)(?=^## |^::: )", text, re.S | re.M)
    assert found, f"{PAGE}: no '## What is public' section"
    return found.group(1)


def listed(text: str) -> dict[str, set[str]]:
    """{namespace: the names its bullet lists} from the section's ``- `namespace`: `a`, `b`` bullets
    (a bullet may continue on indented lines)."""
    bullets = re.findall(r"^- `([\w.]+)`:(.*(?:\n  .*)*)", section(text), re.M)
    return {name: set(re.findall(r"`([^`]+)`", rest)) for name, rest in bullets}


def documented_members(text: str, module: str) -> set[str]:
    """The ``members:`` the page gives mkdocstrings for ``::: module``."""
    block = re.search(rf"^::: {re.escape(module)}\n((?:    .*\n)+)", text, re.M)
    assert block, f"{PAGE}: no '::: {module}' block"
    return set(re.findall(r"^        - (\w+)$", block.group(1), re.M))


def assigned_all(path) -> list[str] | None:
    """The literal list a module assigns to ``__all__`` at its top level, or None."""
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets) and node.value is not None:
            return list(ast.literal_eval(node.value))
    return None


def mismatches(text: str, namespaces: dict[str, list[str]]) -> dict[str, tuple[set[str], set[str]]]:
    """{namespace: (in ``__all__`` but not listed, listed but not in ``__all__``)} where they differ."""
    bullets = listed(text)
    out = {}
    for name, names in namespaces.items():
        shown = bullets.get(name, set())
        if name == "pendverify.api":
            shown = shown | documented_members(text, name)
        if shown != set(names):
            out[name] = (set(names) - shown, shown - set(names))
    return out


@pytest.mark.parametrize("namespace", PUBLIC)
def test_every_public_name_imports(namespace):
    module = importlib.import_module(namespace)
    assert module.__all__, namespace
    for name in module.__all__:
        assert getattr(module, name) is not None, f"{namespace}.{name}"
        exec(f"from {namespace} import {name}", {})


def test_dir_of_the_front_door_is_its_all():
    script = "import pendverify; print(' '.join(dir(pendverify))); print(' '.join(pendverify.__all__))"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    shown, public = (line.split() for line in done.stdout.splitlines())
    assert shown == sorted(public)
    analytic = importlib.import_module("pendverify.analytic")
    assert set(analytic.__all__) <= set(dir(analytic))


def test_the_page_lists_the_same_names_as_each_all():
    namespaces = {name: importlib.import_module(name).__all__ for name in PUBLIC}
    assert mismatches(PAGE.read_text(encoding="utf-8"), namespaces) == {}


def test_a_name_missing_from_the_page_or_extra_on_it_is_found():
    text = textwrap.dedent(
        """\
        # API reference

        ## What is public

        - `pendverify`: `check`, `simulate`,
          `Run`
        - `pendverify.api`: `ModelLike`

        ::: pendverify.api
            options:
              members:
                - check
        """
    )
    assert (
        mismatches(
            text, {"pendverify": ["check", "simulate", "Run"], "pendverify.api": ["check", "ModelLike"]}
        )
        == {}
    )
    found = mismatches(
        text, {"pendverify": ["check", "Run", "load_model"], "pendverify.api": ["check", "sweep"]}
    )
    assert found == {
        "pendverify": ({"load_model"}, {"simulate"}),
        "pendverify.api": ({"sweep"}, {"ModelLike"}),
    }


def test_every_other_package_is_internal_and_says_so():
    modules = installed_modules()
    text = section(PAGE.read_text(encoding="utf-8"))
    for package in package_names():
        if package in PUBLIC:
            continue
        assert assigned_all(modules[package]) == [], (
            f"{modules[package]}: an internal package assigns __all__ = []"
        )
        if package not in DATA:  # named by its first level: `pendverify.numerics` covers numerics.codegen
            first = package.split(".")[1]
            assert re.search(rf"`(pendverify\.)?{first}`", text), f"{PAGE} does not say {package} is internal"


def test_a_missing_or_non_empty_all_is_found(tmp_path):
    cases = {
        "none.py": "x = 1\n",
        "full.py": "__all__ = ['x']\nx = 1\n",
        "empty.py": "__all__: list[str] = []\n",
    }
    found = {}
    for name, source in cases.items():
        (tmp_path / name).write_text(source)
        found[name] = assigned_all(tmp_path / name)
    assert found == {"none.py": None, "full.py": ["x"], "empty.py": []}
