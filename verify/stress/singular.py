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
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pendverify.checks.sampling import State, sample_states
from pendverify.checks.trust import REFUSE_REL, assess, conditioning
from pendverify.errors import PendverifyError
from pendverify.robot.system import PinocchioSystem
from pendverify.stress.framework import Case, Context, StressResult, compare, error_ratio

WALK_EXPONENTS = tuple(range(0, 17, 2))  # the parameter × 10^-k
SEARCH_KINDS = ("mass", "length", "offset")  # alone; inertias go with their link's mass
SEARCH_ITERATIONS = 200


def _kappa(model, q) -> float:
    with np.errstate(all="ignore"):
        k = conditioning(model.mass_matrix(np.asarray(q, dtype=float))).kappa_scaled
    return k if math.isfinite(k) else 1e300


def _scaled(params, names, factor):
    return params.replace(**{n: getattr(params, n) * factor for n in names})


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
        steps, results, refused, kappa_raw, kappa_scaled = [], [], 0, 0.0, 0.0
        for k in WALK_EXPONENTS:
            changed = _scaled(params, names, 10.0 ** (sign * k))
            model = model_cls(changed)
            system = PinocchioSystem.for_model(
                model_cls, binding.rewrite(changed), getattr(changed, "g", None)
            )
            verdict = assess(model, state.q, system)
            comp = compare(f"{name} ×1e{sign * k}", model, system, [state, at_rest], ctx.seed)
            steps.append((k, comp.kept, len(comp.refused), verdict.bound))
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
            f"{', '.join(map(str, verified)) or 'none'}; refused at k = "
            f"{', '.join(map(str, refusing)) or 'none'}"
        )
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
