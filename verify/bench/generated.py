"""The generated back ends' costs against same-run baselines, and generation/compilation times.

The hand-written kernels these replaced are gone; what they cost against the
generated code (before deletion, same process) is recorded in
``docs/generated-backends.md``.  What stays measurable:

Per call.  ``_calls`` runs ``calls`` evaluations of the generated right-hand side
inside a numba loop (the state moves by 1e-12 each call, so nothing is hoisted out
of the loop); the cost per call is the minimum over ``repeats`` loops divided by
``calls``.  The scipy wrapper (``scipy_rhs``: one Python call, an allocation and the
kernel) is timed against Pinocchio's ``aba`` right-hand side
(``pendverify.simulation.engines``), both called from Python, alternating, so the
ratio wrapper / aba comes from the same run.

One integration.  The fast path's compiled DOP853 (``dop853_runner.integrate``) against
scipy's DOP853 on the same generated right-hand side (``solve_ivp`` on
``scipy_rhs``: the same steps, scipy's bookkeeping in Python), alternating.

Generation and compilation.  ``cache_timings`` runs a fresh Python process twice
on one empty cache directory: the first generates the module (SymPy), imports
it and compiles the right-hand side; the second finds all of it on disk.  The
DOP853 stepper of the generated module is compiled on first use: ``stepper``
adds one short integration to each process.

Nothing here asserts a time; ``python -m pendverify.bench.generated`` prints.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.cache_location import CACHE_VARIABLE
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators import dop853_runner
from pendverify.simulation import engines


@njit(error_model="numpy")
def _calls(rhs, P, x, out, calls):
    acc = 0.0
    for _ in range(calls):
        x[0] += 1e-12
        rhs(P, x, out)
        acc += out[x.shape[0] - 1]
    return acc


def _per_call(rhs, P, x, calls: int, repeats: int) -> float:
    """Seconds per call of the compiled ``rhs`` in a numba loop (the minimum of ``repeats`` loops)."""
    x, out = x.copy(), np.empty_like(x)
    _calls(rhs, P, x, out, 10)  # compile
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        _calls(rhs, P, x, out, calls)
        best = min(best, time.perf_counter() - start)
    return best / calls


def _alternating(runs, repeats: int) -> list[float]:
    """The minimum wall time of each callable in ``runs``, the runs interleaved."""
    best = [np.inf] * len(runs)
    for _ in range(repeats):
        for i, run in enumerate(runs):
            start = time.perf_counter()
            run()
            best[i] = min(best[i], time.perf_counter() - start)
    return best


def _system(name: str, forced: bool):
    model = MODELS[name](load_parameter_file(default_parameter_file(name))[2])
    kw = {}
    if forced:  # friction and a state feedback on every input
        rng = np.random.default_rng(0)
        B = model.input_matrix()
        kw = dict(
            D=np.diag(model.damping_matrix()),
            B=B,
            K=rng.normal(size=(B.shape[1], 2 * model.nv)),
            u0=rng.normal(size=B.shape[1]),
        )
    return model, GeneratedSystem.from_model(model, **kw)


def per_call(calls: int = 100_000, repeats: int = 7, scipy_calls: int = 2_000) -> list[dict]:
    """Cost per call of the generated right-hand side, and of its scipy wrapper against Pinocchio's aba."""
    rows = []
    for name in MODELS:
        for forced in (False, True):
            model, gen = _system(name, forced)
            x = np.linspace(0.3, 1.2, 2 * model.nv)
            t_gen = _per_call(gen.kernel.rhs, gen.packed(), np.append(x, [0.0, 0.0]), calls, repeats)
            wrapper, aba = gen.scipy_rhs(), engines.build("aba", model, gen)
            xa = aba.to_engine(x)
            wrapper(0.0, x), aba.fun(0.0, xa)

            def batch(fun, y):
                return lambda: [fun(0.0, y) for _ in range(scipy_calls)]

            s_gen, s_aba = _alternating([batch(wrapper, x), batch(aba.fun, xa)], repeats)
            rows.append(
                dict(
                    model=name,
                    forces="friction + feedback" if forced else "none",
                    generated_ns=t_gen * 1e9,
                    scipy_generated_us=s_gen / scipy_calls * 1e6,
                    scipy_aba_us=s_aba / scipy_calls * 1e6,
                    scipy_ratio=s_gen / s_aba,
                )
            )
    return rows


def integration(t_end: float = 1.0, tol: float = 1e-10, repeats: int = 15) -> list[dict]:
    """One DOP853 run: the compiled stepper against scipy's on the same generated rhs (friction, feedback)."""
    from scipy.integrate import solve_ivp

    rows = []
    for name in MODELS:
        model, gen = _system(name, True)
        x0 = np.append(np.full(2 * model.nv, 0.4), [0.0, 0.0])
        fun = gen.scipy_rhs()

        def ours(gen=gen, x0=x0):
            return dop853_runner.integrate(gen, x0, t_end, tol, tol)

        def scipy(fun=fun, x0=x0):
            return solve_ivp(fun, (0.0, t_end), x0, method="DOP853", rtol=tol, atol=tol)

        nfev = [ours().nfev, int(scipy().nfev)]  # compile
        fast, slow = _alternating([ours, scipy], repeats)
        rows.append(dict(model=name, nfev=nfev, generated_s=fast, scipy_s=slow, ratio=fast / slow))
    return rows


_CHILD = """
import json, sys, time
start = time.perf_counter()
import numpy as np
from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.numerics import generate
from pendverify.numerics.integrators import dop853_runner
result = {}
for name in MODELS:
    model = MODELS[name](load_parameter_file(default_parameter_file(name))[2])
    t0 = time.perf_counter()
    system = generate.GeneratedSystem.from_model(model)
    t1 = time.perf_counter()
    x = np.full(2 * model.nv, 0.3)
    system.rhs(x)
    t2 = time.perf_counter()
    entry = dict(origin=system.kernel.origin, kernel_s=t1 - t0, rhs_first_call_s=t2 - t1)
    if STEPPER:
        dop853_runner.integrate(system, x, 0.01, 1e-6, 1e-6)
        entry["stepper_first_call_s"] = time.perf_counter() - t2
    result[name] = entry
result["process_s"] = time.perf_counter() - start
print(json.dumps(result))
"""


def cache_timings(stepper: bool = True, cache: str | None = None) -> list[dict]:
    """[first process, second process] on one empty cache directory (seconds; see the docstring)."""
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, CACHE_VARIABLE: cache or tmp}
        runs = []
        for _ in range(2):
            start = time.perf_counter()
            code = _CHILD.replace("STEPPER", repr(stepper))
            out = subprocess.run(
                [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
            )
            run = json.loads(out.stdout.strip().splitlines()[-1])
            run["wall_s"] = time.perf_counter() - start
            runs.append(run)
        return runs


def report(calls: int = 100_000, repeats: int = 7, stepper: bool = True) -> str:
    lines = [f"per call (numba loop of {calls} calls, min of {repeats}; scipy wrappers against aba):"]
    for r in per_call(calls, repeats):
        lines.append(
            f"  {r['model']:22s} {r['forces']:20s} generated {r['generated_ns']:6.1f} ns   scipy wrapper "
            f"{r['scipy_generated_us']:.2f} µs, Pinocchio aba {r['scipy_aba_us']:.2f} µs "
            f"(ratio {r['scipy_ratio']:.2f})"
        )
    lines.append("one DOP853 run, 1 s at rtol = atol = 1e-10, friction + feedback (min of 15):")
    for r in integration():
        lines.append(
            f"  {r['model']:22s} nfev {r['nfev'][0]}/{r['nfev'][1]}  compiled "
            f"{r['generated_s'] * 1e6:7.1f} µs  scipy on the generated rhs {r['scipy_s'] * 1e6:7.1f} µs  "
            f"ratio {r['ratio']:.3f}"
        )
    first, second = cache_timings(stepper)
    for label, run in (("first process (empty cache)", first), ("second process (cached)", second)):
        lines.append(f"{label}: {run['wall_s']:.2f} s wall, {run['process_s']:.2f} s after start")
        for name in MODELS:
            e = run[name]
            extra = (
                f", stepper first call {e['stepper_first_call_s']:.2f} s"
                if "stepper_first_call_s" in e
                else ""
            )
            lines.append(
                f"  {name:22s} {e['origin']:9s} kernel {e['kernel_s']:.2f} s, "
                f"rhs first call {e['rhs_first_call_s']:.2f} s{extra}"
            )
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover
    print(report())
