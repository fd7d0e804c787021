"""Models given by q̈ alone: gymnasium's cart-pole and acrobot as they stand in its source.

The accelerations of ``gymnasium/envs/classic_control/cartpole.py`` (``step``) and
``acrobot.py`` (``_dsdt``, the default "book" variant) are written as text models (``qddot``,
``B``; the intermediate names of the source substituted as they are defined there) with
gymnasium's constants as the parameters, and verified against URDFs built here from those
constants: the inputs do not span the coordinates (one force, one torque), so M is not
determined and only ``aba`` runs, over states and inputs.  A planted error fails; the
"nips" acrobot variant, which leaves out the term m2 l1 lc2 θ̇1² sin θ2 of ddθ2, fails too.
The constants are read from the installed gymnasium (its source is not copied); the URDFs are
``tests/analytic/gym_robots.py``'s.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import pendverify
from pendverify.analytic.plugin import load_model_class
from tests.analytic.gym_robots import acrobot_urdf, cart_pole_urdf

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.envs.classic_control.acrobot import AcrobotEnv  # noqa: E402
from gymnasium.envs.classic_control.cartpole import CartPoleEnv  # noqa: E402

SAMPLES = 100  # the zero state plus 100 random states and inputs


def _substituted(text: str, definitions: list[tuple[str, str]]) -> str:
    """``text`` with each name replaced by its definition (parenthesised), last defined first."""
    for name, value in reversed(definitions):
        text = text.replace(name, f"({value})")
    return text


# cartpole.py, step(): its names, as the source defines them
CART_POLE = [
    ("total_mass", "masspole + masscart"),
    ("polemass_length", "masspole * length"),
    ("temp", "(force + polemass_length * dtheta**2 * sin(theta)) / total_mass"),
    ("thetaacc", "(g * sin(theta) - cos(theta) * temp)"
                 " / (length * (4.0 / 3.0 - masspole * cos(theta)**2 / total_mass))"),
    ("xacc", "temp - polemass_length * thetaacc * cos(theta) / total_mass"),
]  # fmt: skip
# acrobot.py, _dsdt() ("book"): its names, as the source defines them
ACROBOT = [
    ("d1", "m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * cos(theta2)) + I1 + I2"),
    ("d2", "m2 * (lc2**2 + l1 * lc2 * cos(theta2)) + I2"),
    ("phi2", "m2 * lc2 * g * cos(theta1 + theta2 - pi / 2.0)"),
    ("phi1", "-m2 * l1 * lc2 * dtheta2**2 * sin(theta2) - 2 * m2 * l1 * lc2 * dtheta2 * dtheta1 * sin(theta2)"
             " + (m1 * lc1 + m2 * l1) * g * cos(theta1 - pi / 2) + phi2"),
    ("ddtheta2", "(a + d2 / d1 * phi1 - m2 * l1 * lc2 * dtheta1**2 * sin(theta2) - phi2)"
                 " / (m2 * lc2**2 + I2 - d2**2 / d1)"),
    ("ddtheta1", "-(d2 * ddtheta2 + phi1) / d1"),
]  # fmt: skip


def _param(name: str, kind: str) -> str:
    return f'{name} = {{ kind = "{kind}" }}'


CART_POLE_KINDS = (("masscart", "mass"), ("masspole", "mass"), ("length", "offset"), ("g", "gravity"))


def cart_pole_files(tmp_path: Path, definitions=CART_POLE) -> tuple[Path, Path, Path]:
    env = CartPoleEnv()
    xacc, thetaacc = (_substituted(name, definitions) for name in ("xacc", "thetaacc"))
    model = tmp_path / "gym_cart_pole.toml"
    model.write_text(
        f'name = "gym_cart_pole"\ninputs = ["force"]\nqddot = ["{xacc}", "{thetaacc}"]\nB = [["1"], ["0"]]\n'
        '[coordinates]\nx = "position"\ntheta = "angle"\n[parameters]\n'
        + "\n".join(_param(n, k) for n, k in CART_POLE_KINDS)
        + '\n[urdf]\njoints = ["slider", "hinge"]\n'
    )  # fmt: skip
    params = tmp_path / "gym_cart_pole_params.toml"
    params.write_text(
        f'model = "gym_cart_pole"\n[parameters]\nmasscart = {env.masscart}\nmasspole = {env.masspole}\n'
        f"length = {env.length}\ng = {env.gravity}\n"
    )
    urdf = tmp_path / "gym_cart_pole.urdf"
    urdf.write_text(cart_pole_urdf(env))
    return model, urdf, params


def acrobot_files(tmp_path: Path, definitions=ACROBOT) -> tuple[Path, Path, Path]:
    env = AcrobotEnv()
    assert env.book_or_nips == "book"
    acc = [_substituted(name, definitions) for name in ("ddtheta1", "ddtheta2")]
    model = tmp_path / "gym_acrobot.toml"
    kinds = (("m1", "mass"), ("m2", "mass"), ("l1", "length"), ("lc1", "offset"), ("lc2", "offset"),
             ("I1", "inertia"), ("I2", "inertia"), ("g", "gravity"))  # fmt: skip
    model.write_text(
        f'name = "gym_acrobot"\ninputs = ["a"]\nqddot = ["{acc[0]}", "{acc[1]}"]\nB = [["0"], ["1"]]\n'
        '[coordinates]\ntheta1 = "angle"\ntheta2 = "angle"\n[parameters]\n'
        + "\n".join(_param(n, k) for n, k in kinds)
        + '\n[urdf]\njoints = ["joint1", "joint2"]\n'
    )
    values = dict(
        m1=env.LINK_MASS_1, m2=env.LINK_MASS_2, l1=env.LINK_LENGTH_1, lc1=env.LINK_COM_POS_1,
        lc2=env.LINK_COM_POS_2, I1=env.LINK_MOI, I2=env.LINK_MOI, g=9.8,  # _dsdt's own g = 9.8
    )  # fmt: skip
    params = tmp_path / "gym_acrobot_params.toml"
    lines = "".join(f"{k} = {v}\n" for k, v in values.items())
    params.write_text(f'model = "gym_acrobot"\n[parameters]\n{lines}')
    urdf = tmp_path / "gym_acrobot.urdf"
    urdf.write_text(acrobot_urdf(env))
    return model, urdf, params


def _check(files):
    return pendverify.check(*files, samples=SAMPLES)


@pytest.mark.parametrize("files", [cart_pole_files, acrobot_files])
def test_gymnasiums_accelerations_verify_by_aba_and_say_what_did_not_run(files, tmp_path):
    report = _check(files(tmp_path))
    assert report.status == "pass", report
    assert report.checks == ("units", "aba")
    notes = " ".join(n for ns in report.notes.values() for n in ns)
    for check in ("crba", "rnea", "gravity", "energy"):
        assert check in notes
    assert "gives q̈ alone and its inputs do not span the coordinates" in notes
    assert "are the URDF's" in notes


@pytest.mark.slow
@pytest.mark.parametrize(
    "files, definitions, name, old, new",
    [
        # the rod's 4/3 (I about the pivot over m·length²) made 5/3
        (cart_pole_files, CART_POLE, "thetaacc", "4.0 / 3.0", "5.0 / 3.0"),
        (cart_pole_files, CART_POLE, "temp", "(force +", "(2 * force +"),  # the force counted twice
        (acrobot_files, ACROBOT, "d2", "+ I2", "+ 2 * I2"),
        # gymnasium's "nips" variant: ddθ2 without the term m2 l1 lc2 θ̇1² sin θ2
        (acrobot_files, ACROBOT, "ddtheta2", "- m2 * l1 * lc2 * dtheta1**2 * sin(theta2) ", ""),
    ],
)
def test_a_planted_error_fails(files, definitions, name, old, new, tmp_path):
    changed = [(n, v.replace(old, new) if n == name else v) for n, v in definitions]
    assert changed != definitions
    report = _check(files(tmp_path, changed))
    assert report["aba"].status == "fail", report


def test_q_ddot_alone_needs_B_when_there_are_inputs(tmp_path):
    model, _, _ = cart_pole_files(tmp_path)
    model.write_text(model.read_text().replace('B = [["1"], ["0"]]\n', ""))
    with pytest.raises(pendverify.PendverifyError, match="q̈ alone needs B too"):
        load_model_class(model)


# cartpole.py, step() printed as a paper would: T is its `temp`, θ̈ written out in ẍ
CART_POLE_LATEX = r"""name = "gym_cart_pole"
notation = "latex"
inputs = ["force"]
qddot = '''
\begin{bmatrix}
T - \frac{m_p l \cos\theta}{m_c + m_p}\,
  \frac{g\sin\theta - T\cos\theta}{l\left(\frac{4}{3} - \frac{m_p\cos^2\theta}{m_c + m_p}\right)} \\
\frac{g\sin\theta - T\cos\theta}{l\left(\frac{4}{3} - \frac{m_p\cos^2\theta}{m_c + m_p}\right)}
\end{bmatrix}
'''
B = '\begin{bmatrix} 1 \\ 0 \end{bmatrix}'
[coordinates]
x = "position"
theta = "angle"
[parameters]
masscart = { kind = "mass" }
masspole = { kind = "mass" }
length = { kind = "offset" }
g = { kind = "gravity" }
[symbols]
'\theta' = "theta"
'g' = "g"
'm_c' = "masscart"
'm_p' = "masspole"
'l' = "length"
'T' = "(force + masspole*length*dtheta**2*sin(theta))/(masscart + masspole)"
[urdf]
joints = ["slider", "hinge"]
"""


@pytest.mark.parametrize("planted", [False, True])
def test_q_ddot_alone_in_latex_verifies_and_a_planted_error_fails(planted, tmp_path):
    """LaTeX q̈ without M (one input, two coordinates): aba only; the rod's 4/3 made 5/3 fails."""
    _, urdf, params = cart_pole_files(tmp_path)
    text = CART_POLE_LATEX.replace(r"\frac{4}{3}", r"\frac{5}{3}") if planted else CART_POLE_LATEX
    assert (text != CART_POLE_LATEX) == planted
    model = tmp_path / "gym_cart_pole_latex.toml"
    model.write_text(text)
    report = pendverify.check(model, urdf, params, samples=SAMPLES, explain=False)
    assert report.checks == ("units", "aba")
    assert report["aba"].status == ("fail" if planted else "pass"), report
