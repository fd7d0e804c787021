"""The checks over all states at once give the per-state path's numbers, state by state, bit for bit.

``run_check`` evaluates a check over the whole batch (``pendverify.checks.batch``);
``run_check_per_state`` is the reference.  For both seeds on the battery's own states,
for two plug-in models, at large angles through the stress catalogue's reduced-angle
system, and through the precision re-judgement, every judged state's rounding tolerance,
relative error, relative tolerance and absolute error, the refused states and the notes
must be equal (``==`` on the bits), and so the verdicts, worst and largest states.  The
trust rule's verdict at each state (``trust_batch.assess_batch``) must be ``assess``'s.
"""

from __future__ import annotations

import math
import operator
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS
from pendverify.certify.battery import BatterySettings
from pendverify.checks import batch as batch_module
from pendverify.checks.batch import BatchContext, collect_batch
from pendverify.checks.catalogue import CHECKS, applicable_checks, run_check, run_check_per_state
from pendverify.checks.elementwise import elementwise
from pendverify.checks.judge import collect_per_state
from pendverify.checks.lanes import Lanes
from pendverify.checks.sampling import sample_states
from pendverify.checks.targets import default_target, erd_targets, plugin_target
from pendverify.checks.trust import assess
from pendverify.checks.trust_batch import assess_batch
from pendverify.stress.cases import ReducedAngleSystem, shifted_states
from pendverify.stress.framework import QUICK
from pendverify.stress.generic import run_generic

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SEEDS = ("double_pendulum", "cart_double_pendulum")
SAMPLER_SEEDS = (BatterySettings().seed, 7)


def same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def same(a, b) -> bool:
    """Equal, floats bit for bit (a NaN equals a NaN with the same bits)."""
    if isinstance(a, float) and isinstance(b, float):
        return same_bits(a, b)
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


def assert_both_paths_agree(label, model, system, states, seed=1):
    ctx = BatchContext.of(model, system, states)
    assert ctx is not None
    names = applicable_checks(model, system)
    assert names
    for check in CHECKS:
        if check.name not in names:
            continue
        batch, reference = collect_batch(check, ctx), collect_per_state(check, model, system, states)
        for field in ("judged", "rounding", "rel_err", "rel_tol", "abs_err"):
            assert same_bits(getattr(batch, field), getattr(reference, field)), (label, check.name, field)
        assert same(batch.refused, reference.refused), (label, check.name)
        assert batch.notes == reference.notes, (label, check.name)
        result, expected = (
            run(check, label, model, system, states, seed) for run in (run_check, run_check_per_state)
        )
        assert same(result.as_dict(), expected.as_dict()), (label, check.name)
    assert ctx.fallbacks == []
    verdicts = assess_batch(ctx)
    assert [verdicts[i] for i in range(len(states))] == [assess(model, s.q, system) for s in states], label
    return ctx


@pytest.mark.parametrize("name", SEEDS)
def test_the_batteries_checks_agree_state_by_state_on_both_seeds(name):
    """The battery's own states (``BatterySettings``): 2000 random ones and the special ones."""
    target = default_target(name)
    settings = BatterySettings()
    states = sample_states(target.model, settings.samples, settings.seed)
    ctx = assert_both_paths_agree(name, target.model, target.system, states, settings.seed)
    # the seeds' closed forms run on the whole batch, their q̈ (written with @ or np.linalg) too
    assert {ctx.forms.how[k] for k in ("mass_matrix", "inverse_mass_matrix", "acceleration")} == {"lanes"}


@pytest.mark.parametrize("name", SEEDS)
@pytest.mark.parametrize("seed", SAMPLER_SEEDS[1:])
def test_another_sampler_seed_and_large_angles_agree(name, seed):
    target = default_target(name)
    states = sample_states(target.model, 200, seed)
    assert_both_paths_agree(name, target.model, target.system, states, seed)
    # |θ| ≈ 1e6 rad, Pinocchio at θ mod 2π (the stress catalogue's invariance): some states refused
    shifted = shifted_states(target.model, states)
    reduced = ReducedAngleSystem(target.system, target.model.angular)
    assert_both_paths_agree(name, target.model, reduced, shifted, seed)
    assert_both_paths_agree(name, target.model, target.system, shifted, seed)
    # at |θ| ≈ 1e9 rad the rounding of the angles alone passes the trust limit
    mixed = states[:100] + shifted_states(target.model, states[100:], 1e9)
    check = next(c for c in CHECKS if c.name == "crba")
    refused = collect_batch(check, BatchContext.of(target.model, target.system, mixed)).refused
    assert 0 < len(refused) < len(mixed)
    assert_both_paths_agree(name, target.model, target.system, mixed, seed)


@pytest.mark.parametrize("stem", ("cart_pole", "triple_pendulum"))
@pytest.mark.parametrize("seed", SAMPLER_SEEDS)
def test_plug_in_models_agree(stem, seed):
    target = plugin_target(*(str(EXAMPLES / f"{stem}.{ext}") for ext in ("py", "urdf", "toml")))
    states = sample_states(target.model, 200, seed)
    assert_both_paths_agree(stem, target.model, target.system, states, seed)


def test_example_robot_datas_urdfs_agree_continuous_joints_included():
    """Their ``double_pendulum_continuous`` has continuous joints: Pinocchio takes (cos φ, sin φ)."""
    targets = erd_targets()
    assert any(2 in t.system.cmap.joint_nq for t in targets)
    for target in targets:
        states = sample_states(target.model, 100, 11)
        assert_both_paths_agree(target.label, target.model, target.system, states)


def test_a_warning_from_the_precise_rejudgement_is_the_same(monkeypatch):
    """The triple pendulum's M⁻¹ with m3 × 1e6 loses digits (a warning), and some states are refused."""
    args = [str(EXAMPLES / f"triple_pendulum.{ext}") for ext in ("py", "urdf", "toml")]
    batched = run_generic(*args, QUICK, names=("m3 ×1e6",)).results
    monkeypatch.setattr(batch_module.BatchContext, "of", classmethod(lambda cls, *a: None))
    reference = run_generic(*args, QUICK, names=("m3 ×1e6",)).results
    assert batched[0].verdict.startswith("pass (warn")
    for r in (*batched, *reference):
        r.seconds = 0.0
    assert [r.as_dict() for r in batched] == [r.as_dict() for r in reference]


# --- what the batch does when it cannot follow one state at a time --------------------------------
class Odd(MODELS["double_pendulum"]):
    """The seed with closed forms the batch must hand back to the per-state path."""

    def gravity(self, q):  # a square: C's pow on a number, a square on an array; they differ now and then
        p = self.params
        c1, c12 = self.math.cos(q[0]), self.math.cos(q[0] + q[1])
        bump = (c1 * 1e3) ** 2 * 0.0
        return np.array(
            [p.m1 * p.g * p.r1 * c1 + p.m2 * p.g * (p.l1 * c1 + p.r2 * c12) + bump, p.m2 * p.g * p.r2 * c12]
        )

    def mutated(self, q):  # a reduction: refused by the scan
        return np.sum(q)

    def potential_energy(self, q):  # a branch on the state
        value = super().potential_energy(q)
        return value if q[0] < 1e9 else -value

    def det_mass_matrix(self, q):  # @ of two arrays it builds itself: NumPy's object loop, refused
        return np.array([1.0, 0.0]) @ np.array([super().det_mass_matrix(q), 0.0])

    def inverse_mass_matrix(self, q):  # np.linalg on the batch's arrays: LAPACK once per state
        return np.linalg.solve(self.mass_matrix(q), np.eye(2))

    def kinetic_energy(self, q, v):  # @ with a transposed (Fortran-ordered) matrix: BLAS once per state
        return 0.5 * (v @ self.mass_matrix(q).T @ v)


def test_code_the_batch_cannot_run_as_written_is_evaluated_state_by_state():
    assert elementwise(Odd, "gravity") and not elementwise(Odd, "mutated")
    target = default_target("double_pendulum")
    model = Odd(target.model.params)
    states = sample_states(model, 60, 3)
    ctx = assert_both_paths_agree("odd", model, target.system, states)
    assert ctx.forms.how["potential_energy"] == ctx.forms.how["det_mass_matrix"] == "per state"
    assert {ctx.forms.how[k] for k in ("gravity", "inverse_mass_matrix", "kinetic_energy")} == {"lanes"}


def test_a_power_is_unsure_where_a_number_and_an_array_round_differently():
    x = np.random.default_rng(0).uniform(-10, 10, 20000)
    squared = Lanes(x) ** 2
    differ = np.array([math.pow(v, 2) != v * v for v in x.tolist()])
    assert differ.any()  # C's pow is not always the correctly rounded square
    assert np.array_equal(squared.unsure, differ)
    assert same_bits(squared.a, np.array([math.pow(v, 2) for v in x.tolist()]))
    with np.errstate(divide="ignore"):
        halves = Lanes(x) / Lanes(np.where(np.arange(x.size) % 7 == 0, 0.0, x))
    assert np.array_equal(halves.unsure, np.arange(x.size) % 7 == 0)  # a Python float raises there
    with pytest.raises(Exception, match="compares"):
        operator.lt(Lanes(x), 0.0)


def test_a_system_without_a_batch_takes_the_per_state_path():
    target = default_target("cart_double_pendulum")

    class Wrapped:  # a wrapper the batch knows nothing about
        def __init__(self, system):
            self._system = system

        def __getattr__(self, name):
            return getattr(self._system, name)

    states = sample_states(target.model, 20, 5)
    assert BatchContext.of(target.model, Wrapped(target.system), states) is None
    check = next(c for c in CHECKS if c.name == "aba")
    result = run_check(check, "w", target.model, Wrapped(target.system), states, 5)
    assert same(
        result.as_dict(), run_check_per_state(check, "w", target.model, target.system, states, 5).as_dict()
    )


def _one_draw_per_vector(model, n_random, seed):
    """The sampler as it was written before issue 15: one ``uniform`` call per vector."""
    from pendverify.checks import sampling as s

    rng = np.random.default_rng(seed)
    angular = np.array(model.angular)
    q_range = np.where(angular, s.ANGLE_RANGE, s.POSITION_RANGE)
    u_scale = s._force_scales(model, model.input_matrix())
    w_scale = s._force_scales(model, model.disturbance_matrix())
    out = []
    for name, q in model.special_states().items():
        q = np.asarray(q, dtype=float)
        out.append((f"{name} at rest", q, np.zeros(model.nv), np.zeros(u_scale.size), np.zeros(w_scale.size)))
        v = rng.uniform(-s.RATE_RANGE, s.RATE_RANGE, model.nv)
        u, w = rng.uniform(-1, 1, u_scale.size) * u_scale, rng.uniform(-1, 1, w_scale.size) * w_scale
        out.append((f"{name} moving", q, v, u, w))
    for i in range(n_random):
        q = rng.uniform(-1, 1, model.nv) * q_range
        v = rng.uniform(-s.RATE_RANGE, s.RATE_RANGE, model.nv)
        u, w = rng.uniform(-1, 1, u_scale.size) * u_scale, rng.uniform(-1, 1, w_scale.size) * w_scale
        out.append((f"random #{i}", q, v, u, w))
    return out


@pytest.mark.parametrize("stem", ("cart_pole", "furuta_pendulum", *SEEDS))
def test_the_sampler_draws_the_states_one_draw_per_vector_would(stem):
    if stem in SEEDS:
        model = default_target(stem).model
    else:
        model = plugin_target(*(str(EXAMPLES / f"{stem}.{ext}") for ext in ("py", "urdf", "toml"))).model
    for seed in (0, 20260301):
        drawn = sample_states(model, 50, seed)
        expected = _one_draw_per_vector(model, 50, seed)
        assert [s.label for s in drawn] == [e[0] for e in expected]
        for s, (_, *arrays) in zip(drawn, expected, strict=True):
            assert all(same_bits(a, b) for a, b in zip((s.q, s.v, s.u, s.w), arrays, strict=True)), s.label


@pytest.mark.parametrize("name", SEEDS)
def test_the_seeds_written_in_latex_agree(name):
    """A text model's methods (``sympy.lambdify`` onto ``self.math``) run on the batch as well."""
    root = EXAMPLES.parent
    target = plugin_target(
        str(EXAMPLES / f"{name}_latex.toml"),
        str(root / "urdf" / f"{name}.urdf"),
        str(root / "analytic" / "params" / f"{name}.toml"),
    )
    states = sample_states(target.model, 200, SAMPLER_SEEDS[1])
    assert_both_paths_agree(name, target.model, target.system, states, SAMPLER_SEEDS[1])
