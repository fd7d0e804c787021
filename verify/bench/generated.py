"""The generated right-hand side against the hand kernels: cost per call, and generation/compilation times.

Per call.  ``_calls`` runs ``calls`` evaluations of one compiled right-hand side
inside a numba loop (the state moves by 1e-12 each call, so nothing is hoisted
out of the loop); the right-hand side is a dispatcher argument, so the loop is
specialised, and compiled, for each one alike.  The loops of the hand kernel and
of the generated one alternate (a busy machine slows both alike); the cost per
call is the minimum over ``repeats`` loops divided by ``calls``, and the ratio
generated / hand is formed from the same run.  The scipy wrapper (``scipy_rhs``: one Python call, an
allocation and the kernel) is timed the same way with fewer calls.

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
from pendverify.numerics import generate, kernels


@njit(error_model="numpy")
def _calls(rhs, P, x, out, calls):
    acc = 0.0
    for _ in range(calls):
        x[0] += 1e-12
        rhs(P, x, out)
        acc += out[x.shape[0] - 1]
    return acc


def _per_call(pairs, x, calls: int, repeats: int) -> list[float]:
    """Seconds per call of each (rhs, P) in ``pairs``: the loops interleaved, the minimum of each."""
    x, out = x.copy(), np.empty_like(x)
    for rhs, P in pairs:
        _calls(rhs, P, x, out, 10)  # compile
    best = [np.inf] * len(pairs)
    for _ in range(repeats):
        for i, (rhs, P) in enumerate(pairs):
            start = time.perf_counter()
            _calls(rhs, P, x, out, calls)
            best[i] = min(best[i], time.perf_counter() - start)
    return [b / calls for b in best]


def _per_scipy_call(funs, x, calls: int, repeats: int) -> list[float]:
    best = [np.inf] * len(funs)
    for _ in range(repeats):
        for i, fun in enumerate(funs):
            fun(0.0, x)
            start = time.perf_counter()
            for _ in range(calls):
                fun(0.0, x)
            best[i] = min(best[i], time.perf_counter() - start)
    return [b / calls for b in best]


def _systems(name: str, forced: bool):
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
    return model, kernels.FastSystem.from_model(model, **kw), generate.GeneratedSystem.from_model(model, **kw)


def per_call(calls: int = 100_000, repeats: int = 7, scipy_calls: int = 20_000) -> list[dict]:
    """Cost per call of the generated and the hand right-hand side, per seed and force law."""
    rows = []
    for name in MODELS:
        for forced in (False, True):
            model, hand, gen = _systems(name, forced)
            x = np.append(np.linspace(0.3, 1.2, 2 * model.nv), [0.0, 0.0])
            pairs = [(kernels._rhs, hand.packed()), (gen.kernel.rhs, gen.packed())]
            t_hand, t_gen = _per_call(pairs, x, calls, repeats)
            s_hand, s_gen = _per_scipy_call([hand.scipy_rhs(), gen.scipy_rhs()], x, scipy_calls, repeats)
            rows.append(
                dict(
                    model=name,
                    forces="friction + feedback" if forced else "none",
                    hand_ns=t_hand * 1e9,
                    generated_ns=t_gen * 1e9,
                    ratio=t_gen / t_hand,
                    scipy_hand_us=s_hand * 1e6,
                    scipy_generated_us=s_gen * 1e6,
                    scipy_ratio=s_gen / s_hand,
                )
            )
    return rows


def integration(t_end: float = 1.0, tol: float = 1e-10, repeats: int = 15) -> list[dict]:
    """One DOP853 run (fastpath's hand kernels vs the generated module's stepper), friction and feedback."""
    from pendverify.numerics import fastpath

    rows = []
    for name in MODELS:
        model, hand, gen = _systems(name, True)
        x0 = np.append(np.full(2 * model.nv, 0.4), [0.0, 0.0])
        runs = [(fastpath.integrate, hand), (generate.integrate, gen)]
        nfev = [run(system, x0, t_end, tol, tol).nfev for run, system in runs]  # compile
        best = [np.inf, np.inf]
        for _ in range(repeats):
            for i, (run, system) in enumerate(runs):
                start = time.perf_counter()
                run(system, x0, t_end, tol, tol)
                best[i] = min(best[i], time.perf_counter() - start)
        rows.append(dict(model=name, nfev=nfev, hand_s=best[0], generated_s=best[1], ratio=best[1] / best[0]))
    return rows


_CHILD = """
import json, sys, time
start = time.perf_counter()
import numpy as np
from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.numerics import generate
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
        generate.integrate(system, x, 0.01, 1e-6, 1e-6)
        entry["stepper_first_call_s"] = time.perf_counter() - t2
    result[name] = entry
result["process_s"] = time.perf_counter() - start
print(json.dumps(result))
"""


def cache_timings(stepper: bool = True, cache: str | None = None) -> list[dict]:
    """[first process, second process] on one empty cache directory (seconds; see the docstring)."""
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, PENDVERIFY_CACHE=cache or tmp)
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
    lines = [f"per call (numba loop of {calls} calls, min of {repeats}):"]
    for r in per_call(calls, repeats):
        lines.append(
            f"  {r['model']:22s} {r['forces']:20s} hand {r['hand_ns']:6.1f} ns  generated "
            f"{r['generated_ns']:6.1f} ns  ratio {r['ratio']:.2f}   scipy wrapper {r['scipy_hand_us']:.2f} / "
            f"{r['scipy_generated_us']:.2f} µs (ratio {r['scipy_ratio']:.2f})"
        )
    lines.append("one DOP853 run, 1 s at rtol = atol = 1e-10, friction + feedback (min of 15):")
    for r in integration():
        lines.append(
            f"  {r['model']:22s} nfev {r['nfev'][0]}/{r['nfev'][1]}  hand {r['hand_s'] * 1e6:7.1f} µs  "
            f"generated {r['generated_s'] * 1e6:7.1f} µs  ratio {r['ratio']:.2f}"
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
