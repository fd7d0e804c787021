"""One coordinate: every 1 × 1 matrix stays a matrix, in every key and every text-like form.

A model with one coordinate has a 1 × 1 M, C, D, M⁻¹ (and a 1 × 1 B with one input); they are
matrices, not one-entry vectors, whatever form the file takes.  The single pendulum of
``tests/analytic/one_coordinate_models.py`` written as text (every key; Cqdot; C_plus_D; f;
whole equations; matrix equations), as LaTeX (``bmatrix``es, bare entries, lists), by q̈ alone,
as a ``sympy.physics.mechanics`` METHOD (Lagrange, Kane, an (M, forcing) pair) and as DYNAMICS
code (f(x, u), f(t, x, u), qddot(q, v, u)) passes ``pendverify check`` against its URDF, and a
planted error in one entry of each fails (exit 1) on the check it touches, the diagnosis naming
the entry where the form gives one; so does a cart on an inclined rail (a position coordinate).
A quantity of the wrong shape is still refused: a 1 × 2 M, a vector H written as a matrix, a
DYNAMICS D written as a vector, a Python model whose mass matrix returns a vector.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from pendverify.analytic.plugin import load_model_class
from pendverify.cli import main
from tests.analytic.one_coordinate_models import (
    CART,
    CART_PARAMS,
    CART_URDF,
    FORMS,
    PEND_PARAMS,
    PEND_URDF,
)
from tests.error_message import one_error

SAMPLES = "30"  # the special states plus 30 random ones: a planted error shows on every state
ROW = re.compile(r"^\S+\s+(\w+)\s+[0-9.e+-]+\s+[0-9.e+-]+\s+.*\s(pass|FAIL)\s*$")


def _check(tmp_path: Path, capsys, model: str, suffix: str, urdf=PEND_URDF, params=PEND_PARAMS, name="m"):
    """(exit status, {check: verdict}, stdout, stderr) of ``pendverify check`` on the model text."""
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "params.toml").write_text(params)
    path = tmp_path / f"{name}{suffix}"
    path.write_text(model)
    code = main(
        ["check", "--analytic", str(path), "--urdf", str(tmp_path / "robot.urdf"),
         "--params", str(tmp_path / "params.toml"), "--samples", SAMPLES]
    )  # fmt: skip
    out, err = capsys.readouterr()
    rows = {m.group(1): m.group(2) for m in map(ROW.match, out.splitlines()) if m}
    return code, rows, out, err


@pytest.mark.parametrize("form", list(FORMS))
def test_the_single_pendulum_passes_in_every_form(form, tmp_path, capsys):
    suffix, text, _ = FORMS[form]
    code, rows, out, err = _check(tmp_path, capsys, text, suffix)
    assert code == 0, (err, out[-3000:])
    assert rows and set(rows.values()) == {"pass"}, out[-3000:]
    assert {"aba"} <= rows.keys()


@pytest.mark.parametrize("form", list(FORMS))
def test_a_planted_error_in_one_entry_fails_in_every_form(form, tmp_path, capsys):
    suffix, text, (old, new, check, entry) = FORMS[form]
    assert text.count(old) == 1, old
    code, rows, out, err = _check(tmp_path, capsys, text.replace(old, new), suffix)
    assert code == 1, (err, out[-3000:])
    assert rows[check] == "FAIL", out[-3000:]
    if entry is not None:
        assert re.search(rf"^diagnosis \[pend:\w+\]: {re.escape(entry)} ", out, re.M), out[-3000:]


def test_every_method_of_a_one_coordinate_text_model_has_its_keys_shape(tmp_path):
    """M, C, D, B, M⁻¹ are 1 × 1, H and q̈ one-entry vectors, V and det M scalars."""
    path = tmp_path / "pend.toml"
    path.write_text(FORMS["text, every key"][1])
    cls = load_model_class(path)
    model = cls(cls.params_type(m=2.0, l=0.5, b=0.1, g=9.81))
    q, v, u, w = np.array([0.3]), np.array([-0.7]), np.array([1.1]), np.zeros(0)
    assert np.shape(model.mass_matrix(q)) == (1, 1)
    assert np.shape(model.coriolis_matrix(q, v)) == (1, 1)
    assert np.shape(model.damping_matrix()) == (1, 1)
    assert np.shape(model.input_matrix()) == (1, 1)
    assert np.shape(model.inverse_mass_matrix(q)) == (1, 1)
    assert np.shape(model.gravity(q)) == (1,)
    assert np.shape(model.acceleration(q, v, u, w)) == (1,)
    assert np.ndim(model.potential_energy(q)) == np.ndim(model.det_mass_matrix(q)) == 0
    assert model.mass_matrix(q)[0, 0] == pytest.approx(2.0 * 0.5**2)
    assert model.inverse_mass_matrix(q)[0, 0] * model.mass_matrix(q)[0, 0] == pytest.approx(1.0)


def test_a_cart_on_an_inclined_rail_passes_and_a_planted_error_fails(tmp_path, capsys):
    code, rows, out, err = _check(tmp_path, capsys, CART, ".toml", CART_URDF, CART_PARAMS)
    assert code == 0 and set(rows.values()) == {"pass"}, (err, out[-3000:])
    assert {"crba", "gravity", "damping"} <= rows.keys()
    code, rows, out, _ = _check(
        tmp_path, capsys, CART.replace('H = ["4*m*g/5"]', 'H = ["3*m*g/5"]'), ".toml", CART_URDF, CART_PARAMS
    )
    assert code == 1 and rows["gravity"] == "FAIL", out[-3000:]
    assert re.search(r"^diagnosis \[cart:\w+\]: H\[1\] ", out, re.M), out[-3000:]


_PYTHON_VECTOR_M = """
import dataclasses
import numpy as np
from pendverify.analytic import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class PendParams(ParameterSet):
    model = "pend"
    m: float = quantity("mass", "in [kg]")
    l: float = quantity("length", "in [m]")
    b: float = quantity("damping", "in [N·m·s/rad]")
    g: float = quantity("gravity", "in [m/s²]")


class Pend(ClosedFormModel):
    name = "pend"
    params_type = PendParams
    coordinates = ("theta",)
    angular = (True,)
    urdf_joints = ("hinge",)

    def mass_matrix(self, q):
        return np.array([self.params.m * self.params.l**2])  # a vector: the planted error

    def coriolis_matrix(self, q, v):
        return np.zeros((1, 1))

    def gravity(self, q):
        return np.array([self.params.m * self.params.g * self.params.l * self.math.sin(q[0])])

    def potential_energy(self, q):
        return -self.params.m * self.params.g * self.params.l * self.math.cos(q[0])
"""


@pytest.mark.parametrize(
    "suffix, model, words",
    [
        (".toml", FORMS["text, every key"][1].replace('M = [["m*l**2"]]', 'M = [["m*l**2", "0"]]'),
         ["key 'M'", "wrong shape", "1 × 1", "1 row,", "1 entry"]),
        (".toml", FORMS["text, W"][1].replace('H = ["m*g*l*sin(theta)"]', 'H = [["m*g*l*sin(theta)"]]'),
         ["key 'H'", "wrong shape", "vector of 1 entry"]),
        (".toml", FORMS["LaTeX, every key as a bmatrix"][1].replace(r"m l^2 \end", r"m l^2 & 0 \end", 1),
         ["key 'M'", "the LaTeX gives 1 row of 2 entries", "with 1 coordinate M must be 1 × 1"]),
        (".toml", FORMS["LaTeX, lists of entries"][1].replace("M = [['m l^2']]", "M = ['m l^2']"),
         ["key 'M'", "a list of rows, each a list of LaTeX entries", "1 × 1"]),
        (".py", FORMS["DYNAMICS f(x, u)"][1].replace('"D": [["b"]]', '"D": ["b"]'),
         ["key 'D'", "wrong shape", "1 × 1"]),
        (".py", _PYTHON_VECTOR_M, ["Pend.mass_matrix", "shape (1,)", "expected (1, 1)"]),
    ],
)  # fmt: skip
def test_a_quantity_of_the_wrong_shape_is_still_refused(suffix, model, words, tmp_path, capsys):
    code, _, _, err = _check(tmp_path, capsys, model, suffix)
    assert code == 2, err
    headline, _, _ = one_error(err)
    for word in words:
        assert word in headline, headline


def test_a_one_coordinate_entry_is_labelled_by_the_interface_not_by_its_one_column(tmp_path, capsys):
    """A 1×1 M is the matrix entry M[1,1] in every label (diagnosis, repair, sympy, mutate); H is H[1]."""
    from pendverify.diagnosis.slots import entry_label
    from pendverify.symbolic.mutants import entry_label as mutant_label

    x = sp.Symbol("x")
    assert entry_label("mass_matrix", sp.Matrix([[x]]), 0) == "M[1,1]"
    assert entry_label("gravity", sp.Matrix([x]), 0) == "H[1]"
    assert entry_label("gravity", sp.Matrix([x, x]), 1) == "H[2]"
    assert mutant_label("damping_matrix", sp.Matrix([[x]]), 0) == "damping_matrix[0,0]"
    assert mutant_label("gravity", sp.Matrix([x]), 0) == "gravity[0]"
    suffix, text, _ = FORMS["text, every key"]
    code, _, out, _ = _check(tmp_path, capsys, text.replace('M = [["m*l**2"]]', 'M = [["2*m*l**2"]]'), suffix)
    assert code == 1
    repairs = [line for line in out.splitlines() if "makes every check pass" in line]
    assert repairs and all("entry M[1,1])" in line for line in repairs), out[-3000:]
