"""Every check must be able to fail: plant wrong hand models and wrong URDFs.

Each planted error is a subclass that changes one term of a seed model.  The
suite must report it as a failure of the check that looks at that term (other
checks may fail too), while the untouched model passes everything.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pendverify.analytic import CartDoublePendulum, DoublePendulum
from pendverify.checks.catalogue import CHECK_NAMES, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.cli import main
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for

from ..conftest import SEED, default_params, system_for


class CoriolisSignFlip(DoublePendulum):
    def seed_coriolis_matrix(self, q, v):
        C = super().seed_coriolis_matrix(q, v)
        C[1, 0] = -C[1, 0]  # β sin θ2 θ̇1 → −β sin θ2 θ̇1
        return C


class BetaOff(DoublePendulum):
    @property
    def beta(self):
        return super().beta * (1 + 1e-6)


class FrictionMissing(DoublePendulum):
    def seed_coriolis_matrix(self, q, v):
        return super().seed_coriolis_matrix(q, v) - self.damping_matrix()


class WrongCosineInH(DoublePendulum):
    def gravity(self, q):
        p = self.params
        H = super().gravity(q)
        H[1] = p.m2 * p.g * p.r2 * math.cos(q[1])  # cos θ2 instead of cos(θ1 + θ2)
        return H


class CartCoriolisSignFlip(CartDoublePendulum):
    def coriolis_matrix(self, y, yd):
        C = super().coriolis_matrix(y, yd)
        C[0, 2] = -C[0, 2]
        return C


class CartFrictionMissing(CartDoublePendulum):
    def f(self, y, yd, u, w):
        return super().f(y, yd, u, w) + self.damping_matrix() @ yd


class CartWrongCosineInM(CartDoublePendulum):
    def mass_matrix(self, y):
        M = super().mass_matrix(y)
        p = self.params
        M[1, 2] = M[2, 1] = p.l1 * p.l2 * p.m2 * math.cos(y[1] + y[2])  # cos(θ1 + θ2)
        return M


class CartDetTermMissing(CartDoublePendulum):
    def det_mass_matrix(self, y):
        p = self.params
        missing = p.l1**2 * p.l2**2 * p.m2 * p.m1 * p.m2 * math.sin(y[1]) ** 2
        return super().det_mass_matrix(y) - missing  # drop the m1·m2·sin²θ1 term


class DetTermMissing(DoublePendulum):
    def det_mass_matrix(self, q):
        return super().det_mass_matrix(q) + self.delta**2  # αδ − β²cos²θ2: the −δ² dropped


class KineticEnergyTypo(CartDoublePendulum):
    """The public bug class: θ̇1² where θ̇2² belongs, seen only through the energy."""

    def kinetic_energy(self, y, yd):
        wrong = yd.copy()
        wrong[2] = yd[1]
        return super().kinetic_energy(y, wrong)


PLANTED = [
    (CoriolisSignFlip, "coriolis"),
    (CoriolisSignFlip, "rnea"),
    (CoriolisSignFlip, "aba"),
    (BetaOff, "crba"),
    (FrictionMissing, "aba"),
    (WrongCosineInH, "gravity"),
    (DetTermMissing, "det"),
    (CartCoriolisSignFlip, "coriolis"),
    (CartCoriolisSignFlip, "skew"),
    (CartFrictionMissing, "aba"),
    (CartWrongCosineInM, "crba"),
    (CartDetTermMissing, "det"),
    (KineticEnergyTypo, "energy"),
]


def _results(cls):
    params = default_params(cls.name)
    model = cls(params)
    return {
        r.name: r
        for r in run_checks(cls.__name__, model, system_for(params), sample_states(model, 60, SEED), SEED)
    }


@pytest.mark.parametrize(("cls", "check"), PLANTED, ids=[f"{c.__name__}-{k}" for c, k in PLANTED])
def test_planted_error_is_reported_by_its_check(cls, check):
    result = _results(cls)[check]
    assert not result.passed, f"{cls.__name__}: check {check} did not fail ({result.error:.3g})"
    assert result.error > result.tolerance


def test_beta_off_by_one_ppm_fails_by_a_wide_margin():
    """1e-6 relative is far above the eps-level tolerance: a loose 1e-6 would have missed it."""
    result = _results(BetaOff)["crba"]
    assert result.error > 1e3 * result.tolerance


@pytest.mark.parametrize("name", ["double_pendulum", "cart_double_pendulum"])
def test_every_check_can_fail(name):
    """Union over the planted models of this seed: every check name is seen failing."""
    failed = set()
    for cls, _ in PLANTED:
        if cls.name == name:
            failed |= {k for k, r in _results(cls).items() if not r.passed}
    if name == "double_pendulum":
        failed |= {"skew", "minverse", "energy", "damping"} & _failing_extra_dp()
    else:
        failed |= {"gravity", "minverse", "rnea", "damping"} & _failing_extra_cart()
    assert failed == set(CHECK_NAMES), f"never seen failing: {set(CHECK_NAMES) - failed}"


def _damped_urdf_results(model, text: str) -> dict:
    params = model.params
    system = PinocchioSystem.from_urdf(params.model, text, params.g)
    return {r.name: r for r in run_checks("damped", model, system, sample_states(model, 20, SEED), SEED)}


def _failing_extra_dp():
    class NotChristoffel(DoublePendulum):
        # same C·q̇, but not Ṁ − 2C skew: move β sin θ2 θ̇2·θ̇1 between columns
        def seed_coriolis_matrix(self, q, v):
            b, s = self.beta, math.sin(q[1])
            return np.array(
                [[-b * s * v[1] * 2 + self.params.b1, -b * s * v[0]], [b * s * v[0], self.params.b2]]
            )

    class InverseTypo(DoublePendulum):
        def inverse_mass_matrix(self, q):
            Minv = super().inverse_mass_matrix(q)
            Minv[0, 1] *= -1
            return Minv

    class PotentialTypo(DoublePendulum):
        def potential_energy(self, q):
            return super().potential_energy(q) + self.params.g * self.params.m2 * self.params.r2 * math.sin(
                q[1]
            )

    failed = set()
    for cls in (NotChristoffel, InverseTypo, PotentialTypo):
        failed |= {k for k, r in _results(cls).items() if not r.passed}
    # a URDF whose joint damping is b1·10 while the hand model keeps the set's b1
    params = default_params("double_pendulum")
    text = urdf_for(params.replace(b1=10 * params.b1))
    failed |= {k for k, r in _damped_urdf_results(DoublePendulum(params), text).items() if not r.passed}
    return failed


def _failing_extra_cart():
    class GravitySign(CartDoublePendulum):
        def gravity(self, y):
            return -super().gravity(y)

    class InverseTypo(CartDoublePendulum):
        def inverse_mass_matrix(self, y):
            Minv = super().inverse_mass_matrix(y)
            Minv[2, 2] *= 1 + 1e-9
            return Minv

    failed = set()
    for cls in (GravitySign, InverseTypo):
        failed |= {k for k, r in _results(cls).items() if not r.passed}
    # joint dampers on the relative joint: Tᵀ·diag(b)·T couples θ1 and θ2, the seed's D does not
    params = default_params("cart_double_pendulum")
    text = urdf_for(params).replace(
        '<joint name="pole2" type="revolute">',
        '<joint name="pole2" type="revolute">\n    <dynamics damping="0.02"/>',
    )
    failed |= {k for k, r in _damped_urdf_results(CartDoublePendulum(params), text).items() if not r.passed}
    return failed


def test_the_untouched_models_pass(model_name):
    cls = DoublePendulum if model_name == "double_pendulum" else CartDoublePendulum
    assert all(r.passed for r in _results(cls).values())


# --- a URDF that disagrees with its parameter set -----------------------------------------
def _urdf_and_params(tmp_path, model, urdf_params):
    from pendverify.robot.writer import urdf_for

    urdf = tmp_path / "robot.urdf"
    urdf.write_text(urdf_for(urdf_params))
    params = tmp_path / "params.toml"
    params.write_text(default_params(model).to_toml())
    return str(urdf), str(params)


@pytest.mark.parametrize(
    ("model", "change", "named"),
    [
        ("double_pendulum", {"I1": 0.0208 * 1.01}, "I1"),
        ("double_pendulum", {"r2": 0.22 + 0.01}, "r2"),
        ("cart_double_pendulum", {"l2": 0.75 * 1.01}, None),
        ("cart_double_pendulum", {"m1": 0.5 * 1.01}, None),
    ],
)
def test_urdf_disagreeing_with_params_fails(tmp_path, capsys, model, change, named):
    urdf_params = default_params(model).replace(**change)
    urdf, params = _urdf_and_params(tmp_path, model, urdf_params)
    status = main(["check", "--urdf", urdf, "--params", params, "--samples", "30"])
    out = capsys.readouterr().out
    assert status == 1
    assert "FAIL" in out and "crba" in out
    if named:
        assert f"the URDF gives {named} = " in out


def test_urdf_agreeing_with_params_passes(tmp_path, capsys, model_name):
    urdf, params = _urdf_and_params(tmp_path, model_name, default_params(model_name))
    assert main(["check", "--urdf", urdf, "--params", params, "--samples", "30"]) == 0
    assert "all checks pass" in capsys.readouterr().out
