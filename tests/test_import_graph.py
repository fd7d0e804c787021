"""The installed package ``pendverify`` imports without cycles, its code reads no bytecode or frames,
and every command reaches the library through ``pendverify.api`` alone.

The import graph is read from the source files with ``ast``, nothing is imported to
build it: every ``import`` and ``from … import`` of a pendverify module counts, at
module level or inside a function, except those under ``if TYPE_CHECKING:`` (type
annotations only).  ``from pkg import name`` imports the submodule ``pkg.name`` when
there is one, else ``pkg`` itself; ``import a.b.c`` imports ``a.b.c`` (the nearest
module that exists).  A cycle is a strongly connected component of more than one
module.  The modules are those of every package pyproject.toml lists, each found where
it is installed (``importlib.util.find_spec``: the package-dir mapping puts
``pendverify.analytic`` in analytic/, ``pendverify`` in verify/, ...).

The front door (``pendverify.commands``' rule): a command module imports ``pendverify.api``,
the commands' own helpers and, by name, what ``COMMAND_MAY_IMPORT`` lists — formatters, the
command line's contract (output paths, errors, exit statuses) and the light rules its options
are parsed with before ``func`` runs; any other import of pendverify is a door past the API.
"""

from __future__ import annotations

import ast
import importlib.util
import sys
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

REPO = Path(__file__).resolve().parents[1]

#: what code that reads bytecode or the call stack contains
INTROSPECTION = ("_getframe", "co_code", "dis.", "__code__", "f_back")


def package_names() -> list[str]:
    """The packages of the distribution, as pyproject.toml lists them."""
    data = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))
    return list(data["tool"]["setuptools"]["packages"])


def installed_modules() -> dict[str, Path]:
    """{dotted module name: its source file} for every module of every package, as installed."""
    modules = {}
    for package in package_names():
        spec = importlib.util.find_spec(package)
        assert spec is not None and spec.submodule_search_locations, f"{package} is not installed"
        for location in spec.submodule_search_locations:
            for path in sorted(Path(location).glob("*.py")):
                name = package if path.stem == "__init__" else f"{package}.{path.stem}"
                modules[name] = path
    return modules


def _type_checking_only(tree: ast.Module) -> set[int]:
    """The ids of the nodes under ``if TYPE_CHECKING:`` (its body, not its else)."""
    skipped = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            test = node.test
            name = test.id if isinstance(test, ast.Name) else getattr(test, "attr", "")
            if name == "TYPE_CHECKING":
                for statement in node.body:
                    skipped.update(id(n) for n in ast.walk(statement))
    return skipped


def imported_modules(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The modules among ``modules`` that module ``name`` (source file ``path``) imports."""

    def known(target: str) -> str | None:
        while target and target not in modules:
            target = target.rpartition(".")[0]
        return target or None

    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    skipped = _type_checking_only(tree)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        targets = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package
                for _ in range(node.level - 1):
                    parent = parent.rpartition(".")[0]
                base = f"{parent}.{base}" if base else parent
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
        for target in targets:
            module = known(target)
            if module is not None and module != name:
                found.add(module)
    return found


def import_graph(modules: dict[str, Path]) -> dict[str, set[str]]:
    return {name: imported_modules(name, path, modules) for name, path in modules.items()}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module, each sorted (Tarjan, iterative)."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            advanced = False
            for nxt in edges:
                if nxt not in graph:
                    continue
                if nxt not in index:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                    advanced = True
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return sorted(found)


# --- the finder itself ---------------------------------------------------------------------------
def test_the_finder_reports_a_planted_cycle_and_nothing_else():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a", "e"}, "e": set(), "f": {"f"}}
    assert cycles(graph) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
    assert cycles({"x": {"y"}, "y": {"x"}, "p": {"q"}, "q": {"r"}, "r": {"p", "x"}}) == [
        ["p", "q", "r"],
        ["x", "y"],
    ]


def test_the_graph_reads_deferred_and_submodule_imports_and_skips_type_checking_ones(tmp_path):
    sources = {
        "pkg/__init__.py": "",
        "pkg/low.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.high import High\n",
        "pkg/high.py": "def f():\n    from pkg import low\n    return low\n",
        "pkg/a.py": "from . import b\n",
        "pkg/b.py": "import pkg.a.missing_name\n",
    }
    modules = {}
    for relative, text in sources.items():
        path = tmp_path / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        stem = Path(relative).stem
        modules["pkg" if stem == "__init__" else f"pkg.{stem}"] = path
    graph = import_graph(modules)
    assert graph["pkg.high"] == {"pkg.low"}  # inside a function, and `from pkg import low` is the submodule
    assert graph["pkg.low"] == set()  # under TYPE_CHECKING: not an import at run time
    assert cycles(graph) == [["pkg.a", "pkg.b"]]  # a relative import and a dotted one close a cycle


# --- the package ------------------------------------------------------------------------------------
def test_every_package_is_found_where_it_is_installed():
    modules = installed_modules()
    for name in ("pendverify", "pendverify.analytic.interface", "pendverify.numerics.codegen.cache"):
        assert name in modules
    assert modules["pendverify.analytic.interface"].name == "interface.py"


def test_pendverify_imports_without_cycles():
    found = cycles(import_graph(installed_modules()))
    assert not found, "import cycles, each among the modules of one line:\n" + "\n".join(
        ", ".join(c) for c in found
    )


def test_no_code_reads_bytecode_or_frames():
    hits = []
    for folder in ("verify", "analytic", "viz"):
        for path in sorted((REPO / folder).rglob("*.py")):
            relative = path.relative_to(REPO).as_posix()
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                hits += [f"{relative}:{number}: {word}" for word in INTROSPECTION if word in line]
    assert not hits, "bytecode or frame introspection:\n" + "\n".join(hits)


# --- the front door ---------------------------------------------------------------------------------
#: what a command module may import of pendverify besides ``pendverify.api`` and ``pendverify.commands``:
#: {module: the names it may import from it}
COMMAND_MAY_IMPORT = {
    # the command line's contract: output paths checked and written atomically, errors, exit statuses
    "pendverify.atomic": {"STDOUT", "check_output", "check_report_output", "write_atomic"},
    "pendverify.errors": {
        "InputError",
        "OptionConflictError",
        "PendverifyError",
        "UnknownNameError",
        "missing_file",
    },
    "pendverify.exitcodes": {"BAD_INPUT", "TERMINATED"},
    # formatters: a result the API returned, as text, JSON, JUnit or a plot
    "pendverify.jsonio": {"to_json", "versions"},
    "pendverify.checks.report": {"text_table"},
    "pendverify.checks.junit": {"to_junit"},
    "pendverify.checks.evidence": {
        "invariant_record",
        "item_record",
        "item_verdict",
        "largest_abs",
        "stress_record",
        "stress_verdict",
    },
    "pendverify.bench.plot": {"render"},
    "pendverify.bench.report": {"fraction", "ratios", "to_csv", "to_markdown"},
    "pendverify.bench.explain_report": {"table"},
    "pendverify.bench.certify_report": {"table", "to_json"},
    "pendverify.bench.timing": {"cpu_model"},  # the machine, in the report's header
    "pendverify.symbolic.mutation_report": {"format_report"},
    "pendverify.symbolic.compare": {"format_report"},
    "pendverify.worked_examples": {"NAMES", "next_commands"},  # the names --help lists; what to type next
    "pendverify.file_kinds": {"KINDS"},  # the option a stray file belongs behind
    "pendverify.documents": {"file_kind"},  # the kind of a stray file
    # the rules options are parsed with (argparse types, defaults, names), light enough for --help
    "pendverify.analytic": {"MODELS"},
    "pendverify.simulation.limits": {"MAX_SAMPLES_VARIABLE", "max_samples"},
    "pendverify.simulation.engine_names": {"SCENE_ENGINE_CHOICES"},
    "pendverify.certify.settings_rules": {"samples_option", "seed_option"},
    "pendverify.certify.sweep_limits": {"DEFAULT_MAX_SETS", "WORKER_TIMEOUT_S"},
}


def doors_past_the_api(path: Path) -> list[str]:
    """The imports of pendverify in the command module ``path`` that neither go through
    ``pendverify.api`` nor are allowed by ``COMMAND_MAY_IMPORT``, as ``line: module.name``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            pairs = [(alias.name, "") for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            # relative: from the package pendverify.commands (level 1) or above it
            base = ".".join(["pendverify", "commands"][: max(0, 3 - node.level)]) if node.level else ""
            module = ".".join(part for part in (base, node.module or "") if part)
            pairs = [(module, alias.name) for alias in node.names]
        else:
            pairs = []
        for module, name in pairs:
            if module.split(".")[0] != "pendverify":
                continue
            through_api = (module, name) == ("pendverify", "api") or module == "pendverify.api"
            helpers = module == "pendverify.commands" or module.startswith("pendverify.commands.")
            if not (through_api or helpers or name in COMMAND_MAY_IMPORT.get(module, ())):
                found.append(f"{node.lineno}: {module}{'.' + name if name else ''}")
    return found


def test_the_front_door_check_finds_a_planted_import_past_the_api(tmp_path):
    command = tmp_path / "planted.py"
    command.write_text(
        "from pendverify.commands import add_command\n"
        "from pendverify.atomic import check_output\n"
        "def run(args):\n"
        "    from pendverify import api\n"
        "    from pendverify.certify.issue import issue\n"  # past the API
        "    from pendverify.jsonio import to_json, read_json\n"  # a formatter, and a reader
        "    import pendverify.stress.catalogue\n"  # past the API
        "    from pendverify import errors\n"  # a module by name: past the API
        "    from ..stress import catalogue\n"  # relative, past the API
        "    from . import simulate\n"  # a sibling command
    )
    assert doors_past_the_api(command) == [
        "5: pendverify.certify.issue.issue",
        "6: pendverify.jsonio.read_json",
        "7: pendverify.stress.catalogue",
        "8: pendverify.errors",
        "9: pendverify.stress.catalogue",
    ]


def test_every_command_goes_through_the_api():
    commands = Path(installed_modules()["pendverify.commands"])
    doors = [
        f"{path.name}:{door}"
        for path in sorted(commands.parent.glob("*.py"))
        for door in doors_past_the_api(path)
    ]
    assert not doors, "commands import the library past pendverify.api:\n" + "\n".join(doors)


def test_every_sub_package_is_installed():
    """pyproject lists the packages explicitly (the folders are mapped onto ``pendverify``):
    a sub-package missing there works in a checkout and is absent from a wheel."""
    config = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    roots = {folder: name for name, folder in config["package-dir"].items()}
    found = set()
    for folder, name in roots.items():
        for init in (REPO / folder).rglob("__init__.py"):
            rel = init.parent.relative_to(REPO / folder).parts
            found.add(".".join((name, *rel)))
    assert found == set(config["packages"]), found ^ set(config["packages"])
