"""The scene keys of the actuation u(t, q, q̇) and disturbance w(t) laws a scene can switch on.

Actuation (``[effects.actuation]``), u in the model's inputs (``model.inputs``: N·m per
joint for the double pendulum, N on the cart); any model with inputs takes any type:

=========  =====================================================================
type       keys
=========  =====================================================================
constant   value = [u…]
step       time (s), after = [u…], before = [u…] (default zeros)
sine       amplitude = [u…], frequency (Hz > 0), phase (rad, 0), offset = [u…]
table      times = [t0 < t1 < …] (s), values = [[u…], …]: piecewise linear, held at the ends
lqr        Q = [2·nv weights ≥ 0] on (q − q*, q̇), R = [one weight > 0 per input],
           saturation (in u's units, optional), equilibrium (a name in the model's
           ``special_states()``, default "upright"): u = −K (x − x*) about x* = (q*, 0),
           which must be an equilibrium (|H(q*)| within rounding, see ``equilibrium``).
           The cart's scenes: Q on (q, θ1, θ2, q̇, θ̇1, θ̇2), R = [1].
pd         models whose B is square and invertible: kp = [nv], kd = [nv] (≥ 0), target = [nv]
           in model coordinates: the joint-space force τ = kp (target − q) − kd q̇ is
           applied through u = B⁻¹ τ (B = I for the double pendulum: u = τ)
=========  =====================================================================

Disturbance (``[effects.disturbance]``), w in the model's disturbances (``model.disturbances``,
entering as W w; the cart's: on (q, θ1, θ2) in N, N·m, N·m); a model without W takes none:

=========  =====================================================================
impulse    time (s), impulse = [3] (N·s, N·m·s), width (s, 0.01): a rectangular pulse
step       time (s), value = [3]
noise      std = [3], bandwidth (Hz > 0), seed (integer), components (32): band-limited
           noise as a sum of sinusoids with seeded frequencies in (0, bandwidth] and
           phases; smooth, so the integrator needs no breakpoints
=========  =====================================================================

The laws themselves, and their breakpoints (times where they jump or kink, which the
integrator stops at), are in ``pendverify.simulation.laws``.
"""

from __future__ import annotations

import numpy as np

from pendverify.simulation.laws import LQR, PD, Constant, Law, Noise, Pulse, Sine, Step, TabulatedLaw

#: Rounding allowance of the equilibrium test |H_i(q*)| ≤ K·ε·(1 + max|q*|)·Σ|coefficients of H_i|.
EQUILIBRIUM_K = 16.0
EPS = float(np.finfo(float).eps)


ACTUATION_TYPES = ("constant", "step", "sine", "table", "lqr", "pd")
DISTURBANCE_TYPES = ("impulse", "step", "noise")


def parse_actuation(r, model_cls, params=None) -> Law | None:
    """An actuation law from the scene table reader ``r`` (a ``scene_reader.TableReader``; None when absent).

    ``params`` (with the scene's g) is the parameter set ``pd`` reads B from and ``lqr``
    tests its equilibrium with.
    """
    if r is None:
        return None
    n = len(model_cls.inputs)
    if n == 0:
        r.fail("type", r.get("type", None), f"the {model_cls.name} model has no input")
    kind = r.string("type", ACTUATION_TYPES)
    if kind == "constant":
        r.only(("type", "value"))
        return Constant(kind, n, value=r.vector("value", n))
    if kind == "step":
        r.only(("type", "time", "before", "after"))
        return Step(
            kind,
            n,
            time=r.number("time", minimum=0.0),
            before=r.vector("before", n, default=[0.0] * n),
            after=r.vector("after", n),
        )
    if kind == "sine":
        r.only(("type", "amplitude", "frequency", "phase", "offset"))
        return Sine(
            kind,
            n,
            amplitude=r.vector("amplitude", n),
            frequency=r.number("frequency", positive=True),
            phase=r.number("phase", default=0.0),
            offset=r.vector("offset", n, default=[0.0] * n),
        )
    if kind == "table":
        r.only(("type", "times", "values"))
        times = r.get("times")
        if not isinstance(times, list) or len(times) < 2:
            r.fail("times", times, "expected a list of at least 2 increasing times")
        times = r.vector("times", len(times), minimum=0.0)
        if np.any(np.diff(times) <= 0):
            r.fail("times", times.tolist(), "expected strictly increasing times")
        rows = r.get("values")
        if not isinstance(rows, list) or len(rows) != len(times):
            r.fail("values", rows, f"expected {len(times)} rows, one per time")
        values = np.array([_row(r, "values", row, n, i) for i, row in enumerate(rows)])
        return TabulatedLaw(kind, n, times=times, values=values)
    if kind == "lqr":
        r.only(("type", "Q", "R", "saturation", "equilibrium"))
        name, q_star = _equilibrium(r, model_cls(params))
        sat = r.number("saturation", positive=True) if r.has("saturation") else None
        return LQR(
            kind,
            n,
            Q=r.vector("Q", 2 * len(model_cls.coordinates), minimum=0.0),
            R=_positive(r, "R", n),
            saturation=sat,
            equilibrium=name,
            q_star=q_star,
        )
    # pd
    nv = len(model_cls.coordinates)
    if n != nv:
        r.fail(
            "type",
            kind,
            f"PD acts through B⁻¹, and B of {model_cls.name} is {nv}×{n}, not square "
            f"({n} input{'s' if n != 1 else ''} for {nv} coordinates); use lqr or an open-loop type",
        )
    B = np.asarray(model_cls(params).input_matrix(), dtype=float)
    if np.linalg.cond(B) > 1 / (EQUILIBRIUM_K * EPS):
        r.fail("type", kind, f"PD acts through B⁻¹, and B of {model_cls.name} is singular")
    r.only(("type", "kp", "kd", "target"))
    return PD(
        kind,
        n,
        kp=r.vector("kp", nv, minimum=0.0),
        kd=r.vector("kd", nv, minimum=0.0),
        target=r.vector("target", nv, default=[0.0] * nv),
        B_inv=np.linalg.inv(B),
    )


def equilibrium_tolerance(model, q_star: np.ndarray) -> np.ndarray:
    """Per coordinate, how far from zero a computed H_i(q*) may be at an exact equilibrium.

    H_i is a sum of terms c·trig(q…) whose |c| add up to ``gravity_scale()_i``; evaluating it
    in floating point errs by a few ε per term, and the angle itself carries a rounding
    error of ε·|q*| (π is not a double: sin(float(π)) ≈ 1.2e-16), so
    |H_i(q*)| ≤ K·ε·(1 + max|q*|)·gravity_scale_i with K = ``EQUILIBRIUM_K`` = 16, the
    allowance the engine comparison uses for the same kind of evaluation.
    """
    return EQUILIBRIUM_K * EPS * (1.0 + np.max(np.abs(q_star))) * np.abs(model.gravity_scale())


def _equilibrium(r, model) -> tuple[str, np.ndarray]:
    states = model.special_states()
    names = ", ".join(states)
    if not r.has("equilibrium") and "upright" not in states:
        r.fail(
            "equilibrium",
            None,
            f"missing key: {model.name} has no special state 'upright'; name one of {names}",
        )
    name = r.string("equilibrium", default="upright")
    if name not in states:
        r.fail("equilibrium", name, f"expected a special state of {model.name}: one of {names}")
    q_star = np.asarray(states[name], dtype=float)
    H = np.asarray(model.gravity(q_star), dtype=float)
    tol = equilibrium_tolerance(model, q_star)
    if np.any(np.abs(H) > tol):
        i = int(np.argmax(np.abs(H) - tol))
        r.fail(
            "equilibrium",
            name,
            f"not an equilibrium of {model.name}: H(q*) = [{', '.join(f'{h:.3g}' for h in H)}] "
            f"(on {model.coordinates[i]}: {abs(H[i]):.3g} > {tol[i]:.2g}, the rounding allowance)",
        )
    return name, q_star


def _row(r, key, row, n, i):
    if not isinstance(row, list) or len(row) != n or any(isinstance(x, bool) for x in row):
        r.fail(f"{key}[{i}]", row, f"expected a list of {n} numbers")
    arr = np.array(row, dtype=float) if all(isinstance(x, (int, float)) for x in row) else None
    if arr is None or not np.all(np.isfinite(arr)):
        r.fail(f"{key}[{i}]", row, f"expected a list of {n} finite numbers")
    return arr


def _positive(r, key, n):
    arr = r.vector(key, n)
    if np.any(arr <= 0):
        r.fail(key, arr.tolist(), "expected numbers > 0")
    return arr


def parse_disturbance(r, model_cls) -> Law | None:
    if r is None:
        return None
    n = len(model_cls.disturbances)
    if n == 0:
        r.fail("type", r.get("type", None), f"the {model_cls.name} model has no disturbance input")
    kind = r.string("type", DISTURBANCE_TYPES)
    if kind == "impulse":
        r.only(("type", "time", "impulse", "width"))
        return Pulse(
            kind,
            n,
            time=r.number("time", minimum=0.0),
            width=r.number("width", default=0.01, positive=True),
            impulse=r.vector("impulse", n),
        )
    if kind == "step":
        r.only(("type", "time", "value"))
        return Step(
            kind, n, time=r.number("time", minimum=0.0), before=np.zeros(n), after=r.vector("value", n)
        )
    r.only(("type", "std", "bandwidth", "seed", "components"))
    seed = r.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        r.fail("seed", seed, "expected an integer >= 0")
    components = r.get("components", 32)
    if isinstance(components, bool) or not isinstance(components, int) or components < 1:
        r.fail("components", components, "expected an integer >= 1")
    return Noise(
        kind,
        n,
        std=r.vector("std", n, minimum=0.0),
        bandwidth=r.number("bandwidth", positive=True),
        seed=seed,
        components=components,
    )
