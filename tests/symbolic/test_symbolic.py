"""SymPy as a third opinion: both seeds equal their Lagrangian derivation, planted errors do not.

The key case is a wrong assumption shared by the hand model and the URDF: the
numerical checks cannot see it (both sides agree), the derivation from the
energies written from the stated conventions does.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from pendverify.analytic import MODELS, CartDoublePendulum, DoublePendulum
from pendverify.analytic.forms import Energies
from pendverify.analytic.plugin import load_model_class
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.catalogue import run_checks
from pendverify.checks.sampling import sample_states
from pendverify.checks.verdict import CHRISTOFFEL_CONSISTENT, NON_CHRISTOFFEL
from pendverify.cli import main
from pendverify.errors import PendverifyError
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for
from pendverify.symbolic.compare import DIFFERS, EQUAL, SKIPPED, WARNING, compare
from pendverify.symbolic.lagrange import derive
from pendverify.symbolic.work import DEFAULT_MAX_SYMBOLIC, MAX_SYMBOLIC_VARIABLE, symbolic_work
from pendverify.symbolic.zero_test import is_zero
from tests.cli_run import Done, run_main

from ..conftest import SEED, default_params


@pytest.mark.parametrize("cls", list(MODELS.values()), ids=list(MODELS))
def test_seed_closed_forms_equal_their_lagrangian(cls):
    report = compare(cls)
    assert report.passed
    statuses = {c.method: c.status for c in report.comparisons}
    # every closed form is read, the cart's q̈ = M⁻¹(y) f(y, ẏ, u, w) included
    assert {m for m, s in statuses.items() if s == SKIPPED} == set()
    assert all(s in (EQUAL, SKIPPED) for s in statuses.values()), statuses
    # term by term: every entry of every closed form was compared
    assert sum(c.entries for c in report.comparisons) == (31 if cls is DoublePendulum else 61)
    extra = "seed_coriolis_matrix" if cls is DoublePendulum else "f"
    assert statuses[extra] == EQUAL


def test_derivation_gives_the_textbook_quantities():
    sm = SymbolicModel.of(DoublePendulum)
    lag = derive(sm)
    p = sm.parameters
    t2 = sm.symbols["q"][1]
    beta = p["m2"] * p["l1"] * p["r2"]
    assert is_zero(lag.M[1, 1] - (p["I2"] + p["m2"] * p["r2"] ** 2), sm.angles)
    assert is_zero(lag.M[0, 1] - (p["I2"] + p["m2"] * p["r2"] ** 2 + beta * sp.cos(t2)), sm.angles)
    assert lag.D == sp.diag(p["b1"], p["b2"]) and lag.B == sp.eye(2) and lag.W.shape == (2, 0)


# --- a wrong assumption shared by the URDF and the hand model ---------------------------------
class PivotInertia(DoublePendulum):
    """Treats I1, I2 as inertias about the joints: the parallel-axis m·r² terms are left out."""

    @property
    def alpha(self):
        p = self.params
        return p.I1 + p.I2 + p.m2 * p.l1**2

    @property
    def delta(self):
        return self.params.I2


def test_shared_wrong_assumption_passes_numerically_but_not_symbolically():
    params = default_params("double_pendulum").replace(I1=0.09, I2=0.06)
    # the URDF written under the same belief: its centre-of-mass inertia is I − m·r²
    urdf_params = params.replace(
        I1=params.I1 - params.m1 * params.r1**2, I2=params.I2 - params.m2 * params.r2**2
    )
    model = PivotInertia(params)
    system = PinocchioSystem.for_model(DoublePendulum, urdf_for(urdf_params), params.g)
    results = run_checks("pivot", model, system, sample_states(model, 40, SEED), SEED)
    assert all(r.passed for r in results), [r.name for r in results if not r.passed]

    report = compare(PivotInertia)
    assert not report.passed
    mass = next(c for c in report.comparisons if c.method == "mass_matrix")
    assert mass.status == DIFFERS
    assert any("M[1,1]: -m2*r2**2" in d for d in mass.differences), mass.differences
    assert any("M[0,0]: -m1*r1**2 - m2*r2**2" in d for d in mass.differences), mass.differences


# --- Coriolis factorisations ------------------------------------------------------------------
class NotChristoffel(DoublePendulum):
    """Same C·q̇ as the seed, but −β sin θ2 θ̇1·θ̇2 moved from column 2 to column 1 of row 1."""

    def seed_coriolis_matrix(self, q, v):
        b, s = self.beta, self.math.sin(q[1])
        return np.array([[-2 * b * s * v[1] + self.params.b1, -b * s * v[1]], [b * s * v[0], self.params.b2]])


class SkewShifted(CartDoublePendulum):
    """C + c·[q̇]×: same C·q̇ (q̇ × q̇ = 0) and Ṁ − 2C still skew, yet not the Christoffel C."""

    def coriolis_matrix(self, y, yd):
        c = self.params.m1
        cross = np.array([[0, -yd[2], yd[1]], [yd[2], 0, -yd[0]], [-yd[1], yd[0], 0]])
        return super().coriolis_matrix(y, yd) + c * cross


@pytest.mark.parametrize(
    ("cls", "verdict"),
    [
        (NotChristoffel, NON_CHRISTOFFEL),
        (SkewShifted, CHRISTOFFEL_CONSISTENT),
    ],
)
def test_other_coriolis_factorisations_are_warnings(cls, verdict):
    report = compare(cls)
    coriolis = next(c for c in report.comparisons if c.method == "coriolis_matrix")
    assert coriolis.status == WARNING
    assert verdict in coriolis.note
    assert report.passed  # a warning, not a failure


class WrongSign(CartDoublePendulum):
    def coriolis_matrix(self, y, yd):
        C = super().coriolis_matrix(y, yd)
        C[0, 2] = -C[0, 2]
        return C


def test_wrong_coriolis_term_differs():
    report = compare(WrongSign)
    coriolis = next(c for c in report.comparisons if c.method == "coriolis_matrix")
    assert coriolis.status == DIFFERS and not report.passed
    assert coriolis.differences == ["C[0,2]: 2*dtheta2*l2*m2*sin(theta2)"]


# --- the zero test and the derivation's guards ------------------------------------------------
def test_zero_test_decides_trigonometric_identities():
    a, b, x = sp.symbols("a b x", real=True)
    angles = (a, b)
    assert is_zero(sp.sin(a) ** 2 + sp.cos(a) ** 2 - 1, angles)
    assert is_zero(sp.cos(a - b) - sp.cos(a) * sp.cos(b) - sp.sin(a) * sp.sin(b), angles)
    assert is_zero(
        (sp.sin(a) ** 4 - sp.cos(a) ** 4) / (1 + x**2) - (1 - 2 * sp.cos(a) ** 2) / (1 + x**2), angles
    )
    assert not is_zero(sp.cos(a + b) - sp.cos(a - b), angles)
    assert not is_zero(sp.sin(a) * sp.Rational(1001, 1000) - sp.sin(a), angles)
    assert not is_zero(sp.sin(sp.Rational(1001, 1000) * a) - sp.sin(a), angles)  # outside the class: probe
    assert is_zero(sp.sqrt(x**2 + 1) ** 2 - x**2 - 1, angles)


class LinearKinetic(DoublePendulum):
    def energies(self, q, v, u, w):
        e = super().energies(q, v, u, w)
        return Energies(e.kinetic + self.params.m1 * v[0], e.potential, e.dissipation, e.power)


class NoEnergies(DoublePendulum):
    def energies(self, q, v, u, w):
        return None


class NumericTrig(DoublePendulum):
    def gravity(self, q):
        return np.array([math.cos(q[0]), 0.0])


@pytest.mark.parametrize(
    ("cls", "message"),
    [
        (LinearKinetic, "the kinetic energy is not a quadratic form"),
        (NoEnergies, "defines no energies(q, v, u, w)"),
        (NumericTrig, "NumericTrig.gravity cannot be read by SymPy"),
    ],
)
def test_models_sympy_cannot_use_are_named_errors(cls, message):
    with pytest.raises(PendverifyError, match=message.replace("(", r"\(").replace(")", r"\)")):
        compare(cls)


def test_sympy_command(capsys):
    assert main(["sympy", "--model", "cart_double_pendulum"]) == 0
    out = capsys.readouterr().out
    assert "61 entries" in out and "every closed form equals its derivation" in out
    assert main(["sympy", "--model", "triple"]) == 2


# --- bounded work: the derivation's size is estimated before it starts ------------------------------
def _dense_text_model(path: Path, n: int) -> Path:
    """A text model whose n × n mass matrix is dense: every pair of coordinates is coupled."""

    def entry(i: int, j: int) -> str:
        a, b = min(i, j), max(i, j)
        return f'"{n + 1}*m1 + m1*cos(q{i})**2"' if i == j else f'"m1*cos(q{a} - q{b})/{n}"'

    rows = ",\n".join("[" + ", ".join(entry(i, j) for j in range(n)) + "]" for i in range(n))
    lines = [
        'name = "dense"',
        f"M = [\n{rows}\n]",
        'V = "' + " + ".join(f"g*m1*sin(q{i})" for i in range(n)) + '"',
        "Cqdot = [" + ", ".join('"0"' for _ in range(n)) + "]",
        "[coordinates]",
        *(f'q{i} = "angle"' for i in range(n)),
        "[parameters]",
        'm1 = { kind = "mass", unit = "kg" }',
        'g = { kind = "gravity", unit = "m/s²" }',
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def _sympy_cli(*args: str, env: dict | None = None) -> Done:
    """``pendverify sympy ARGS`` in-process with ``env`` set (the limit is read at each call)."""
    with pytest.MonkeyPatch.context() as mp:
        for name, value in (env or {}).items():
            mp.setenv(name, value)
        return run_main(["sympy", *args])


@pytest.mark.slow
def test_a_dense_50_dof_model_is_refused_before_the_derivation_naming_the_limit(tmp_path):
    model = _dense_text_model(tmp_path / "dense.toml", 50)
    result = _sympy_cli("--analytic", str(model))
    err = result.stderr.strip()
    assert result.returncode == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert str(model) in err and f"limit of {DEFAULT_MAX_SYMBOLIC}" in err and MAX_SYMBOLIC_VARIABLE in err


@pytest.mark.slow
def test_the_symbolic_limit_is_overridden_from_the_environment(tmp_path):
    lowered = _sympy_cli("--model", "double_pendulum", env={MAX_SYMBOLIC_VARIABLE: "100"})
    assert lowered.returncode == 2 and "limit of 100" in lowered.stderr, lowered.stderr
    model = _dense_text_model(tmp_path / "dense.toml", 4)
    n, ops = symbolic_work(SymbolicModel.of(load_model_class(model)))
    refused = _sympy_cli("--analytic", str(model), env={MAX_SYMBOLIC_VARIABLE: str(n * ops - 1)})
    assert refused.returncode == 2 and f"limit of {n * ops - 1}" in refused.stderr
    allowed = _sympy_cli("--analytic", str(model), "--quiet", env={MAX_SYMBOLIC_VARIABLE: str(n * ops)})
    assert allowed.returncode == 1, allowed.stderr  # read and compared: its Cqdot = 0 differs
    bad = _sympy_cli("--model", "double_pendulum", env={MAX_SYMBOLIC_VARIABLE: "lots"})
    assert bad.returncode == 2 and f"key '{MAX_SYMBOLIC_VARIABLE}'" in bad.stderr, bad.stderr
