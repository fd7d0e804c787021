"""Mutation sensitivity: how many single-term mutants of a model do the checks catch?

Each mutant (``pendverify.symbolic.mutants``) becomes a numeric model: a subclass of the
model's class whose one mutated method calls the original and overwrites the
mutated entry with the lambdified mutant expression (the other entries keep
their original rounding; methods that call the mutated one see the mutant, as
they would in source code).  The nine checks run on it, and it is classified:

detected
    some check fails.  The check aimed at the mutated method runs first (M →
    crba, C → coriolis, C·q̇ → rnea, H → gravity, V → energy, det → det,
    M⁻¹ → minverse, D, B, W, f → aba), then the others, first on the special states and a few
    random ones, then on all the sampled states; the run stops at the first
    failure and reports that check (``all_checks`` runs every check on every
    mutant, for the full profile of which checks see what).
equivalent
    the mutant does not change the dynamics, proved symbolically
    (``pendverify.symbolic.equivalence``): the expression is identical, or
    simplifies to the original, or V changes by a constant, or — for a
    Coriolis-type form — C·q̇ is unchanged (a different factorisation of C; the
    report says whether Ṁ − 2C stays skew, i.e. whether the factorisation is
    Christoffel-consistent, and which checks flag it: a warning, not a failure).
    A mutant that is zero only for this parameter set is reported as equivalent
    *for these parameters*, naming that.
survived
    no check fails and no equivalence is proved: a gap in the verification.

Detection rate = detected / (all − equivalent) over the mutants run; the target is 100 %.

The work is bounded before it starts and while it runs.  The number of mutants grows with the
size of the closed forms (a 5-link chain's M has 2 871, its C 8 339; the reference systems'
largest form, the cart's M⁻¹, 460), and each costs a lambdification and a run of the checks
(0.05–0.3 s on a 2-core machine, growing with the degrees of freedom).  So at most
``PENDVERIFY_MAX_MUTANTS`` (default ``DEFAULT_MAX_MUTANTS``) mutants of each closed form run: a
larger set is sampled with the seed, evenly over its entries and operators (every reference
system's forms are below the bound, so they run whole); and the run stops at its wall-clock
bound ``PENDVERIFY_MUTATE_SECONDS`` (default ``DEFAULT_MUTATE_SECONDS``), a backstop against a
machine slower than measured.  The report says what was not run in either case.  Before
any mutant runs, the untouched model and one *control* per method (every
entry replaced by its own lambdified expression) must pass every check, so that
a detection is never caused by the lambdified rounding itself.  The verdicts and the
printed report are in ``pendverify.symbolic.mutation_report``.
"""

from __future__ import annotations

import itertools
import random
import time

import numpy as np

from pendverify.analytic.symbolic_reading import SymbolicModel, entries
from pendverify.checks.catalogue import CHECKS, applicable_checks, run_check
from pendverify.checks.sampling import sample_states
from pendverify.errors import PendverifyError, UnknownNameError
from pendverify.progress import bar
from pendverify.simulation.limits import environment_limit
from pendverify.symbolic.edited import edited_model
from pendverify.symbolic.equivalence import coriolis_equivalence, differences, equivalence
from pendverify.symbolic.mutants import Mutant, generate, is_coriolis_form
from pendverify.symbolic.mutation_report import (
    DETECTED,
    EQUIVALENT,
    SURVIVED,
    Bounds,
    MutationReport,
    Outcome,
)
from pendverify.symbolic.zero_test import show

FIRST_RANDOM = 4  # random states in the first round, after the special ones
#: |mutant − original| / (|original| + 1) above this at a sampled state cannot be rounding
DIFFERENT_RTOL = 1e-9
AIMED_AT = {
    "mass_matrix": "crba",
    "coriolis_matrix": "coriolis",
    "gravity": "gravity",
    "potential_energy": "energy",
    "det_mass_matrix": "det",
    "inverse_mass_matrix": "minverse",
    "coriolis_force": "rnea",
}
DEFAULT_MUTATION_STATES = 40
MAX_MUTANTS_VARIABLE = "PENDVERIFY_MAX_MUTANTS"
#: above the reference systems' largest form (460 mutants) so that they run whole
DEFAULT_MAX_MUTANTS = 500
MUTATE_SECONDS_VARIABLE = "PENDVERIFY_MUTATE_SECONDS"
#: the backstop: the conformance matrix gives a command 300 s, and a mutant takes well under a second
DEFAULT_MUTATE_SECONDS = 240


# --- numeric mutants ------------------------------------------------------------------------
def numeric_model(model, sm: SymbolicModel, method: str, changes):
    """A model whose ``method`` returns the original value with ``changes`` written in."""
    return edited_model(model, sm, {method: changes}, "Mutant", readable=False)


def _failing(model, system, states, seed, order=None, stop: bool = False) -> list[str]:
    """The checks that fail (in ``order``; the first only, with ``stop``).

    A check whose evaluation raises (a mutant with a singular M, or whose NaN the
    Pinocchio side refuses) fails too.
    """
    failing = []
    names = applicable_checks(model, system)
    for check in order or CHECKS:
        if check.name not in names:
            continue
        try:
            if not run_check(check, "mutant", model, system, states, seed).passed:
                failing.append(check.name)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError, PendverifyError) as exc:
            # the unmutated model and the controls passed: the mutant caused this
            failing.append(f"{check.name} (raises {type(exc).__name__})")
        if stop and failing:
            break
    return failing


def _order(method: str, form) -> tuple:
    """The check aimed at ``method`` first, then the others."""
    aimed = AIMED_AT.get(method, "coriolis" if form.args == "qv" else "aba")
    return tuple(sorted(CHECKS, key=lambda c: c.name != aimed))


def _numerically_different(model, mutated, method, args, states) -> bool:
    """True if the mutant's value differs from the original beyond any rounding at a sampled state."""
    for s in states:
        a = [{"q": s.q, "v": s.v, "u": s.u, "w": s.w}[k] for k in args]
        with np.errstate(all="ignore"):
            new = np.asarray(getattr(mutated, method)(*a), dtype=float)
            old = np.asarray(getattr(model, method)(*a), dtype=float)
            if np.any(np.abs(new - old) > DIFFERENT_RTOL * (np.abs(old) + 1.0)):
                return True
    return False


def classify(model, system, sm, mutant: Mutant, rounds, seed, all_checks: bool = False) -> Outcome:
    out = Outcome(mutant.method, mutant.operator, mutant.description, SURVIVED)
    if mutant.identical:
        out.verdict, out.reason = EQUIVALENT, "identical expression after SymPy's canonical ordering"
        return out
    value = sm.closed_forms[mutant.method]
    coriolis = is_coriolis_form(sm, mutant.method, value) and coriolis_equivalence(sm, mutant)
    form = sm.cls.closed_forms[mutant.method]
    mutated = numeric_model(model, sm, mutant.method, mutant.changes)
    order = _order(mutant.method, form)
    with np.errstate(all="ignore"):  # a mutant may well divide by zero: that is a detection
        for states in rounds:
            out.checks = _failing(mutated, system, states, seed, order, stop=not (all_checks or coriolis))
            if out.checks:
                break
    if coriolis:
        flagged = f"; flagged by {', '.join(out.checks)} (warning)" if out.checks else ""
        out.verdict, out.reason = EQUIVALENT, coriolis + flagged
    elif out.checks and _numerically_different(model, mutated, mutant.method, form.args, rounds[-1]):
        out.verdict = DETECTED
    else:
        # not detected, or detected although no difference shows at 50 digits: prove or report
        reason = equivalence(sm, mutant, model.params)
        if reason and out.checks:
            reason += (
                f"; yet {', '.join(out.checks)} failed: rounding of the lambdified form exceeds a tolerance"
            )
        if reason:
            out.verdict, out.reason = EQUIVALENT, reason
        elif out.checks:
            out.verdict = DETECTED
        else:
            diff = show(differences(sm, mutant)[0], sm.angles, 100)
            out.reason = f"no check fails, and the change {diff} is not zero: a gap in the checks"
    return out


# --- the run --------------------------------------------------------------------------------
def _controls(model, system, sm, states, seed) -> list[str]:
    done = []
    failing = _failing(model, system, states, seed)
    if failing:
        raise PendverifyError(
            f"{sm.cls.__name__}: the unmutated model fails {', '.join(failing)}; "
            "mutation sensitivity needs a model that passes every check (run pendverify check)"
        )
    for method, value in sm.closed_forms.items():
        changes = [(i, e, e) for i, e in enumerate(entries(value))]
        if not changes:
            continue
        failing = _failing(numeric_model(model, sm, method, changes), system, states, seed)
        if failing:
            raise PendverifyError(
                f"{sm.cls.__name__}.{method}: its own lambdified expressions fail {', '.join(failing)}; "
                "the mutants' rounding would not be comparable"
            )
        done.append(method)
    return done


def sampled(mutants: list[Mutant], limit: int, seed: int) -> tuple[list[Mutant], dict[str, int]]:
    """At most ``limit`` mutants per method, drawn with ``seed`` in their generated order (so spread
    over the entries and operators), and how many each method had.  The methods take turns, so
    that a run stopped at its wall-clock bound has run some mutants of each."""
    generated: dict[str, list[Mutant]] = {}
    for m in mutants:
        generated.setdefault(m.method, []).append(m)
    kept = []
    for method, ms in generated.items():
        if len(ms) > limit:
            ms = [ms[i] for i in sorted(random.Random(f"{seed}:{method}").sample(range(len(ms)), limit))]
        kept.append(ms)
    turns = [m for group in itertools.zip_longest(*kept) for m in group if m is not None]
    return turns, {method: len(ms) for method, ms in generated.items()}


def run_mutation(
    target,
    samples: int = DEFAULT_MUTATION_STATES,
    seed: int = 20260301,
    all_checks: bool = False,
    methods: tuple[str, ...] | None = None,
) -> MutationReport:
    """Generate, run and classify the mutants of ``target.model`` (of ``methods`` only, if given),
    within the bounds of the module docstring."""
    started = time.perf_counter()
    bounds = Bounds(
        environment_limit(MAX_MUTANTS_VARIABLE, DEFAULT_MAX_MUTANTS),
        environment_limit(MUTATE_SECONDS_VARIABLE, DEFAULT_MUTATE_SECONDS),
    )
    model, system = target.model, target.system
    sm = SymbolicModel.of(type(model))
    written = sm.cls.written_closed_forms()
    unknown = sorted(set(methods or ()) - set(written))
    if unknown:
        raise UnknownNameError("closed form", ", ".join(unknown), tuple(written))
    states = sample_states(model, samples, seed)
    first = len(states) - samples + min(FIRST_RANDOM, samples)
    rounds = [r for r in (states[:first], states[first:]) if r]
    controls = _controls(model, system, sm, states, seed)
    unseen = unseen_methods(sm.cls)
    wanted = [m for m in (methods or sm.closed_forms) if m not in unseen]
    mutants, bounds.generated = sampled(generate(sm, wanted), bounds.max_mutants, seed)
    outcomes = []
    with bar(len(mutants), "mutate", "mutant") as progress:
        for m in mutants:
            if time.perf_counter() - started > bounds.seconds:
                for m in mutants[len(outcomes) :]:
                    bounds.not_run[m.method] = bounds.not_run.get(m.method, 0) + 1
                break
            outcomes.append(classify(model, system, sm, m, rounds, seed, all_checks))
            progress.update(1)
    return MutationReport(
        target.label,
        target.source,
        seed,
        len(states),
        outcomes,
        controls,
        time.perf_counter() - started,
        all_checks,
        derived_methods(sm.cls),
        unseen,
        bounds,
    )


def derived_methods(cls) -> list[str]:
    """The interface's closed forms the model leaves to their derived defaults: nothing to mutate."""
    written = cls.written_closed_forms()
    return [
        m
        for m in cls.closed_forms
        if m not in written and not (m == "disturbance_matrix" and not cls.disturbances)
    ] + ([] if "acceleration" in cls.hand_written() else ["acceleration"])


def unseen_methods(cls) -> list[str]:
    """Hand-written closed forms no Pinocchio check can see: B and W when q̈ is derived.

    The URDF defines no input map, so B and W reach a check only through a
    hand-written q̈ (the reference systems' f + g·u); a derived q̈ applies the model's own B
    and W on both sides of ``aba``.  They are compared by ``pendverify sympy``
    (the input power) instead, and not mutated here.
    """
    if "acceleration" in cls.hand_written():
        return []
    return [m for m in ("input_matrix", "disturbance_matrix") if m in cls.written_closed_forms()]
