"""Hard cases for any model: derived from its parameters' kinds and its coordinates.

``generic_cases(model_cls, params, urdf)`` builds, for a model file with its URDF and
parameter set (``pendverify stress --analytic FILE --urdf URDF --params PARAMS``):

* ``nominal``: the set itself;
* ``mass ratio``: each ``mass`` parameter × 1e-6 and × 1e6;
* ``length ratio``: each ``length`` and ``offset`` parameter × 1e-3 and × 1e3;
* ``large angle``: every angle moved by ±2πk, |2πk| ≈ 1e3 and 1e6 rad, compared with
  Pinocchio directly and at θ reduced to (−π, π] (the 2πk invariance);
* ``high speed``: rates up to 1e3;
* ``zero gravity``: g = 0;
* ``near singular``: the parameter and state that drive M nearest to singular, found from
  its conditioning (``pendverify.stress.singular``), walked towards the singularity (not for
  a model given by q̈ alone, which has no M).

A changed set's URDF is the given URDF with the parameter's values rewritten where they
sit (``pendverify.robot.rebind``).  A parameter that cannot be rewritten there, or whose
kind the cases do not vary, is listed with the reason (``notes``), never guessed.  Every
case compares through the core checks and the trust rule (one tolerance model): states
the rule refuses are counted, not compared, and not failed.
"""

from __future__ import annotations

import dataclasses
import time

from pendverify.checks.applicability import derived_notes
from pendverify.checks.catalogue import skipped_notes
from pendverify.errors import UnknownNameError
from pendverify.robot.description import urdf_text
from pendverify.robot.rebind import Binding
from pendverify.stress.cases import high_speed_case, large_angle_case
from pendverify.stress.catalogue import StressReport, run_case
from pendverify.stress.framework import SEED, Case, Context, Settings, checks_case, on_description
from pendverify.stress.singular import near_singular_case
from pendverify.targets import plugin_target

MASS_FACTORS = (1e-6, 1e6)
LENGTH_FACTORS = (1e-3, 1e3)
ANGLE_SHIFTS = (1e3, 1e6)  # rad
#: kind -> what the generic cases do with a parameter of that kind
KIND_CASES = {
    "mass": "mass ratio",
    "length": "length ratio",
    "offset": "length ratio",
    "inertia": "",  # one moment scaled alone can break the triangle inequality: not varied alone
    "damping": "",
    "gravity": "zero gravity",
}
NOT_VARIED = {
    "inertia": "inertias are not scaled alone (one moment alone can break the triangle inequality)",
    "damping": "damping enters the checks only through D and the URDF's dampers; not varied",
}


def _label(x: float) -> str:
    return f"×{x:.0e}".replace("e+0", "e").replace("e-0", "e-")


def generic_cases(model_cls, params, urdf: str, source: str = "<URDF>") -> tuple[list[Case], list[str]]:
    """(cases, notes): the hard cases of a model file on its URDF, and what was not varied and why."""
    binding = Binding.of(urdf, params, source)
    cls, notes = model_cls, []
    cases = [
        on_description(checks_case("nominal", "nominal", lambda: params, "allowed", model_cls=cls), urdf, cls)
    ]
    for f in dataclasses.fields(params):
        kind = f.metadata.get("kind")
        group = KIND_CASES.get(kind)
        if group is None:
            notes.append(f"parameter {f.name}: kind {kind!r} is unknown to the stress cases: not varied")
        elif not group:
            notes.append(f"parameter {f.name} ({kind}): {NOT_VARIED[kind]}")
        elif group in ("mass ratio", "length ratio") and not binding.bound(f.name):
            notes.append(f"parameter {f.name} ({kind}): not varied: {binding.reasons[f.name]}")
        elif group != "zero gravity":
            for factor in MASS_FACTORS if group == "mass ratio" else LENGTH_FACTORS:
                changed = params.replace(**{f.name: getattr(params, f.name) * factor})
                case = checks_case(
                    f"{f.name} {_label(factor)}", group, lambda p=changed: p, "allowed", model_cls=cls
                )
                cases.append(on_description(case, binding.rewrite(changed), cls))
    if any(cls.angular):
        for shift in ANGLE_SHIFTS:
            case = large_angle_case(f"|θ| ≈ {shift:.0e} rad", lambda: params, cls, "allowed", shift)
            cases.append(on_description(case, urdf, cls))
    else:
        notes.append("no angular coordinate: no large-angle case")
    cases.append(on_description(high_speed_case("|q̇| ≤ 1e3", lambda: params, cls), urdf, cls))
    if hasattr(params, "g"):
        zero_g = checks_case("g = 0", "zero gravity", lambda: params.replace(g=0.0), model_cls=cls)
        cases.append(on_description(zero_g, urdf, cls))
    else:
        notes.append("the parameter set has no g: no zero-gravity case")
    if cls.has_mass_matrix:
        cases.append(on_description(near_singular_case(cls, params, binding), urdf, cls))
    else:
        notes.append(f"no near-singular case: {cls.__name__} gives q̈ alone, no M to drive towards singular")
    return cases, notes


def run_generic(
    model_file: str, urdf: str, params_file: str | None, settings: Settings, names=None, seed: int = SEED
):
    """``pendverify stress --analytic FILE --urdf URDF --params PARAMS``: the generic cases, run."""
    started = time.perf_counter()
    target = plugin_target(model_file, urdf, params_file)  # validates the three files, as check does
    text = urdf_text(urdf, "stress --analytic")  # UTF-8 whatever the locale; a xacro file expanded
    cases, notes = generic_cases(type(target.model), target.model.params, text, urdf)
    known = tuple(c.name for c in cases)
    for name in names or ():
        if name not in known:
            raise UnknownNameError("stress case", name, known)
    ctx = Context(settings, seed)
    chosen = [c for c in cases if names is None or c.name in names]
    # what is hand-written and checked, and what is derived and therefore not evidence
    evidence = [*skipped_notes(target.model, target.system), *derived_notes(target.model)]
    report = StressReport(settings, seed, [run_case(c, ctx) for c in chosen], notes=notes, evidence=evidence)
    report.elapsed_s = time.perf_counter() - started
    return report
