"""Every way of giving the double pendulum's equations yields the same verdicts, and one error fails each.

The double pendulum reference system as a class (``examples/minimal_double_pendulum.py``), a
text file (``examples/minimal_double_pendulum_text.toml``), LaTeX parts
(``examples/double_pendulum_latex.toml``), LaTeX whole equations, a LaTeX matrix equation over
LaTeX parts (M q̈ + C q̇ + D q̇ + G = B u), q̈ alone (M derived from
q̈ and B), a ``LagrangesMethod`` and q̈ as Python code (``qddot(q, v, u)`` solving M q̈ = f with
NumPy, B = I): against the same URDF and parameter values, each check that runs on two forms
has the same verdict on both (all pass); doubling link 2's inertia in M's last entry (or, for
the mechanics model, in link 2's body) fails crba in every form, the code form's M being derived
from its q̈ (``pendverify.analytic.numeric_derivation``: with B = I, M, H and C·q̇ are derived
numerically, and energy, coriolis, skew, det and minverse do not run on it).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import pendverify
from tests.analytic.mechanics_double_pendulum import DECLARATION, lagrange
from tests.analytic.test_matrix_equation import latex_file
from tests.analytic.test_whole_equations import LATEX, equations_file

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "urdf" / "double_pendulum.urdf"
MINIMAL_PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
REFERENCE_PARAMS = REPO / "analytic" / "params" / "double_pendulum.toml"  # the same values, and l2
SAMPLES = 60

M11 = "(I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2) + 2*m2*l1*r2*cos(theta2))"
M12 = "(I2 + m2*r2**2 + m2*l1*r2*cos(theta2))"
M22 = "(I2 + m2*r2**2)"
F1 = (
    "(tau1 - b1*dtheta1 + m2*l1*r2*sin(theta2)*(2*dtheta1*dtheta2 + dtheta2**2)"
    " - g*((m1*r1 + m2*l1)*cos(theta1) + m2*r2*cos(theta1 + theta2)))"
)
F2 = "(tau2 - b2*dtheta2 - m2*l1*r2*sin(theta2)*dtheta1**2 - g*m2*r2*cos(theta1 + theta2))"


def _copy(tmp_path: Path, source: Path, old: str = "", new: str = "") -> Path:
    text = source.read_text()
    assert old in text
    path = tmp_path / source.name
    path.write_text(text.replace(old, new))
    return path


def _qddot_file(tmp_path: Path, m22: str = M22) -> Path:
    """q̈ = M⁻¹ f written out (the 2 × 2 inverse), B = I: M is derived from q̈."""
    det = f"({M11}*{m22} - {M12}**2)"
    qdd = [f"({m22}*{F1} - {M12}*{F2})/{det}", f"({M11}*{F2} - {M12}*{F1})/{det}"]
    text = (REPO / "examples" / "minimal_double_pendulum_text.toml").read_text()
    head, tables = text.split("[coordinates]", 1)
    keep = [line for line in head.splitlines() if line.startswith(("name", "inputs"))]
    body = "\n".join(keep) + f'\nqddot = ["{qdd[0]}", "{qdd[1]}"]\nB = [["1", "0"], ["0", "1"]]\n'
    body += 'D = [["b1", "0"], ["0", "b2"]]\n[coordinates]' + tables
    path = tmp_path / "qddot.toml"
    path.write_text(body)
    return path


CODE = f"""\
import numpy as np
from math import cos, sin


def qddot(q, v, u, *, m1, m2, l1, r1, r2, I1, I2, b1, b2, g):
    theta1, theta2 = q
    dtheta1, dtheta2 = v
    tau1, tau2 = u
    M = np.array([[{M11}, {M12}], [{M12}, {M22}]])
    f = np.array([{F1}, {F2}])
    return np.linalg.solve(M, f)


DYNAMICS = qddot
DECLARATION = {{
    **DECLARATION,
    "dynamics": "qddot(q, v, u)",
    "B": [["1", "0"], ["0", "1"]],
    "D": [["b1", "0"], ["0", "b2"]],
}}
"""


def _code_file(tmp_path: Path, m22: str = M22) -> Path:
    """q̈ as Python code: M and f as NumPy arrays, solved; its declaration the mechanics model's."""
    path = tmp_path / "qddot_code.py"
    head = "from tests.analytic.mechanics_double_pendulum import DECLARATION\n"
    code = CODE.replace(f", {M22}]])", f", {m22}]])")
    assert (code != CODE) == (m22 != M22)
    path.write_text(head + code)
    return path


def _forms(tmp_path: Path, planted: bool) -> dict[str, dict]:
    """Each form's check arguments (right, or with link 2's inertia doubled in M's last entry)."""
    folder = tmp_path / ("planted" if planted else "right")
    folder.mkdir()
    examples = REPO / "examples"
    doubled = {
        "class": ("beta, delta = p.m2 * p.l1 * p.r2, p.I2 +", "beta, delta = p.m2 * p.l1 * p.r2, 2 * p.I2 +"),
        "text": ('"I2 + m2*r2**2"]', '"2*I2 + m2*r2**2"]'),
        "latex": ("'\\delta' = \"I2 + m2*r2**2\"", "'\\delta' = \"2*I2 + m2*r2**2\""),
        "whole": (r"\delta\,\ddot{\theta}_2", r"2\delta\,\ddot{\theta}_2"),
        "matrix": ("'\\delta' = \"I2 + m2*r2**2\"", "'\\delta' = \"2*I2 + m2*r2**2\""),
    }
    change = {k: (v if planted else ("", "")) for k, v in doubled.items()}
    return {
        "class": dict(model=_copy(folder, examples / "minimal_double_pendulum.py", *change["class"])),
        "text": dict(model=_copy(folder, examples / "minimal_double_pendulum_text.toml", *change["text"])),
        "LaTeX parts": dict(
            model=_copy(folder, examples / "double_pendulum_latex.toml", *change["latex"]),
            params=REFERENCE_PARAMS,
        ),
        "LaTeX whole equations": dict(
            model=equations_file(folder, LATEX.replace(*change["whole"]), latex=True)
        ),
        "LaTeX matrix equation": dict(
            model=latex_file(folder, r"M\ddot{q} + C\dot{q} + D\dot{q} + G = B u", **dict([change["matrix"]]))
        ),
        "q̈ alone": dict(model=_qddot_file(folder, "(2*I2 + m2*r2**2)" if planted else M22)),
        "LagrangesMethod": dict(model=lagrange(2 if planted else 1), declaration=DECLARATION),
        "q̈ as code": dict(model=_code_file(folder, "(2*I2 + m2*r2**2)" if planted else M22)),
    }


#: the forms whose M, H and C·q̇ are derived numerically from q̈ as code: no V, matrix C, det or M⁻¹
DERIVED_NUMERICALLY = ("q̈ as code",)


def _verdicts(arguments: dict) -> dict[str, str]:
    arguments = {"params": MINIMAL_PARAMS, **arguments}
    report = pendverify.check(urdf=URDF, samples=SAMPLES, explain=False, **arguments)
    return {check: report[check].status for check in report.checks}


def test_every_form_gives_the_same_verdicts(tmp_path):
    verdicts = {name: _verdicts(arguments) for name, arguments in _forms(tmp_path, False).items()}
    for name, found in verdicts.items():
        if name in DERIVED_NUMERICALLY:
            assert set(found) == {"crba", "rnea", "gravity", "aba", "damping"}, (name, found)
        else:
            assert {"crba", "rnea", "gravity", "aba", "energy"} <= set(found), name
        for other, theirs in verdicts.items():
            for check in set(found) & set(theirs):
                assert found[check] == theirs[check], (name, other, check)
    assert all(status == "pass" for found in verdicts.values() for status in found.values()), verdicts


@pytest.mark.parametrize(
    "form",
    [
        "class",
        "text",
        "LaTeX parts",
        "LaTeX whole equations",
        "LaTeX matrix equation",
        "q̈ alone",
        "LagrangesMethod",
        "q̈ as code",
    ],
)
def test_a_doubled_inertia_in_M_fails_crba_in_every_form(form, tmp_path):
    """crba in every form, the code form's M derived numerically from its q̈."""
    assert _verdicts(_forms(tmp_path, True)[form])["crba"] == "fail"
