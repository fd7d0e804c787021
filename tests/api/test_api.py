"""The Python API (``pendverify.check``, ``simulate``, ``load_*``, ``pendverify.testing``).

It goes through the functions the CLI calls, so its table is the CLI's; a model class
written here with a planted error fails, and ``assert_verified`` shows the table; bad
input is a one-line ``PendverifyError``; ``import pendverify`` does not load Pinocchio.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import pendverify
from pendverify.analytic import DoublePendulum, DoublePendulumParams
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import validate_model_class
from pendverify.checks.evidence import check_record
from pendverify.checks.report import Report
from pendverify.cli import main
from pendverify.documents import read_toml
from pendverify.errors import PendverifyError
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for
from pendverify.targets import committed_urdf, model_target, params_target
from pendverify.testing import assert_verified

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
SCENES = REPO / "scenes"
CART_POLE = (EXAMPLES / "cart_pole.py", EXAMPLES / "cart_pole.urdf", EXAMPLES / "cart_pole.toml")
FEW = 60  # random states where the test is about the API, not the breadth of the sample
TIMING = re.compile(r", \d+\.\d+ s: ")
#: a repair search that stopped at its time bound (``pendverify.diagnosis.repair``) tried as many
#: candidates as the time allowed: that count depends on the machine's load, nothing else on the line does
TIME_BOUNDED = re.compile(
    r"\d+ (candidate\(s\) tried against every check) (\(the search stopped at its time bound\))"
)


def default_values(name: str = "double_pendulum") -> dict[str, float]:
    return load_parameter_file(default_parameter_file(name))[2].as_dict()


def comparable(table: str) -> list[str]:
    """The table's lines, with what differs between runs blanked: the time taken, and the number of
    repair candidates a search tried when it stopped at its time bound (it still says that it did)."""
    return [TIME_BOUNDED.sub(r"… \1 \2", TIMING.sub(", … s: ", line)) for line in table.splitlines()]


def cli_table(capsys, *argv: str) -> tuple[int, str]:
    status = main(["check", *argv])
    return status, capsys.readouterr().out.rstrip("\n")


# --- check --------------------------------------------------------------------------------------------
def test_check_builtin_name_gives_the_cli_table(capsys):
    report = pendverify.check("double_pendulum", erd=False)
    assert isinstance(report, pendverify.CheckReport) and isinstance(report, Report)
    assert report.passed and report.status == "pass"
    assert str(report) == report.table()
    # the evidence: every check, its error within its tolerance, where it was worst
    assert {r.name for r in report.results} >= {"crba", "rnea", "coriolis", "aba", "energy"}
    for r in report.results:
        assert r.model == "double_pendulum" and r.status == "pass"
        assert 0 <= r.error <= r.tolerance < 1e-11, r
        assert r.label
    assert report.states == {"double_pendulum": 410} and report.seed == 20260301

    status, cli = cli_table(capsys, "--model", "double_pendulum", "--no-erd")
    assert status == 0
    api_lines, cli_lines = report.table().splitlines(), cli.splitlines()
    assert TIMING.search(cli_lines[-1]) and TIMING.search(api_lines[-1])
    assert api_lines[:-1] == cli_lines[:-1]  # every line but the timing line, verbatim
    assert comparable(report.table()) == comparable(cli)


DEFAULT_PARAMS = str(default_parameter_file("double_pendulum"))
ERD_SIMPLE = "erd:double_pendulum_simple"
#: (the API's arguments, the CLI's) that must select the same targets and give the same table
SAME_ARGUMENTS = {
    "everything": ((), {}, []),
    "the double pendulum, with example-robot-data": (
        ("double_pendulum",),
        {},
        ["--model", "double_pendulum"],
    ),
    "the double pendulum, erd=False": (
        ("double_pendulum",),
        {"erd": False},
        ["--model", "double_pendulum", "--no-erd"],
    ),
    "the cart": (("cart_double_pendulum",), {}, ["--model", "cart_double_pendulum"]),
    "erd:NAME as the model": ((ERD_SIMPLE,), {}, ["--urdf", ERD_SIMPLE]),
    "erd:NAME as the urdf": (
        ("double_pendulum",),
        {"urdf": ERD_SIMPLE},
        ["--urdf", ERD_SIMPLE, "--model", "double_pendulum"],
    ),
    "erd:NAME with parameters": (
        (),
        {"urdf": ERD_SIMPLE, "params": DEFAULT_PARAMS},
        ["--urdf", ERD_SIMPLE, "--params", DEFAULT_PARAMS],
    ),
    "a parameter file alone": ((), {"params": DEFAULT_PARAMS}, ["--params", DEFAULT_PARAMS]),
    "a model file": (
        (str(CART_POLE[0]), str(CART_POLE[1]), str(CART_POLE[2])),
        {},
        ["--analytic", str(CART_POLE[0]), "--urdf", str(CART_POLE[1]), "--params", str(CART_POLE[2])],
    ),
}


def test_comparable_blanks_only_what_a_time_bound_decides():
    """A repair search's count is blanked only where it stopped at its time bound; the sentence
    itself, and a count the search reached by exhausting its candidates, are still compared."""
    bounded = "no repair: …; 4 candidate(s) tried against every check (the search stopped at its time bound)"
    assert comparable(bounded) == comparable(bounded.replace("4 candidate", "5 candidate"))
    assert comparable(bounded) != comparable(bounded.replace("every check", "the first check"))
    whole = "no repair: …; 4 candidate(s) tried against every check"
    assert comparable(whole) != comparable(whole.replace("4 candidate", "5 candidate"))


@pytest.mark.parametrize("case", SAME_ARGUMENTS, ids=list(SAME_ARGUMENTS))
def test_the_api_and_the_cli_check_the_same_targets_with_the_same_numbers(capsys, tmp_path, case):
    args, kwargs, argv = SAME_ARGUMENTS[case]
    report = pendverify.check(*args, **kwargs, samples=FEW)
    out = tmp_path / "cli.json"
    status, cli = cli_table(capsys, *argv, "--samples", str(FEW), "--json", str(out))
    cli = cli.removesuffix(f"\nreport written to {out}")
    assert status == (0 if report.passed else 1)
    assert comparable(report.table()) == comparable(cli)
    document = json.loads(out.read_text())
    assert document["states"] == report.states and document["skipped"] == report.skipped
    fields = ("model", "check", "max_error", "tolerance", "max_abs_error", "status")
    assert [tuple(r[f] for f in fields) for r in document["results"]] == [
        tuple(check_record(r)[f] for f in fields) for r in report.results
    ]


def test_a_built_in_name_checks_what_check_model_checks():
    """check("double_pendulum") is `check --model double_pendulum`: the default set and
    example-robot-data's URDFs (installed with the test extra); erd=False is --no-erd."""
    with_erd = pendverify.check("double_pendulum", samples=FEW)
    assert with_erd.models == (
        "double_pendulum",
        "erd:double_pendulum",
        "erd:double_pendulum_continuous",
        "erd:double_pendulum_simple",
    )
    assert with_erd.passed and not with_erd.skipped
    assert pendverify.check("double_pendulum", samples=FEW, erd=False).models == ("double_pendulum",)
    assert pendverify.check("cart_double_pendulum", samples=FEW).models == ("cart_double_pendulum",)
    assert pendverify.check(samples=FEW).models == (
        "double_pendulum",
        "cart_double_pendulum",
        "erd:double_pendulum",
        "erd:double_pendulum_continuous",
        "erd:double_pendulum_simple",
    )
    # an erd:NAME target alone is the very row of the default check
    alone = pendverify.check(ERD_SIMPLE, samples=FEW)
    assert alone.models == (ERD_SIMPLE,) == pendverify.check(urdf=ERD_SIMPLE, samples=FEW).models
    assert [(r.name, r.error) for r in alone.results] == [
        (r.name, r.error) for r in with_erd.results if r.model == ERD_SIMPLE
    ]


def test_plugin_file_with_its_urdf_and_parameters_passes_as_on_the_cli(capsys):
    report = assert_verified(*CART_POLE, samples=FEW)
    assert report.passed and {r.model for r in report.results} == {"cart_pole:cart_pole"}
    model, urdf, params = (str(p) for p in CART_POLE)
    status, cli = cli_table(
        capsys, "--analytic", model, "--urdf", urdf, "--params", params, "--samples", str(FEW)
    )
    assert status == 0
    assert comparable(report.table()) == comparable(cli)

    # the same model as a class and its parameters as a mapping: the same figures
    cls = pendverify.load_model(CART_POLE[0])
    assert pendverify.load_model(cls) is cls
    values = read_toml(CART_POLE[2])["parameters"]
    again = pendverify.check(cls, str(CART_POLE[1]), values, samples=FEW)
    assert [(r.name, r.error, r.status) for r in again.results] == [
        (r.name, r.error, r.status) for r in report.results
    ]


def test_builtin_with_parameters_from_a_file_a_mapping_or_urdf_text():
    by_file = pendverify.check(
        "double_pendulum", params=default_parameter_file("double_pendulum"), samples=FEW
    )
    assert by_file.passed and by_file.states == {"double_pendulum:double_pendulum": FEW + 10}
    by_mapping = pendverify.check("double_pendulum", params=default_values(), samples=FEW)
    assert by_mapping.passed and list(by_mapping.states) == ["double_pendulum:inline"]
    params = pendverify.load_params(DoublePendulum, default_values())
    assert isinstance(params, DoublePendulumParams)
    by_text = pendverify.check(DoublePendulum, urdf_for(params), params, samples=FEW)
    assert by_text.passed and list(by_text.states) == ["double_pendulum:urdf-text"]
    assert [r.error for r in by_mapping.results] == [r.error for r in by_file.results]


def test_targets_are_labelled_by_file_stem_by_urdf_text_or_by_the_callers_name():
    params = load_parameter_file(default_parameter_file("double_pendulum"))[2]
    urdf = committed_urdf("double_pendulum")
    assert model_target(DoublePendulum, str(urdf), params).label == "double_pendulum:double_pendulum"
    by_text = model_target(DoublePendulum, urdf.read_text(), params)
    assert by_text.label == "double_pendulum:urdf-text" and by_text.source == "<urdf text>"
    assert (
        model_target(DoublePendulum, urdf.read_text(), params, "bench arm").label
        == "double_pendulum:bench arm"
    )
    inline = params_target(params)
    assert inline.label == "double_pendulum:inline"
    assert inline.source == "<URDF of the inline double_pendulum parameters>"
    from_file = params_target(params, "set 7", "sweeps/set7.toml")
    assert (from_file.label, from_file.source) == ("double_pendulum:set 7", "<URDF of sweeps/set7.toml>")


def test_a_missing_parameter_set_is_asked_for_in_words_that_fit_the_api():
    """The library's message names both ways to give it, and the URDF text is not repeated."""
    urdf = committed_urdf("cart_double_pendulum").read_text()
    with pytest.raises(PendverifyError) as caught:
        pendverify.check("cart_double_pendulum", urdf)
    message = str(caught.value)
    assert message == (
        "<urdf text>: give the parameter set (--params on the command line, params= in the Python API): "
        "a cart_double_pendulum URDF alone does not fix the closed form"
    )
    assert pendverify.check(
        "cart_double_pendulum", urdf, default_values("cart_double_pendulum"), samples=10
    ).passed


def test_validate_model_class_is_public_and_names_the_rule():
    class Nameless(DoublePendulum):
        name = ""

    validate_model_class(DoublePendulum)  # a usable class: nothing to say
    with pytest.raises(PendverifyError, match=r"test_api\.py: Nameless: needs a class attribute name"):
        validate_model_class(Nameless)
    with pytest.raises(PendverifyError, match=r"^models/arm\.py: Nameless: "):
        validate_model_class(Nameless, "models/arm.py")


def test_load_urdf_gives_pinocchio_in_the_models_coordinates():
    params = pendverify.load_params("double_pendulum", default_parameter_file("double_pendulum"))
    system = pendverify.load_urdf("double_pendulum", committed_urdf("double_pendulum"), params.g)
    assert isinstance(system, PinocchioSystem)
    q = np.array([0.4, -1.1])
    np.testing.assert_allclose(system.mass_matrix(q), DoublePendulum(params).mass_matrix(q), rtol=1e-13)
    np.testing.assert_allclose(system.gravity(q), DoublePendulum(params).gravity(q), rtol=1e-13)


# --- a model class written here, with its map declared as a plug-in's ----------------------------------
class SignFlipParams(DoublePendulumParams):
    model = "sign_flip"


class SignFlip(DoublePendulum):
    """The seed with a declared coordinate map; ``flip`` plants a sign error in one Coriolis term."""

    name = "sign_flip"
    params_type = SignFlipParams
    geometry_reader = ""  # declare the map, as a plug-in does
    urdf_joints = ("joint1", "joint2")
    joint_offset = (0.0, 0.0)
    flip = True

    def seed_coriolis_matrix(self, q, v):
        C = super().seed_coriolis_matrix(q, v)
        if self.flip:
            C[1, 0] = -C[1, 0]  # β sin θ2 θ̇1 written as −β sin θ2 θ̇1
        return C


class Unflipped(SignFlip):
    flip = False


def test_a_planted_coriolis_sign_error_fails_and_assert_verified_shows_the_table():
    urdf, values = committed_urdf("double_pendulum"), default_values()
    control = assert_verified(Unflipped, urdf, values, samples=FEW)  # the map is right: all pass
    assert "coordinate map declared by Unflipped" in control.table()

    report = pendverify.check(SignFlip, urdf, values, samples=FEW)
    assert not report.passed and report.status == "fail"
    failed = {r.name for r in report.failures()}
    assert {"rnea", "aba"} <= failed
    assert "crba" not in failed and "gravity" not in failed
    assert "FAIL" in report.table()

    with pytest.raises(AssertionError) as caught:
        assert_verified(SignFlip, urdf, values, samples=FEW)
    message = str(caught.value)
    assert comparable(message) == comparable(report.table())
    assert "FAIL" in message and "sign_flip:double_pendulum" in message
    assert re.search(r"sign_flip:double_pendulum\s+rnea .* FAIL", message)


def test_strict_turns_a_warning_into_a_failure():
    class TextbookC(Unflipped):
        """A published C: the same C·q̇, but Ṁ − 2C is not skew-symmetric."""

        def seed_coriolis_matrix(self, q, v):
            b, s = self.beta, self.math.sin(q[1])
            return np.array(
                [[-2 * b * s * v[1] + self.params.b1, -b * s * v[1]], [b * s * v[0], self.params.b2]]
            )

    urdf, values = committed_urdf("double_pendulum"), default_values()
    warned = assert_verified(TextbookC, urdf, values, samples=FEW)
    assert warned.status == "warn" and warned.warnings
    assert "not the Christoffel C" in warned.table() and "FAIL" not in warned.table()
    with pytest.raises(AssertionError) as caught:
        assert_verified(TextbookC, urdf, values, samples=FEW, strict=True)
    assert "not the Christoffel C" in str(caught.value)
    assert re.search(r"\s+coriolis .* FAIL", str(caught.value))


# --- simulate -------------------------------------------------------------------------------------------
def test_simulate_a_scene_file_returns_a_trajectory_whose_invariants_hold():
    run = pendverify.simulate(SCENES / "damped_double_pendulum.toml")
    assert run.passed and run.invariants and all(i.passed for i in run.invariants)
    assert run.t[0] == 0.0 and run.t[-1] == pytest.approx(10.0)
    assert run.q.shape == run.v.shape == (len(run.t), 2)
    assert np.all(np.diff(run.energy) <= 1e-9 * np.max(np.abs(run.energy)))  # damped: E never rises


def test_simulate_a_scene_mapping_with_both_engines():
    scene = {
        "name": "inline swing",
        "model": "double_pendulum",
        "initial": {"q": [0.3, 1.2]},
        "time": {"duration": 1.0, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
        "effects": {"gravity": True},
    }
    run = pendverify.simulate(scene, engine="both")
    assert run.passed and run.engine_comparison is not None and run.engine_comparison.passed
    assert len(run.t) == 51


def test_a_urdf_with_the_closed_form_engine_is_the_one_an_lqr_is_designed_on():
    # the closed form integrates without a URDF; a scene's LQR controller is designed on one
    urdf = committed_urdf("cart_double_pendulum")
    run = pendverify.simulate(SCENES / "cart_lqr_push.toml", urdf, "closed_form")
    assert run.passed and run.dynamics.engine == "closed_form"
    written = pendverify.simulate(
        SCENES / "cart_lqr_push.toml", engine="closed_form"
    )  # the URDF the project writes
    np.testing.assert_array_equal(run.q, written.q)  # the committed URDF is that one, byte for byte


def test_the_simulate_command_refuses_a_urdf_its_engine_does_not_use(capsys):
    scene, urdf = SCENES / "damped_double_pendulum.toml", committed_urdf("double_pendulum")
    assert main(["simulate", str(scene), "--engine", "closed_form", "--urdf", str(urdf)]) == 2
    assert "engine closed_form does not use a URDF" in capsys.readouterr().err


# --- bad input: one line, a PendverifyError -------------------------------------------------------------
SYNTAX_ERROR = "import numpy\ndef broken(:\n"

BAD_INPUTS = {
    "unknown name": (lambda tmp: pendverify.check("tripple_pendulum"), "unknown model 'tripple_pendulum'"),
    "missing model file": (lambda tmp: pendverify.check(tmp / "mine.py", "x.urdf"), "model file not found"),
    "model file with a syntax error": (
        lambda tmp: pendverify.load_model(_write(tmp / "bad.py", SYNTAX_ERROR)),
        "bad.py, line 2: importing it failed",
    ),
    "not a model": (lambda tmp: pendverify.load_model(42), "got a int"),
    "not a model class": (lambda tmp: pendverify.load_model(dict), "not a subclass"),
    # a model SymPy reads runs its units check alone; one it cannot read has nothing to check
    "plug-in without a URDF": (
        lambda tmp: pendverify.check(REPO / "tests" / "analytic" / "data" / "pendulum_functions.py"),
        "pendulum_functions.py: give --urdf (urdf= in the Python API): the URDF to verify pendulum_functions",
    ),
    "unknown example-robot-data URDF": (
        lambda tmp: pendverify.check("erd:double_pendulum_triple"),
        "erd:double_pendulum_triple: example-robot-data has no 'double_pendulum_triple'; it has",
    ),
    "erd:NAME as the model and a urdf": (
        lambda tmp: pendverify.check("erd:double_pendulum", committed_urdf("double_pendulum")),
        "give it as model or as urdf, not both",
    ),
    "erd not a bool": (
        lambda tmp: pendverify.check("double_pendulum", erd="no"),
        "key 'erd' = 'no': must be True or False",
    ),
    "a mapping of parameters without a model": (
        lambda tmp: pendverify.check(params=default_values()),
        "name the model of these parameters",
    ),
    "negative samples": (lambda tmp: pendverify.check("double_pendulum", samples=-1), "'samples' = -1"),
    "zero model-form rtol": (
        lambda tmp: pendverify.check("double_pendulum", model_form_rtol=0.0),
        "must be a finite number > 0",
    ),
    "a parameter document instead of the mapping": (
        lambda tmp: pendverify.load_params("double_pendulum", {"parameters": default_values()}),
        "key 'parameters'",
    ),
    "negative mass": (
        lambda tmp: pendverify.load_params("double_pendulum", {**default_values(), "m1": -1.0}),
        "key 'm1' = -1.0: a mass must be a finite number > 0",
    ),
    "missing parameter": (
        lambda tmp: pendverify.load_params("double_pendulum", {"m1": 1.0}),
        "missing key",
    ),
    "missing parameter file": (
        lambda tmp: pendverify.check("double_pendulum", params=tmp / "none.toml"),
        "file not found",
    ),
    "another model's parameter file": (
        lambda tmp: pendverify.load_params(CART_POLE[0], default_parameter_file("double_pendulum")),
        "must be 'cart_pole'",
    ),
    "another model's parameter set": (
        lambda tmp: pendverify.load_params(SignFlip, DoublePendulumParams(**default_values())),
        "sign_flip needs SignFlipParams",
    ),
    "another built-in model's parameter file": (
        lambda tmp: pendverify.check(
            "double_pendulum", params=default_parameter_file("cart_double_pendulum")
        ),
        "key 'model' = 'cart_double_pendulum': must be 'double_pendulum'",
    ),
    "missing URDF": (
        lambda tmp: pendverify.load_urdf("double_pendulum", tmp / "none.urdf"),
        "robot description not found",
    ),
    "non-finite gravity": (
        lambda tmp: pendverify.load_urdf("double_pendulum", committed_urdf("double_pendulum"), float("nan")),
        "key 'g' = nan",
    ),
    "malformed URDF text": (
        lambda tmp: pendverify.check("double_pendulum", '<robot name="x"><link name="a"/>'),
        "<urdf text>: malformed XML",
    ),
    "URDF and parameters of different models": (
        lambda tmp: pendverify.check(CART_POLE[0], committed_urdf("double_pendulum"), CART_POLE[2]),
        "do not match the URDF's movable joints",
    ),
    "missing scene": (lambda tmp: pendverify.simulate(tmp / "none.toml"), "scene file not found"),
    "invalid scene": (
        lambda tmp: pendverify.simulate(
            {"model": "double_pendulum", "initial": {"q": [0, 0]}, "time": {"duration": -1.0}}
        ),
        "key 'time.duration' = -1.0",
    ),
    "unknown engine": (
        lambda tmp: pendverify.simulate(SCENES / "damped_double_pendulum.toml", engine="euler"),
        "unknown engine 'euler'",
    ),
    "a URDF for the closed form engine": (
        lambda tmp: pendverify.simulate(
            SCENES / "damped_double_pendulum.toml", committed_urdf("double_pendulum"), "closed_form"
        ),
        "does not use a URDF",
    ),
}


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@pytest.mark.parametrize("case", BAD_INPUTS, ids=list(BAD_INPUTS))
def test_bad_input_is_one_line_pendverify_error(tmp_path, case):
    call, expected = BAD_INPUTS[case]
    with pytest.raises(PendverifyError) as caught:
        call(tmp_path)
    message = str(caught.value)
    assert "\n" not in message and expected in message, message


def test_a_bad_input_is_not_an_assertion():
    with pytest.raises(PendverifyError):
        assert_verified("double_pendulum", params={"m1": 1.0})


# --- import cost ----------------------------------------------------------------------------------------
def test_import_pendverify_does_not_import_pinocchio_or_sympy():
    script = textwrap.dedent(
        """
        import sys
        import pendverify
        heavy = {"pinocchio", "sympy", "scipy"} & set(sys.modules)
        assert not heavy, heavy
        assert pendverify.__version__ and "check" in dir(pendverify)
        assert isinstance(pendverify.PendverifyError("x"), Exception)
        assert "pinocchio" not in sys.modules
        try:
            pendverify.no_such_name
        except AttributeError:
            pass
        else:
            raise SystemExit("no AttributeError")
        from pendverify import commands  # submodules still import as before
        assert callable(pendverify.check) and "pinocchio" in sys.modules
        assert all(getattr(pendverify, name) is not None for name in pendverify.__all__)
        print("ok")
        """
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"


@pytest.mark.slow
def test_certify_set_writes_a_bundle_that_recheck_accepts(tmp_path):
    from pendverify.analytic.params import default_parameter_file
    from pendverify.certify.issue import recheck

    issued = pendverify.certify_set(tmp_path, default_parameter_file("double_pendulum"), samples=40)
    assert issued.certified and issued.path == tmp_path / "double_pendulum.cert.json"
    text = repr(issued)  # short: the items and the certificate are in the fields, not the repr
    assert text == f"<Issued certified: {len(issued.items)} items pass; {issued.path}>" and len(text) <= 300
    assert recheck(str(issued.path)).passed
    with pytest.raises(pendverify.PendverifyError, match="exists"):
        pendverify.certify_set(tmp_path, default_parameter_file("double_pendulum"), samples=40)


def test_certify_set_takes_a_model_file_and_a_missing_urdf_is_named_in_api_words(tmp_path):
    from pendverify.certify.issue import recheck

    examples = Path(__file__).resolve().parents[2] / "examples"
    issued = pendverify.certify_set(
        tmp_path,
        analytic=examples / "cart_pole.py",
        urdf=examples / "cart_pole.urdf",
        urdf_params=examples / "cart_pole.toml",
        samples=40,
    )
    assert issued.certified and issued.certificate["model_source"]["text"].startswith('"""')
    assert recheck(str(issued.path), run_embedded_code=True).passed
    sentence = r"give --urdf \(urdf= in the Python API\): the URDF to verify cart_pole against"
    with pytest.raises(pendverify.PendverifyError, match=sentence):
        pendverify.certify_set(
            tmp_path / "b", analytic=examples / "cart_pole.py", urdf_params=examples / "cart_pole.toml"
        )


def test_certify_set_signs_with_a_key_and_recheck_trusts_only_that_key(tmp_path):
    from pendverify.analytic.params import default_parameter_file
    from pendverify.certify.issue import recheck
    from pendverify.certify.signing import generate_keys

    private, public, _ = generate_keys(tmp_path / "keys")
    _, other_public, _ = generate_keys(tmp_path / "other")
    params = default_parameter_file("double_pendulum")
    issued = pendverify.certify_set(tmp_path / "out", params, key=private, samples=40)
    assert issued.certified and issued.certificate["signature"]
    assert recheck(str(issued.path), trust=str(public)).passed
    with pytest.raises(pendverify.PendverifyError, match="not by the trusted key"):
        recheck(str(issued.path), trust=str(other_public))
    with pytest.raises(pendverify.PendverifyError, match="key"):
        pendverify.certify_set(tmp_path / "bad", params, key=tmp_path / "no-such.pem", samples=40)


def test_sweep_certifies_every_set_then_resume_keeps_them(tmp_path):
    """``api.sweep`` is ``certify --sweep``: each set's bundle written, then kept with ``resume``;
    a set whose certificate is removed is computed again, and bad arguments are refused."""
    from pendverify import api

    sweep = tmp_path / "sweep.toml"
    sweep.write_text(
        'model = "double_pendulum"\ncount = 2\nseed = 5\nsamples = 5\nduration = 0.05\n'
        "[ranges]\nm1 = [0.5, 2.0]\n"
    )
    out = tmp_path / "out"
    lines = []
    run, present = api.sweep(sweep, out, workers=1, log=lines.append)
    names = [f"double_pendulum-{i}" for i in range(2)]
    assert (run.total, run.written, run.skipped, present) == (2, 2, 0, 2)
    assert sorted(p.name for p in out.glob("*.cert.json")) == [f"{n}.cert.json" for n in names]
    assert lines == [] and not run.lost and not run.interrupted
    (out / f"{names[1]}.cert.json").unlink()
    run, present = api.sweep(sweep, out, workers=1, resume=True)
    assert (run.written, run.skipped, present) == (1, 1, 2)
    with pytest.raises(PendverifyError, match="resume"):
        api.sweep(sweep, out, resume="yes")
    with pytest.raises(PendverifyError, match="key 'workers' = 0: must be an integer >= 1"):
        api.sweep(sweep, tmp_path / "none", workers=0)
    with pytest.raises(PendverifyError, match="key 'worker_timeout' = -1: must be a finite number > 0"):
        api.sweep(sweep, tmp_path / "none", worker_timeout=-1)
    with pytest.raises(PendverifyError, match="exceed the limit of 1"):
        api.sweep(sweep, tmp_path / "small", max_sets=1)


def test_assert_verified_fails_on_a_model_alone_whose_units_agree():
    """A model without ``urdf`` gets its units row alone: nothing was compared with a robot, so the
    helper a user's test suite calls must not pass (the report says NOT verified)."""
    model = Path(__file__).resolve().parents[2] / "examples" / "minimal_double_pendulum.py"
    report = pendverify.check(model)
    assert report.passed and not report.robot_compared
    with pytest.raises(AssertionError, match="NOT verified"):
        assert_verified(model)
