"""Verify targets: guard the states, run the checks, judge, diagnose — one ``Report``.

For each target (a closed-form model and a URDF in Pinocchio):

0. the ``units`` check reads the model alone (``pendverify.checks.units``): one dimension per
   entry, its place's; it needs no robot file, and ``model_report`` runs it alone for a model
   given without one;
1. the sampled states are guarded by the trust rule of ``pendverify.checks.trust``
   (the one ``pendverify stress`` uses); a state beyond it is not compared, and
   every check that could have been judged only there is ``refused``;
2. every check that applies runs on the trusted states (``pendverify.checks.catalogue``);
3. a URDF term the closed form cannot express (``robot.ModelForm``) becomes a
   ``model-form`` row: its size relative to the quantity it enters, against the
   model-form threshold;
4. the verdict rules of ``pendverify.checks.verdict`` run: a C with the right C·q̇ but
   not the Christoffel one is a warning, a URDF's Coulomb friction is a warning,
   ``strict`` turns warnings into failures;
5. failures on trusted states are diagnosed (``pendverify.diagnosis.explain``: the entries that
   differ, the shape of each difference, the known traps and a confirmed repair), unless the
   report says not to explain (``--no-explain``).
"""

from __future__ import annotations

import numpy as np

from pendverify.checks.applicability import derived_notes
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks, skipped_notes
from pendverify.checks.report import Report
from pendverify.checks.result import CheckResult
from pendverify.checks.sampling import sample_states
from pendverify.checks.trust import REFUSE_REL, Verdicts, check_conditioning
from pendverify.checks.units import NAME as UNITS
from pendverify.checks.units import units_check
from pendverify.checks.verdict import FAIL, REFUSED, WARN, apply_strict, non_christoffel_c
from pendverify.errors import IllConditionedError
from pendverify.progress import bar
from pendverify.robot.geometry import MODEL_FORM_RTOL
from pendverify.targets import urdf_needed


def trusted(label: str, batch: CheckBatch) -> tuple[list[int], list[str], Verdicts]:
    """The trust rule at every state of ``batch``: (indices of the states it accepts, one sentence
    per refused state, every state's verdict)."""
    with np.errstate(all="ignore"):
        verdicts = Verdicts(batch)
    refusing = ~(verdicts.bound <= REFUSE_REL)
    kept, refused = [int(i) for i in np.flatnonzero(~refusing)], []
    for i in np.flatnonzero(refusing):
        state = batch.states[i]
        try:
            check_conditioning(batch.model, state.q, batch.system, what=label, verdict=verdicts[i])
        except IllConditionedError as exc:
            refused.append(f"{state.label}: {exc}")
        else:
            kept.append(int(i))
    return sorted(kept), refused, verdicts


def model_form_result(target, seed: int) -> CheckResult | None:
    """The ``model-form`` row: a URDF term outside the closed form's family, against its threshold."""
    form = target.system.model_form
    if form is None:
        return None
    rtol = target.system.model_form_rtol
    return CheckResult(
        model=target.label,
        check="model-form",
        description="URDF terms the closed form cannot express, relative to the quantity they enter",
        max_error=form.relative,
        tolerance=rtol,
        max_abs_error=float(np.max(form.allowance)),
        samples=1,
        seed=seed,
        worst_state={"label": "URDF geometry", "q": []},
        largest_error=form.relative,
        largest_tolerance=rtol,
        largest_state={"label": "URDF geometry", "q": []},
        passed=form.within(rtol),
        # within the threshold the checks allow for the term: a pass that says so (a warning)
        status=WARN if form.within(rtol) else FAIL,
        notes=[form.sentence(rtol)],
    )


def coulomb_warnings(target) -> list[str]:
    """One sentence per joint whose URDF Coulomb friction the hand model has no term for."""
    return [
        f"joint {joint}: the URDF's <dynamics friction> = {value:g} (Coulomb) has no term in the hand "
        "model; it is not compared, and Pinocchio's algorithms do not apply it either"
        for joint, value in target.system.urdf_coulomb_friction().items()
    ]


def _refuse(results: list[CheckResult], refused: list[str], total: int) -> None:
    """Checks that could not be judged on every state are refused, unless a trusted state failed.

    With no trusted state at all, every check is refused: a failure there may be rounding.
    """
    all_refused = len(refused) == total
    for r in results:
        if all_refused or r.status != FAIL:
            r.status, r.passed = REFUSED, False
            r.notes.insert(0, f"{len(refused)} of {total} states refused, e.g. {refused[0]}")


def guarded_checks(
    label: str, model, system, states, seed: int
) -> tuple[list[CheckResult], list[str], dict[str, str], CheckBatch]:
    """The checks that apply, on the states the trust rule accepts; checks refused where it refuses.

    The one way every caller (``check``, the certification battery) runs the checks on
    sampled states: (results, one sentence per refused state, {method: why it ran in the
    model's own Python state by state} (``ClosedForms.per_state``), the batch of the states judged).
    """
    batch = CheckBatch(model, system, states)
    kept, refused, _ = trusted(label, batch)
    names = applicable_checks(model, system)
    if refused and kept:
        batch = batch.subset(kept)
    results = run_checks(label, model, system, batch.states, seed, names, batch)
    if refused:
        _refuse(results, refused, len(states))
    return results, refused, batch.forms.per_state, batch


def per_state_note(per_state: dict[str, str]) -> list[str]:
    """The note naming the closed forms evaluated with the model's own Python, state by state."""
    if not per_state:
        return []
    by_reason: dict[str, list[str]] = {}
    for name, reason in per_state.items():  # one reason, often shared by all: said once
        by_reason.setdefault(reason, []).append(name)
    why = "; ".join(f"{', '.join(names)}: {reason}" for reason, names in by_reason.items())
    return [
        f"evaluated with the model's own Python state by state, not as generated NumPy over all "
        f"states (slower, same verdicts): {why}"
    ]


def verify_target(report: Report, target, samples: int, seed: int) -> None:
    """Verify one target and add its results, notes, warnings and diagnoses to ``report``."""
    label = target.label
    units, units_notes = units_check(label, type(target.model), seed)  # the model alone, first
    states = sample_states(target.model, samples, seed)
    report.states[label] = len(states)
    report.sources[label] = target.source
    notes = (
        units_notes
        + target.system.notes
        + target.notes
        + skipped_notes(target.model, target.system)
        + derived_notes(target.model)
    )
    results, refused, per_state, batch = guarded_checks(label, target.model, target.system, states, seed)
    if units is not None:
        results.insert(0, units)
    notes += per_state_note(per_state)
    kept = len(refused) < len(states)
    if refused:
        notes.append(
            f"{len(refused)} of {len(states)} states refused by the trust rule "
            f"(rounding bound above the trust limit): {refused[0]}"
        )
    form = model_form_result(target, seed)  # a property of the URDF, judged at no state
    if form is not None:
        results.append(form)
    warnings = coulomb_warnings(target)
    # a closed form right in high precision but not in double (pendverify.checks.precision)
    warnings += [f"{r.check}: {r.notes[0]}" for r in results if r.status == WARN and r.notes]
    sentence = non_christoffel_c(results)
    if sentence:
        warnings.append(sentence)
    if report.strict:
        apply_strict(results)
    # the diagnosis compares values with Pinocchio's: the URDF's own terms and the units are not values
    failing = [r for r in results if r.status == FAIL and r.check not in ("model-form", UNITS)]
    if failing and kept and report.explain:
        # SymPy and the searches are loaded only when a model fails (a passing run starts faster)
        from pendverify.diagnosis.explain import explain

        diagnoses = explain(batch, failing)
        if diagnoses:
            report.diagnoses[label] = diagnoses
    if notes:
        report.notes[label] = notes
    if warnings:
        report.warnings[label] = warnings
    report.results += results


def model_report(model_cls, seed: int) -> Report:
    """The report of a model given without a robot description: its ``units`` row alone (what the
    model's own expressions can show), labelled with the model's name, and a sentence naming the
    checks that need a robot description."""
    label = model_cls.name
    report = Report(seed=seed, states={label: 0}, results=[])
    units, notes = units_check(label, model_cls, seed)
    if units is None:  # nothing the model alone can show: as before, a robot description is needed
        raise urdf_needed(model_cls, "; ".join(notes))
    report.results.append(units)
    if notes:
        report.notes[label] = notes
    report.skipped.append(
        "the checks against Pinocchio (crba, rnea, gravity, ...) need a robot description: "
        "give --urdf FILE (urdf= in the Python API)"
    )
    return report


def build_report(
    targets,
    samples: int,
    seed: int,
    strict: bool = False,
    model_form_rtol: float = MODEL_FORM_RTOL,
    explain: bool = True,
) -> Report:
    """Every applicable check on every target, judged and diagnosed: one Report."""
    report = Report(seed=seed, states={}, results=[], strict=strict, explain=explain)
    with bar(len(targets), "check", "model") as progress:
        for target in targets:
            target.system.model_form_rtol = model_form_rtol
            verify_target(report, target, samples, seed)
            progress.update(1)
    return report
