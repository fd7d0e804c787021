"""The Python API in a notebook: every public result object is one short line and an HTML view,
``import pendverify`` holds the documented names only, a report's rows are found by the model's
or the URDF's name, and the python blocks of docs/python-api.md run as written."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import pendverify
from pendverify import api
from pendverify.analytic.params import default_parameter_file
from pendverify.bench.certify import PARTS, SetCost
from pendverify.bench.explain import ExplainBench
from pendverify.bench.run import Results
from pendverify.bench.workprecision import QUICK as QUICK_BENCH
from pendverify.certify.issue import Issued
from pendverify.checks.report import CheckRows, model_label
from pendverify.cli import main
from pendverify.diagnosis.corpus import ModelScores
from pendverify.display import REPR_LIMIT
from pendverify.shipped import shipped_file
from pendverify.stress.catalogue import StressReport
from pendverify.stress.framework import QUICK, stress_evidence
from pendverify.symbolic.mutation_report import MutationReport, Outcome
from pendverify.viz.review_folder import ReviewFolder

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs"
FEW = 20
CART_POLE = tuple(str(shipped_file("examples", f"cart_pole{suffix}")) for suffix in (".py", ".urdf", ".toml"))


@pytest.fixture(scope="module")
def objects(tmp_path_factory) -> dict[str, object]:
    """One of each public result object, the long ones made long (many rows, long names)."""
    tmp = tmp_path_factory.mktemp("objects")
    report = pendverify.check("double_pendulum", samples=FEW)
    run = pendverify.simulate(shipped_file("scenes", "damped_double_pendulum.toml"))
    implied = pendverify.implied_parameters(*CART_POLE, samples=FEW)
    issued = pendverify.certify_set(
        tmp / "certs", str(default_parameter_file("double_pendulum")), samples=FEW
    )
    failed = Issued([dataclasses.replace(i, status="fail", name=i.name * 5) for i in issued.items])
    many = [
        stress_evidence(f"case {i} " * 8, "M", 1e-15, 1e-13, 10.0, 2.0, None, i % 2 == 0) for i in range(60)
    ]
    outcomes = [Outcome("mass_matrix", "swap", f"mutant {i} " * 6, "survived") for i in range(80)]
    return {
        "CheckReport": report,
        "CheckRows": report["crba"],
        "Evidence (check)": report["crba"][0],
        "Run": run,
        "ImpliedParameters": implied,
        "Combination": implied.combinations[0],
        "Issued (certified)": issued,
        "Issued (not certified)": failed,
        "Evidence (battery item)": issued.items[0],
        "Rechecked": pendverify.api.recheck(issued.path),
        "Trajectory": api.trajectory(run),
        "ModelReading": api.read_model("double_pendulum"),
        "SymbolicReport": api.compare_symbolic("double_pendulum")[0],
        "MutationReport": MutationReport("x" * 400, "y" * 400, 1, 10, outcomes, []),
        "StressReport": StressReport(QUICK, 7, many),
        "ReviewFolder": ReviewFolder(report, [], tmp / ("deep" * 100) / "index.html"),
        "Results": Results(QUICK_BENCH, {}, [], {}),
        "SetCost": SetCost("x" * 200, 0.1, {p: 0.01 for p in PARTS}, {"checks": 0.01, "stress": 0.01}, 10),
        "ExplainBench": ExplainBench([ModelScores(f"model {i}" * 10) for i in range(50)], {}, True),
        "WorkedExample": api.worked_example("double_pendulum"),  # the most files: its repr is cut
    }


RESULTS = (
    "CheckReport",
    "CheckRows",
    "Evidence (check)",
    "Run",
    "ImpliedParameters",
    "Combination",
    "Issued (certified)",
    "Issued (not certified)",
    "Evidence (battery item)",
    "Rechecked",
    "Trajectory",
    "ModelReading",
    "SymbolicReport",
    "MutationReport",
    "StressReport",
    "ReviewFolder",
    "Results",
    "SetCost",
    "ExplainBench",
    "WorkedExample",
)


@pytest.mark.parametrize("name", RESULTS)
def test_every_result_object_is_one_short_line_and_an_html_table(objects, name):
    value = objects[name]
    text = repr(value)
    assert "\n" not in text and len(text) <= REPR_LIMIT, f"{name=}: {len(text)} characters: {text[:400]}"
    assert text.startswith(f"<{type(value).__name__}"), f"{name=}: {text}"
    page = value._repr_html_()
    assert page.startswith(("<table>", "<pre>")) and re.search(r"</\w+>$", page), name
    assert len(page) > 60, f"{name=}: {page}"


def test_the_implied_parameters_say_what_differs_in_one_line(objects):
    implied = objects["ImpliedParameters"]
    assert repr(implied) == "<ImpliedParameters exact, the URDF's own agree: 4 combinations, 0 differ>"
    planted = dataclasses.replace(
        implied,
        combinations=[dataclasses.replace(c, model_value=c.urdf_value + 1.0) for c in implied.combinations],
    )  # every combination's model value moved well past its rounding
    assert ", 4 differ (m(cart) + m(pole), " in repr(planted)
    assert planted._repr_html_().count(">differs<") == 4


# --- the top-level namespace -------------------------------------------------------------------------
def documented_top_level_names() -> set[str]:
    """The names the table "What `import pendverify` holds" of docs/python-api.md lists."""
    text = (DOCS / "python-api.md").read_text(encoding="utf-8")
    section = text.split("## What `import pendverify` holds", 1)[1].split("\n## ", 1)[0]
    return set(re.findall(r"^\| `([A-Za-z_]+)` \|", section, re.M))


def test_dir_of_pendverify_is_the_documented_names():
    shown = {name for name in dir(pendverify) if not name.startswith("__")}
    assert shown == documented_top_level_names()
    for name in ("implied_parameters", "ClosedFormModel", "ParameterSet", "quantity", "BiasOnlyModel"):
        assert name in shown
    for name in shown:
        assert getattr(pendverify, name) is not None, name
    assert not {"Any", "TYPE_CHECKING", "annotations", "importlib", "api", "analytic"} & set(dir(pendverify))


def test_the_top_level_names_are_the_api_modules_objects():
    from pendverify.analytic.interface import BiasOnlyModel, ClosedFormModel
    from pendverify.analytic.parameter_set import ParameterSet, quantity

    assert pendverify.implied_parameters is api.implied_parameters
    assert (pendverify.ClosedFormModel, pendverify.BiasOnlyModel) == (ClosedFormModel, BiasOnlyModel)
    assert (pendverify.ParameterSet, pendverify.quantity) == (ParameterSet, quantity)
    with pytest.raises(AttributeError, match="has no attribute 'implied_parameter'"):
        pendverify.implied_parameter  # noqa: B018


def test_the_api_reference_lists_implied_parameters():
    assert "        - implied_parameters\n" in (DOCS / "reference" / "api.md").read_text(encoding="utf-8")


# --- rows by the model's or the URDF's name ----------------------------------------------------------
LABELS = (
    "double_pendulum",
    "erd:double_pendulum",
    "erd:double_pendulum_simple",
    "cart_pole:arm",
    "arm_2:arm",
)


@pytest.mark.parametrize(
    ("key", "label"),
    [
        ("double_pendulum", "double_pendulum"),  # a label itself, though it is also erd's URDF name
        ("double_pendulum_simple", "erd:double_pendulum_simple"),  # the URDF's name alone
        ("cart_pole", "cart_pole:arm"),  # the model's name alone
        ("arm_2:arm", "arm_2:arm"),
    ],
)
def test_a_row_is_named_by_its_label_or_by_either_part_alone(key, label):
    assert model_label(LABELS, key, "check 'crba'") == label


def test_a_name_of_several_rows_or_of_none_lists_the_labels():
    with pytest.raises(KeyError, match=r"'arm' names 2 models of check 'crba': cart_pole:arm, arm_2:arm"):
        model_label(LABELS, "arm", "check 'crba'")
    with pytest.raises(
        KeyError, match=r"check 'crba' has no model 'cartpole'; its models: double_pendulum, "
    ):
        model_label(LABELS, "cartpole", "check 'crba'")


def test_a_plug_ins_row_is_found_by_the_models_name():
    report = pendverify.check(*CART_POLE, samples=FEW)
    assert report.models == ("cart_pole:cart_pole",)
    assert report["crba"]["cart_pole"] is report["crba"]["cart_pole:cart_pole"]
    assert report["cart_pole", "aba"].name == "aba"
    with pytest.raises(KeyError, match=r"'cart_pole' is a model: report\[CHECK\]\['cart_pole'\]"):
        report["cart_pole"]
    rows = report["crba"]
    assert isinstance(rows, CheckRows) and np.isfinite(rows.worst.error)


# --- the guide's examples ---------------------------------------------------------------------------
def python_blocks(page: Path) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", page.read_text(encoding="utf-8"), re.S | re.M)


def test_every_python_block_of_the_guide_runs_as_written(tmp_path, monkeypatch, capsys):
    """In a folder where ``pendverify example cart_pole .`` copied the files, as the page says;
    the blocks run in order in one namespace, then the test functions they define are called."""
    assert main(["example", "cart_pole", str(tmp_path)]) == 0
    monkeypatch.chdir(tmp_path)
    blocks = python_blocks(DOCS / "python-api.md")
    assert len(blocks) >= 3
    namespace: dict[str, object] = {}
    for i, block in enumerate(blocks):
        exec(compile(block, f"docs/python-api.md, python block {i + 1}", "exec"), namespace)
    tests = [f for name, f in namespace.items() if name.startswith("test_") and callable(f)]
    assert tests
    for test in tests:
        test()
    assert namespace["cart"].passed and namespace["implied"].exact and namespace["run"].passed
    assert "10 checks on 1 model(s)" in capsys.readouterr().out  # units, and 9 against Pinocchio
