"""Near-singular M for any model: found from its conditioning, then walked into.

``near_singular_case`` searches, over the parameters the URDF lets it change (``mass``,
``length``, ``offset`` kinds) and over states, for what makes M nearest to singular:
each parameter (and each link's mass with its inertias) is taken to 1e-16 and to 1e16
of its value, κ of the Jacobi-scaled M (diagonal scaled to ones) is scanned over the
sampled states and then maximised from the worst of them by a small Nelder–Mead search.
The winning direction is then walked from the set's value to 1e∓16 of it, in factors
of 100, at the winning state, and every step runs the guarded comparison (trust rule,
then the core checks) on the URDF rewritten for that step.  It passes when every step
the rule accepts verifies, the first step is accepted, and, if the walk's predicted
rounding crosses the refusal limit, the rule refuses there.

Where the walk stops: Pinocchio's own arithmetic.  Pinocchio stores a body's inertia as
(m, c, I_c) and sums two of them (a link into its joint's inertia as the description is
read, a subtree into its parent in CRBA) as ``InertiaTpl::__pequ__`` does::

    c_ab = (m_a c_a + m_b c_b) / max(m_a + m_b, ε)        ε = 2.2e-16, in the file's kg

While m_a + m_b ≥ ε this is the weighted mean of the centres to a few ulps (products and a
sum of non-negative weights: a relative error of at most 3ε of |c|).  Below, the quotient
is clamped: the centre comes out scaled by (m_a + m_b)/ε, and since the URDF reader sums a
link twice (measured, Pinocchio 4.1: c·(m/ε)²), M's m|c|² term by up to (m/ε)⁴: the 2 kg
pendulum's bob at 2e-16 kg sits at 0.406 m instead of 0.5 m and its M is 34 % low.  That
is Pinocchio's M being wrong, not the model.  Rounding is monotone, so fl(m_a + m_b) ≥ m_a
for m_b ≥ 0: every sum that includes a link of mass ≥ ε is ≥ ε.  Hence the limit
(``MASS_FLOOR``): the walk runs only while every link of the rewritten URDF has mass 0 (a
massless link adds nothing, whatever its lever) or ≥ ε kg, an absolute limit because the
clamp is.  The first step that would take a link lighter (and below what the nominal URDF
already holds) is replaced by the factor that puts the lightest link at ``LIMIT_MARGIN``·ε,
and the walk ends there.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pendverify.checks.sampling import State, sample_states
from pendverify.checks.trust import EPS, REFUSE_REL, assess, conditioning
from pendverify.errors import PendverifyError
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.xml_reading import parse_xml
from pendverify.stress.framework import Case, Context, StressResult, compare, error_ratio

WALK_EXPONENTS = tuple(range(0, 17, 2))  # the parameter × 10^-k
SEARCH_KINDS = ("mass", "length", "offset")  # alone; inertias go with their link's mass
SEARCH_ITERATIONS = 200
#: kg: the lightest non-zero link mass at which Pinocchio's inertia sums are not clamped (module docstring)
MASS_FLOOR = EPS
#: the walk's last step puts the lightest link at this multiple of ``MASS_FLOOR``, so that the
#: rounding of the scale factor (a relative ε) cannot take it under the floor
LIMIT_MARGIN = 2.0


def _kappa(model, q) -> float:
    with np.errstate(all="ignore"):
        k = conditioning(model.mass_matrix(np.asarray(q, dtype=float))).kappa_scaled
    return k if math.isfinite(k) else 1e300


def _scaled(params, names, factor):
    return params.replace(**{n: getattr(params, n) * factor for n in names})


def link_masses(urdf_text: str) -> list[float]:
    """Every ``<link><inertial><mass value>`` of a URDF in [kg], in document order."""
    return [float(e.get("value", "0")) for e in parse_xml(urdf_text, "<rewritten URDF>").iter("mass")]


def lightest_changed(urdf_text: str, nominal: list[float]) -> float:
    """The smallest non-zero link mass [kg] of a rewritten URDF among those that differ from
    ``nominal`` (the given URDF's, ``link_masses``); inf if the walk changed none."""
    changed = (m for m, m0 in zip(link_masses(urdf_text), nominal, strict=True) if m != m0 and m > 0)
    return min(changed, default=math.inf)


@dataclasses.dataclass(frozen=True)
class WalkStep:
    """One step of the walk: the parameters scaled by ``factor`` (log10 ``exponent``), and its URDF."""

    exponent: float
    factor: float
    params: object
    urdf: str


def walk_steps(params, names, sign: int, binding) -> tuple[list[WalkStep], str]:
    """The walk's steps, 10^(sign·k) for k in ``WALK_EXPONENTS``, kept where Pinocchio's inertia
    sums are exact (every link mass the walk changes 0 or ≥ ``MASS_FLOOR``, module docstring; the
    masses the URDF is given with are the nominal case's to judge); and what ended it
    early ("" when it ran to the end).  The first step past the floor becomes the factor that
    puts the lightest link at ``LIMIT_MARGIN``·``MASS_FLOOR``, the walk's last step."""
    steps: list[WalkStep] = []
    nominal = link_masses(binding.rewrite(params))
    for k in WALK_EXPONENTS:
        factor = 10.0 ** (sign * k)
        changed = _scaled(params, names, factor)
        urdf = binding.rewrite(changed)
        light = lightest_changed(urdf, nominal)
        if light >= MASS_FLOOR or k == 0:  # the given URDF's own masses are the nominal case's
            steps.append(WalkStep(sign * k, factor, changed, urdf))
            continue
        limit = factor * LIMIT_MARGIN * MASS_FLOOR / light  # the changed masses scale with the factor
        if limit < steps[-1].factor:
            changed = _scaled(params, names, limit)
            urdf = binding.rewrite(changed)
            if lightest_changed(urdf, nominal) >= MASS_FLOOR:
                steps.append(WalkStep(math.log10(limit), limit, changed, urdf))
        stop = (
            f"stopped at ×{steps[-1].factor:.3g}: further, a link would weigh {light:.3g} kg < ε = "
            f"{MASS_FLOOR:.3g} kg, where Pinocchio's inertia sums clamp the mass (its own M is wrong)"
        )
        return steps, stop
    return steps, ""


def _directions(params, binding) -> dict[str, tuple[str, ...]]:
    """What the search may take towards zero: each bound mass, length or offset parameter
    alone, and each link's mass and inertias together (the link made massless)."""
    out = {
        f.name: (f.name,)
        for f in dataclasses.fields(params)
        if f.metadata.get("kind") in SEARCH_KINDS and binding.bound(f.name)
    }
    for link, names in binding.link_groups().items():
        if len(names) > 1:
            out[f"{link} ({', '.join(names)})"] = names
    return out


def _search(model_cls, params, binding, states: list[State]):
    """(direction, parameters, sign, state, κ): what brings M nearest to singular, taken to
    10^∓16 of its value (a vanishing part, or one that dominates all others)."""
    from scipy.optimize import minimize

    best = None
    candidates = [
        (label, names, sign) for label, names in _directions(params, binding).items() for sign in (-1, 1)
    ]
    for label, names, sign in candidates:
        try:
            changed = _scaled(params, names, 10.0 ** (sign * WALK_EXPONENTS[-1]))
            model = model_cls(changed)
            PinocchioSystem.for_model(model_cls, binding.rewrite(changed), getattr(changed, "g", None))
        except PendverifyError:  # e.g. the rewritten URDF breaks an inertia rule: not a direction
            continue

        def objective(q, model=model):
            return -math.log(_kappa(model, q))

        start = min(states, key=lambda s, f=objective: f(s.q))
        found = minimize(
            objective,
            start.q,
            method="Nelder-Mead",
            options={"maxiter": SEARCH_ITERATIONS, "xatol": 1e-10, "fatol": 1e-12},
        )
        q = found.x if found.fun < objective(start.q) else start.q
        kappa = _kappa(model, q)
        if best is None or kappa > best[4]:
            state = dataclasses.replace(start, label=f"{start.label} → κ max", q=np.asarray(q))
            best = (label, names, sign, state, kappa)
    return best


def near_singular_case(model_cls, params, binding, name: str = "near-singular M") -> Case:
    def run(ctx: Context, name: str) -> StressResult:
        states = sample_states(model_cls(params), ctx.settings.random_states, ctx.seed)
        best = _search(model_cls, params, binding, states)
        if best is None:
            return StressResult(name, "no parameter to vary", None, None, None, None, None, True, "not run")
        key, names, sign, state, _ = best
        at_rest = dataclasses.replace(state, label=f"{state.label}, at rest", v=np.zeros_like(state.v))
        walk, stop = walk_steps(params, names, sign, binding)
        steps, results, refused, kappa_raw, kappa_scaled = [], [], 0, 0.0, 0.0
        for step in walk:
            model = model_cls(step.params)
            system = PinocchioSystem.for_model(model_cls, step.urdf, getattr(step.params, "g", None))
            verdict = assess(model, state.q, system)
            comp = compare(f"{name} ×{step.factor:.3g}", model, system, [state, at_rest], ctx.seed)
            steps.append((f"{abs(step.exponent):.3g}", comp.kept, len(comp.refused), verdict.bound))
            results += comp.results
            refused += len(comp.refused)
            if comp.kept:
                kappa_raw, kappa_scaled = max(kappa_raw, comp.kappa_raw), max(kappa_scaled, comp.kappa_scaled)
        failed = [r for r in results if not r.passed]
        crossed = any(bound > REFUSE_REL for *_, bound in steps)
        verified = [k for k, kept, _, _ in steps if kept]
        refusing = [k for k, _, n, _ in steps if n]
        passed = not failed and steps[0][1] > 0 and (refusing or not crossed)
        worst = max(results, key=error_ratio) if results else None
        walk = (
            f"{key} × 10^{'-' if sign < 0 else ''}k at q = {np.array2string(state.q, precision=3)}: "
            "verified at k = "
            f"{', '.join(verified) or 'none'}; refused at k = "
            f"{', '.join(refusing) or 'none'}"
        )
        if stop:
            walk += f"; {stop}"
        if not crossed:
            walk += f"; the rounding bound stays ≤ {REFUSE_REL:g}: M never comes near singular"
        notes = [f"FAIL {r.check} at {r.worst_state['label']}" for r in failed]
        if crossed and not refusing:
            notes.append("the bound crossed the refusal limit but no state was refused")
        return StressResult(
            case=name,
            quantity=f"{worst.check} (worst over the walk)" if worst else "no state verified",
            error=worst.max_error if worst else None,
            tolerance=worst.tolerance if worst else None,
            kappa_raw=kappa_raw or None,
            kappa_scaled=kappa_scaled or None,
            invariant=walk,
            passed=passed,
            note="; ".join(notes),
            level="ok",
            refused=refused,
        )

    return Case(name, "near singular", run)
