"""The battery's simulations on the fast path: energies on all steps at once, the engine recorded,
recheck reproducing it, and planted errors in the closed form still caught by an invariant."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS, DoublePendulum
from pendverify.certify.battery import BatteryRun, BatterySettings, run_battery
from pendverify.certify.certificate import build_certificate, certificate_text, digest_of
from pendverify.certify.issue import recheck
from pendverify.certify.model_source import ModelSource
from pendverify.certify.simulations import ABA, COMPILED, CROSS_CHECK_STATES, invariant_items
from pendverify.checks.evidence import item_record
from pendverify.numerics.energies import GeneratedEnergies
from pendverify.robot.writer import urdf_for
from pendverify.simulation import compiled_scene, invariants
from pendverify.simulation.scene import load_scene

from ..checks.test_planted_errors import CoriolisSignFlip, WrongCosineInH
from ..conftest import default_params

REPO = Path(__file__).resolve().parents[2]
ENERGY_RTOL = 1e-12  # the same closed forms, read by SymPy and summed in another order


@pytest.mark.parametrize("name", ["damped_double_pendulum", "cart_rods_falling", "furuta_arm_turning"])
def test_generated_energies_are_the_closed_forms(name):
    run = compiled_scene.simulate_compiled(load_scene(REPO / "scenes" / f"{name}.toml"))
    xs = run.result.steps_x
    fast = GeneratedEnergies.of(run.dynamics, run.system)
    slow = invariants.TrajectoryEnergies(run.dynamics)
    assert isinstance(fast, GeneratedEnergies)
    n = run.dynamics.nv
    Q, V = xs[:, :n], xs[:, n : 2 * n]
    scale = invariants.energy_scale(slow, xs)
    for what in ("energy", "kinetic"):
        error = np.max(np.abs(getattr(fast, what)(Q, V) - getattr(slow, what)(Q, V)))
        assert error <= ENERGY_RTOL * scale, (what, error, scale)
    momentum = np.abs(fast.momentum(Q, V) - slow.momentum(Q, V))
    assert np.all(momentum <= ENERGY_RTOL * (1 + np.abs(slow.momentum(Q, V)))), momentum.max()
    bound_fast = invariants.adaptive_bound(fast, xs, run.scene.integrator, scale)
    bound_slow = invariants.adaptive_bound(slow, xs, run.scene.integrator, scale)
    assert np.allclose(bound_fast, bound_slow, rtol=1e-6, atol=0.0)  # ∇E by differences: ≈ 1e-9


# --- the battery's invariant items ------------------------------------------------------------
class GravityNotGradient(DoublePendulum):
    """H₂ with cos θ2 for cos(θ1 + θ2): no longer ∂V/∂θ2 (``WrongCosineInH`` through ``self.math``,
    which SymPy reads; the planted-errors module's uses ``math.cos``, which only ABA can run)."""

    def gravity(self, q):
        p = self.params
        H = super().gravity(q)
        return np.array([H[0], p.m2 * p.g * p.r2 * self.math.cos(q[1])])


SETTINGS = BatterySettings(samples=20, sim_duration=1.0)
EFFECTS = ("gravity", "damping", "actuation", "disturbance")


def _items(model_cls, params, engines=None):
    return {i.name: i for i in invariant_items(model_cls, params, urdf_for(params), SETTINGS, engines)}


@pytest.mark.parametrize("name", ["double_pendulum", "cart_double_pendulum"])
def test_every_battery_scene_runs_on_the_fast_path_and_records_it(name):
    params = default_params(name)
    items = _items(MODELS[name], params)
    assert {i.extras["engine"] for i in items.values()} == {COMPILED}, items
    assert all(i.passed for i in items.values()), [(i.name, i.error, i.tolerance) for i in items.values()]
    cross = items["invariant:gravity:engines"]
    assert cross.samples == CROSS_CHECK_STATES and "ABA on the URDF" in cross.detail
    assert all(i.kind == "invariant" and item_record(i)["engine"] == COMPILED for i in items.values())
    old = _items(MODELS[name], params, dict.fromkeys(EFFECTS, ABA))
    assert {i.extras["engine"] for i in old.values()} == {ABA} and "invariant:gravity:engines" not in old
    assert set(old) == set(items) - {"invariant:gravity:engines"}
    assert all(i.passed for i in old.values())


@pytest.mark.slow
@pytest.mark.parametrize(
    ("planted", "why"),
    [(CoriolisSignFlip, "C not Christoffel-consistent with M"), (GravityNotGradient, "H not ∇V")],
)
def test_a_planted_error_in_the_closed_form_fails_an_invariant_on_the_fast_path(planted, why):
    """The compiled run is the closed form's: it gains or loses energy.  ABA's run (and energy) are
    Pinocchio's, which conserve whatever the closed form says: there the same item passes."""
    params = default_params("double_pendulum")
    fast = _items(planted, params)
    assert fast["invariant:gravity:energy"].extras["engine"] == COMPILED
    assert not fast["invariant:gravity:energy"].passed, why
    assert not fast["invariant:gravity:engines"].passed, why  # the generated code is not the URDF's
    aba = _items(planted, params, dict.fromkeys(EFFECTS, ABA))
    assert aba["invariant:gravity:energy"].passed, "ABA never saw the closed form"


def test_a_certificate_without_engines_is_rechecked_on_aba(tmp_path):
    """An invariant item that records no engine ran on ABA: recheck runs it there, as it ran."""
    cls, params = MODELS["double_pendulum"], default_params("double_pendulum")
    urdf = urdf_for(params)
    battery = run_battery(cls, params, urdf, SETTINGS, dict.fromkeys(EFFECTS, ABA))
    cert = build_certificate("before", ModelSource("double_pendulum"), params, urdf, SETTINGS, battery)
    for item in cert["checks"]:
        item.pop("engine", None)
    cert["digest"]["value"] = digest_of(cert)
    path = tmp_path / "before.cert.json"
    path.write_text(certificate_text(cert))
    result = recheck(str(path))
    assert result.passed, result.differences
    assert {i.extras["engine"] for i in result.items if i.kind == "invariant"} == {ABA}
    # an item recording the compiled engine runs there: its figures are not ABA's
    last = cert["checks"][-1]
    assert last["name"] == "invariant:actuation:work–energy"
    last["engine"] = COMPILED
    cert["digest"]["value"] = digest_of(cert)
    path.write_text(certificate_text(cert))
    again = recheck(str(path))
    assert next(i for i in again.items if i.name == last["name"]).extras["engine"] == COMPILED
    assert again.differences and all(d.startswith(last["name"]) for d in again.differences), again.differences


def test_a_model_sympy_cannot_read_runs_on_aba_and_says_so():
    """``math.cos`` is not readable by SymPy: no generated code, so each scene falls back to ABA."""
    items = _items(WrongCosineInH, default_params("double_pendulum"))
    assert {i.extras["engine"] for i in items.values()} == {ABA} and "invariant:gravity:engines" not in items
    assert all("Pinocchio's ABA" in i.detail for i in items.values())


def test_an_unknown_engine_is_refused_by_the_schema(tmp_path):
    from pendverify.certify.schema import check_schema
    from pendverify.errors import CertificateError

    cls, params = MODELS["double_pendulum"], default_params("double_pendulum")
    battery = BatteryRun(invariant_items(cls, params, urdf_for(params), SETTINGS), notes=[])
    cert = build_certificate("x", ModelSource("double_pendulum"), params, urdf_for(params), SETTINGS, battery)
    check_schema(cert, "x.cert.json")
    cert["checks"][0]["engine"] = "euler"
    expected = r"checks\[0\]\.engine' = 'euler': expected one of compiled, aba"
    with pytest.raises(CertificateError, match=expected):
        check_schema(cert, "x.cert.json")
