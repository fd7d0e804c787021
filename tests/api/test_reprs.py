"""What a notebook user sees: short reprs, HTML tables, item access by check name, docstrings."""

from __future__ import annotations

import dataclasses
import inspect
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

import pendverify
from pendverify.analytic import MODELS, ClosedFormModel, DoublePendulum
from pendverify.analytic.interface import BiasOnlyModel
from pendverify.analytic.module_names import NAMESPACE, module_name
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import load_model_class
from pendverify.checks.evidence import Evidence
from pendverify.checks.report import CheckRows, Report
from pendverify.cli import main
from pendverify.display import REPR_LIMIT, shortened
from pendverify.robot.system import PinocchioSystem
from pendverify.simulation.simulate import Run
from pendverify.targets import Selection, Target, committed_urdf, model_target, select_targets

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
FEW = 20
TIMING = re.compile(r", \d+\.\d+ s: ")


class Cells(HTMLParser):
    """The text of every <td>/<th> of an HTML table, row by row, entities decoded."""

    def __init__(self):
        super().__init__()
        self.rows, self.items, self._cell = [], [], None

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th", "li"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self.rows[-1].append("".join(self._cell))
            self._cell = None
        elif tag == "li":
            self.items.append("".join(self._cell))
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def cells(html: str) -> Cells:
    parser = Cells()
    parser.feed(html)
    return parser


def short(text: str) -> str:
    assert "\n" not in text and len(text) <= REPR_LIMIT, (len(text), text)
    return text


@pytest.fixture(scope="module")
def report():
    return pendverify.check("double_pendulum", samples=FEW)


# --- reports ----------------------------------------------------------------------------------------
def test_report_repr_is_short_and_says_verdict_size_and_models(report):
    text = short(repr(report))
    # erd's mesh URDFs put link 1's centre of mass 2 µm off the joint line: a model-form term
    # within its threshold, which passes with a warning (the verdict "warn")
    assert text.startswith("<CheckReport warn: 46 checks on 4 model(s), ")
    assert {r.status for r in report.results if r.name == "model-form"} == {"warn"}
    assert f"{sum(report.states.values())} states, seed 20260301" in text
    assert "erd:double_pendulum_simple" in text
    assert len(repr(report.results)) > 10 * REPR_LIMIT  # what it replaces: the whole evidence


def test_report_repr_stays_short_with_many_long_model_labels(report):
    many = Report(
        seed=1,
        states={f"a_model_with_a_long_name_{i}:a_long_parameter_set_{i}": 10 for i in range(40)},
        results=list(report.results),
    )
    text = short(repr(many))
    assert "…" in text and text.startswith("<Report warn: 46 checks on 44 model(s), 400 states, seed 1")


def test_report_html_shows_the_rows_of_the_cli_table(report, capsys):
    assert main(["check", "--model", "double_pendulum", "--samples", str(FEW)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert set(lines[1]) == {"-"} and lines[2 + 46] == ""  # the header's rule; 46 rows; a blank line
    cli_rows = [re.split(r"\s{2,}", line) for line in lines[2 : 2 + 46]]
    parsed = cells(report._repr_html_())
    assert parsed.rows[0] == re.split(r"\s{2,}", lines[0].strip())
    assert parsed.rows[1:] == cli_rows and len(report.results) == 46
    # the notes and the verdict line are those under the CLI's table (the timing aside)
    kept = ("note", "warning", "largest")
    under = [TIMING.sub(", … s: ", line) for line in lines if line.startswith(kept)]
    assert [TIMING.sub(", … s: ", item) for item in parsed.items] == under
    assert TIMING.sub(", … s: ", lines[-1]) in TIMING.sub(", … s: ", report._repr_html_())


def test_an_empty_report_still_shows():
    empty = Report(seed=1, states={}, results=[], skipped=["example-robot-data is not installed"])
    assert short(repr(empty)) == "<Report pass: 0 checks on 0 model(s), 0 states, seed 1>"
    assert cells(empty._repr_html_()).items == ["note: example-robot-data is not installed"]
    with pytest.raises(KeyError, match="its checks: none"):
        empty["crba"]


def test_report_html_escapes_what_it_shows():
    params = load_parameter_file(default_parameter_file("double_pendulum"))[2]
    target = model_target(DoublePendulum, str(committed_urdf("double_pendulum")), params, "<b>&arm")
    from pendverify.checks.report import CheckReport
    from pendverify.checks.verification import build_report

    report = CheckReport.from_report(build_report([target], 5, 1))
    html = report._repr_html_()
    assert "<b>&arm" not in html and "double_pendulum:&lt;b&gt;&amp;arm" in html
    assert {row[0] for row in cells(html).rows[1:]} == {"double_pendulum:<b>&arm"}
    assert "<b>" not in report["crba"]._repr_html_()


def test_report_item_access_by_check_name(report):
    rows = report["crba"]
    assert isinstance(rows, CheckRows) and rows.check == "crba"
    assert rows.models == report.models and len(rows) == 4
    assert rows.models[0] == "double_pendulum" and rows.models[3] == "erd:double_pendulum_simple"
    one = rows["erd:double_pendulum"]
    assert isinstance(one, Evidence) and (one.model, one.name) == ("erd:double_pendulum", "crba")
    assert one is report["erd:double_pendulum", "crba"] is rows[1]
    assert rows.passed and rows.status == "pass"
    assert rows.worst is max(rows, key=lambda r: r.error / r.tolerance)
    # checks a model does not run are not in its rows: the cart has no damping row
    assert report.checks[-1] == "model-form" and report["model-form"].models == (
        "erd:double_pendulum",
        "erd:double_pendulum_continuous",
    )
    assert "crba" in report and "crbaa" not in report and list(report) == list(report.checks)
    assert dict(report)["aba"].models == report.models


def test_unknown_names_are_key_errors_listing_the_valid_ones(report):
    with pytest.raises(KeyError) as caught:
        report["crbaa"]
    its = "no check 'crbaa' in this report; its checks: units, crba, rnea, gravity, coriolis"
    assert its in str(caught.value)
    with pytest.raises(KeyError) as caught:
        report["cart_double_pendulum", "crba"]
    message = str(caught.value)
    assert "has no model 'cart_double_pendulum'" in message and "erd:double_pendulum_simple" in message
    with pytest.raises(KeyError, match="a check name or"):
        report["double_pendulum", "crba", "x"]


def test_check_rows_and_results_have_short_reprs_and_html(report):
    text = short(repr(report["aba"]))
    assert text.startswith("<CheckRows aba: pass on 4 model(s) (double_pendulum, erd:")
    assert "worst 7.4" in text and "(erd:double_pendulum" in text  # the mesh URDFs' model-form term
    result = report["double_pendulum", "crba"]
    text = short(repr(result))
    assert text.startswith("<Evidence check double_pendulum crba: pass, error ")
    assert f"{result.error:.2e} vs tolerance {result.tolerance:.2e}" in text
    parsed = cells(report["aba"]._repr_html_())
    assert [row[0] for row in parsed.rows[1:]] == list(report.models)


def test_a_failing_row_shows_fail_in_repr_and_html(report):
    params = load_parameter_file(default_parameter_file("double_pendulum"))[2]
    wrong = params.replace(m2=params.m2 * 1.1)
    failing = pendverify.check(
        "double_pendulum", committed_urdf("double_pendulum"), wrong.as_dict(), samples=5
    )
    assert failing.status == "fail" and short(repr(failing)).startswith("<CheckReport fail: ")
    assert "fail" in repr(failing["crba"]) and "FAIL" in failing._repr_html_()
    assert "color:#b00020" in failing._repr_html_()


# --- runs ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def run():
    return pendverify.simulate(REPO / "scenes" / "damped_double_pendulum.toml")


def test_run_repr_is_short_and_says_scene_engine_duration_samples_invariants(run):
    text = short(repr(run))
    assert text == (
        f"<Run 'damped double pendulum' (double_pendulum): engine aba, 10 s, {len(run.t)} samples, "
        f"{len(run.invariants)}/{len(run.invariants)} invariants hold: pass>"
    )
    assert len(run.t) == 1001


def test_scene_and_invariant_reprs_are_short_and_say_what_they_hold(run):
    from pendverify.simulation.scene import load_scene

    scene = short(repr(load_scene(REPO / "scenes" / "cart_lqr_push.toml")))
    assert scene == (
        "<Scene 'cart LQR after a push' (cart_double_pendulum): engine aba, 8 s at 100 Hz, DOP853, "
        "effects: gravity, damping, actuation, disturbance>"
    )
    invariant = run.invariants[0]
    text = short(repr(invariant))
    assert text.startswith(
        f"<Evidence invariant {invariant.name[:60]}: pass, error {invariant.error:.2e} vs "
    )
    assert text.endswith(f" at {invariant.label}>")
    failed = dataclasses.replace(invariant, status="fail")
    assert f": fail, error {invariant.error:.2e}" in repr(failed)


def test_run_html_lists_every_invariant(run):
    html = run._repr_html_()
    parsed = cells(html)
    assert parsed.rows[0][:5] == ["invariant", "error", "tolerance", "worst t (s)", "result"]
    assert [row[0] for row in parsed.rows[1:]] == [i.name for i in run.invariants]
    assert all(row[4] == "pass" for row in parsed.rows[1:])
    assert "scene damped double pendulum (double_pendulum): engine aba, 10 s, 1001 samples" in html


def test_run_with_both_engines_counts_the_comparison():
    scene = {
        "name": "<swing> & co",
        "model": "double_pendulum",
        "initial": {"q": [0.3, 1.2]},
        "time": {"duration": 0.5, "sample_rate": 20.0},
        "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
        "effects": {"gravity": True},
    }
    both = pendverify.simulate(scene, engine="both")
    assert both.engine == "both" and both.metadata()["engine"] == "both"
    assert short(repr(both)).startswith(
        "<Run '<swing> & co' (double_pendulum): engine both, 0.5 s, 11 samples"
    )
    assert f"{len(both.invariants) + 1}/{len(both.invariants) + 1} invariants hold" in repr(both)
    html = both._repr_html_()
    assert "&lt;swing&gt; &amp; co" in html and "<swing>" not in html
    assert cells(html).rows[-1][0].startswith("engines agree")


# --- models, systems, targets ---------------------------------------------------------------------------
def test_model_instances_and_classes_have_short_informative_reprs():
    for name, cls in MODELS.items():
        params = load_parameter_file(default_parameter_file(name))[2]
        text = short(repr(cls(params)))
        assert text.startswith(f"<{cls.__name__} {name!r}: {len(cls.coordinates)} dof (")
        assert f"g={params.g:g}" in text
        text = short(repr(cls))
        assert text.startswith(f"<model class {cls.__name__} {name!r} in {cls.__module__}: ")
    assert repr(ClosedFormModel) == "<model interface ClosedFormModel in pendverify.analytic.interface>"
    assert repr(BiasOnlyModel).startswith("<model interface BiasOnlyModel")
    cart = load_model_class(EXAMPLES / "cart_pole.py")
    where = module_name(EXAMPLES / "cart_pole.py")  # cart_pole, or cart_pole_2... if another copy came first
    assert re.fullmatch(r"pendverify\.plugins\.cart_pole(_\d+)?", where)
    assert short(repr(cart)) == (
        f"<model class CartPole 'cart_pole' in {where}: 2 dof (x, theta), 1 input, 1 disturbance>"
    )


def test_a_model_with_many_parameters_keeps_a_short_repr():
    many = load_model_class(EXAMPLES / "triple_pendulum.py")
    params = pendverify.load_params(many, EXAMPLES / "triple_pendulum.toml")
    text = short(repr(many(params)))
    assert text.startswith("<TriplePendulum 'triple_pendulum': 3 dof (")


def test_pinocchio_system_and_target_reprs():
    system = pendverify.load_urdf("double_pendulum", committed_urdf("double_pendulum"))
    text = short(repr(system))
    assert text.startswith("<PinocchioSystem ") and "2 dof (joints joint1, joint2), g = 9.81 m/s²>" in text
    deep = PinocchioSystem.for_model(DoublePendulum, committed_urdf("double_pendulum"), source="x")
    deep.source = "/" + "very-long-folder/" * 30 + "arm.urdf"
    assert short(repr(deep)).count("…") == 1 and "arm.urdf" in repr(deep)
    (target,) = select_targets(DoublePendulum, erd_urdfs=False).targets
    assert short(repr(target)).startswith("<Target double_pendulum: double_pendulum, 2 dof, URDF ")


def test_shortened_keeps_both_ends():
    assert shortened("abcdef", 6) == "abcdef"
    assert shortened("abcdefghij", 5) == "ab…ij" and len(shortened("x" * 1000, 300)) == 300


# --- plug-in module names -----------------------------------------------------------------------------
def test_plugin_modules_are_named_after_their_file(tmp_path):
    source = (EXAMPLES / "minimal_double_pendulum.py").read_text()
    first, second = tmp_path / "a" / "my-arm 2.py", tmp_path / "b" / "my-arm 2.py"
    for path in (first, second):
        path.parent.mkdir()
        path.write_text(source)
    a, b = load_model_class(first), load_model_class(second)
    assert a.__module__ == f"{NAMESPACE}.my_arm_2" and b.__module__ == f"{NAMESPACE}.my_arm_2_2"
    assert load_model_class(first).__module__ == a.__module__  # the same file keeps its name
    assert module_name(tmp_path / "a" / ".." / "a" / "my-arm 2.py") == a.__module__
    digit = tmp_path / "3dof.py"
    digit.write_text(source)
    assert load_model_class(digit).__module__ == f"{NAMESPACE}._3dof"
    keyword = tmp_path / "class.py"
    keyword.write_text(source)
    assert module_name(keyword) == f"{NAMESPACE}._class"
    assert all(name.isidentifier() for name in a.__module__.split("."))


def test_text_models_are_named_after_their_file_too(tmp_path):
    text = tmp_path / "my arm.toml"
    text.write_text((EXAMPLES / "minimal_double_pendulum_text.toml").read_text())
    cls = load_model_class(text)
    assert cls.__module__ == f"{NAMESPACE}.my_arm"
    assert cls.params_type.__module__ == cls.__module__
    assert load_model_class(text).__module__ == cls.__module__  # read again: the same name


# --- docstrings ---------------------------------------------------------------------------------------
PUBLIC = [
    *(getattr(pendverify, name) for name in pendverify.__all__ if name != "__version__"),
    Report,
    CheckRows,
    Evidence,
    Run,
    PinocchioSystem,
    ClosedFormModel,
    Target,
    Selection,
    select_targets,
]


@pytest.mark.parametrize("obj", PUBLIC, ids=lambda obj: obj.__name__)
def test_every_public_object_has_a_docstring(obj):
    assert inspect.getdoc(obj) and len(inspect.getdoc(obj)) > 20
    if inspect.isclass(obj):
        for name, member in vars(obj).items():
            if not name.startswith("_") and (inspect.isfunction(member) or isinstance(member, property)):
                assert inspect.getdoc(member), f"{obj.__name__}.{name}"


def test_a_refused_certificate_names_the_failing_items_in_a_short_repr(tmp_path):
    wrong = tmp_path / "heavier.toml"
    wrong.write_text(
        Path(default_parameter_file("double_pendulum")).read_text().replace("m2 = 0.8", "m2 = 0.9")
    )
    issued = pendverify.certify_set(
        tmp_path / "out", urdf=committed_urdf("double_pendulum"), urdf_params=wrong, samples=10
    )
    failed = [i.name for i in issued.items if not i.passed]
    assert not issued.certified and failed
    text = short(repr(issued))
    assert text.startswith(
        f"<Issued not certified: {len(failed)} of {len(issued.items)} items fail: {failed[0]}"
    )
