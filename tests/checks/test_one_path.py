"""One evaluation path: a state's figures do not depend on the batch it is judged in.

Every check runs over a batch of states (``pendverify.checks.batch.CheckBatch``); one state
is the batch of one.  For the two reference systems and two plug-in models, the battery's
states (2000 random ones and the special ones) are judged as one batch, then 7 of them in
another order, then each alone: every state's relative error, relative tolerance and
absolute error agree to a few ulps (``ULPS``: the generated NumPy code and Pinocchio's loops
do the same operations on each state whatever the batch; the few ulps leave room for a
vector math library whose last bit depends on a value's position in a SIMD register), and
so do the verdicts.  A closed form SymPy cannot read runs in the model's own Python, the
report names it, and a planted error in it is still caught.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS
from pendverify.certify.battery import BatterySettings
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import CHECKS, applicable_checks, run_checks
from pendverify.checks.judge import collect
from pendverify.checks.report import Report
from pendverify.checks.sampling import sample_states
from pendverify.checks.verification import verify_target
from pendverify.stress.cases import reduced_angles, shifted_states
from pendverify.targets import Target, default_target, plugin_target

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
EPS = float(np.finfo(float).eps)
ULPS = 8  # |a − b| ≤ ULPS·ε·max(|a|, |b|) for figures of the same state in two batches


def _target(name: str):
    if name in MODELS:
        return default_target(name)
    return plugin_target(*(str(EXAMPLES / f"{name}.{ext}") for ext in ("py", "urdf", "toml")))


def figures(batch: CheckBatch) -> dict:
    """{(check, state label): (relative error, relative tolerance, absolute error)} of every judged state."""
    out = {}
    for check in CHECKS:
        if check.name not in applicable_checks(batch.model, batch.system):
            continue
        ev = collect(check, batch)
        for k, i in enumerate(ev.judged):
            out[(check.name, batch.states[i].label)] = (ev.rel_err[k], ev.rel_tol[k], ev.abs_err[k])
        for i, rounding in ev.refused:
            out[(check.name, batch.states[i].label)] = ("refused", rounding, None)
    return out


def assert_same_figures(small: dict, large: dict, what: str) -> None:
    for key, values in small.items():
        for a, b in zip(values, large[key], strict=True):
            if isinstance(a, str) or a is None:
                assert a == b, (what, key)
                continue
            assert abs(a - b) <= ULPS * EPS * max(abs(a), abs(b)) or a == b, (what, key, a, b)


@pytest.mark.parametrize("name", ["double_pendulum", "cart_double_pendulum", "cart_pole", "triple_pendulum"])
def test_a_state_has_the_same_figures_in_a_batch_of_1_7_and_2000_in_any_order(name):
    target = _target(name)
    settings = BatterySettings()
    states = sample_states(target.model, settings.samples, settings.seed)
    assert len(states) > 2000
    large = figures(CheckBatch(target.model, target.system, states))
    rng = np.random.default_rng(23)  # seed recorded here: which 7 states, and their order
    seven = [states[i] for i in rng.choice(len(states), 7, replace=False)]
    assert_same_figures(figures(CheckBatch(target.model, target.system, seven)), large, "7 states")
    for state in seven:
        assert_same_figures(figures(CheckBatch(target.model, target.system, [state])), large, state.label)
    # the verdicts and the worst errors of the whole battery in reverse order (the worst state is
    # the first of equals, so states that tie, as at rest and moving for crba, may swap)
    forward = run_checks(name, target.model, target.system, states, settings.seed)
    backward = run_checks(name, target.model, target.system, states[::-1], settings.seed)
    for f, b in zip(forward, backward, strict=True):
        assert (f.name, f.passed, f.status) == (b.name, b.passed, b.status)
        pairs = [(f.error, b.error), (f.extras["max_abs_error"], b.extras["max_abs_error"])]
        if f.label == b.label:  # the tolerance is the worst state's
            pairs.append((f.tolerance, b.tolerance))
        for x, y in pairs:
            assert abs(x - y) <= ULPS * EPS * max(x, y), (f.name, x, y)


def test_large_angles_refused_and_reduced_alike_in_any_batch():
    """|θ| ≈ 1e9 rad passes the trust limit on its own; Pinocchio at θ mod 2π (the stress invariance)."""
    target = default_target("cart_double_pendulum")
    states = sample_states(target.model, 200, 7)
    mixed = states[:100] + shifted_states(target.model, states[100:], 1e9)
    reduce = reduced_angles(target.model.angular)
    large = figures(CheckBatch(target.model, target.system, mixed, reduce))
    refused = [k for k, v in large.items() if v[0] == "refused"]
    assert 0 < len(refused) < len(large)
    few = mixed[95:105][::-1]
    assert_same_figures(figures(CheckBatch(target.model, target.system, few, reduce)), large, "10 states")


class Branching(MODELS["double_pendulum"]):
    """The seed whose V branches on the state: SymPy cannot read it, so it runs in Python."""

    def potential_energy(self, q):
        value = super().potential_energy(q)
        return value if q[0] < 1e9 else -value


class BranchingTypo(Branching):
    """The same with a typo in the branch taken: V's second term doubled."""

    def potential_energy(self, q):
        p = self.params
        value = super().potential_energy(q) + p.g * p.m2 * p.r2 * self.math.sin(q[0] + q[1])
        return value if q[0] < 1e9 else -value


def _report(cls) -> Report:
    base = default_target("double_pendulum")
    target = Target(cls.name, cls(base.model.params), base.system, base.source)
    report = Report(seed=5, states={}, results=[], strict=False)
    verify_target(report, target, 60, 5)
    return report


def test_a_closed_form_sympy_cannot_read_runs_in_python_and_the_report_says_so():
    report = _report(Branching)
    assert report.passed
    (note,) = [n for n in report.notes[Branching.name] if "own Python" in n]
    assert "potential_energy" in note and "cannot be read by SymPy" in note


def test_a_planted_error_in_a_closed_form_run_in_python_is_caught():
    report = _report(BranchingTypo)
    energy = next(r for r in report.results if r.name == "energy")
    assert not energy.passed and energy.error > 1e-3
