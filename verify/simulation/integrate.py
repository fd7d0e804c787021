"""Integrate a scene's dynamics, stopping at every breakpoint of its laws.

Adaptive methods are scipy's ``solve_ivp`` (its accepted steps are kept, with a
dense output for the samples).  A fixed-step method (``rk4``) is its tableau in
``pendverify.numerics.integrators`` run by the one explicit stepper; its samples come
from cubic Hermite interpolation between steps.  Integration is
split at the laws' breakpoints (steps, pulses, table knots) and into chunks
that drive the progress bar.

A state that leaves double's range ends the run with an ``IntegrationError``
(``solve_ivp``'s failure, or the fixed step's finiteness guard), so the overflow
on the way there is computed without NumPy's RuntimeWarnings (``np.errstate``).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from scipy.integrate import solve_ivp

from pendverify.errors import IntegrationError
from pendverify.numerics.integrators import TABLEAUX, explicit_rk_step
from pendverify.progress import new_bar

PROGRESS_CHUNKS = 20


@dataclass
class Integration:
    steps_t: np.ndarray  # times of the integrator's own steps (including t = 0)
    steps_x: np.ndarray  # (len(steps_t), nx)
    samples_t: np.ndarray
    samples_x: np.ndarray
    nfev: int
    segments: int


def _segments(duration: float, breakpoints: list[float]) -> np.ndarray:
    chunks = np.linspace(0.0, duration, PROGRESS_CHUNKS + 1)
    inner = [b for b in breakpoints if 0.0 < b < duration]
    return np.unique(np.concatenate([chunks, inner]))


def _progress(total: int, label: str):
    return new_bar(total, label, "seg", leave=False)


def _finite(rhs, label: str, method: str):
    """``rhs`` refusing a state that left double's range: a fixed step has no step-size control to stop it."""

    def guarded(t, x):
        if not np.all(np.isfinite(x)):
            raise IntegrationError(
                label,
                f"{method} left double's range at t = {t:.6g} s (the state overflowed); the scene's values "
                "(gravity, damping, initial state) ask for a smaller step or are beyond double precision",
            )
        return rhs(t, x)

    return guarded


def _overflow_reported_as_failure():
    """No RuntimeWarning for overflow, inf − inf or x/0: a non-finite state fails the run instead."""
    return np.errstate(over="ignore", invalid="ignore", divide="ignore")


def _fixed_step_segment(rhs, t0, t1, x0, h, tableau):
    """Steps of ``tableau`` from t0 to t1 (equal steps, at most h), with f at every step for the
    Hermite samples; that f is the next step's first stage."""
    n = max(1, int(np.ceil((t1 - t0) / h - 1e-9)))
    ts = np.linspace(t0, t1, n + 1)
    xs, fs = [x0], [rhs(t0, x0)]
    x, nfev = x0, 1
    for a, b in pairwise(ts):
        x = explicit_rk_step(rhs, a, x, b - a, tableau, k1=fs[-1])
        xs.append(x)
        fs.append(rhs(b, x))
        nfev += tableau.stages
    return ts, np.array(xs), np.array(fs), nfev


def _hermite(ts, xs, fs, t):
    i = np.clip(np.searchsorted(ts, t, side="right") - 1, 0, len(ts) - 2)
    h = ts[i + 1] - ts[i]
    s = ((t - ts[i]) / h)[:, None]
    h = h[:, None]
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
    return h00 * xs[i] + h10 * h * fs[i] + h01 * xs[i + 1] + h11 * h * fs[i + 1]


class _StepLimit(Exception):
    """Raised by ``_StepCounter`` out of ``solve_ivp`` at time ``t``."""

    def __init__(self, t: float):
        super().__init__(t)
        self.t = t


class _StepCounter:
    """A ``solve_ivp`` event that counts the run's steps and stops it beyond ``limit``.

    ``solve_ivp`` evaluates its events once at the start of a segment and once after every
    accepted step; the event never changes sign, and past the limit it raises ``_StepLimit``."""

    terminal = False
    direction = 0

    def __init__(self, limit: int):
        self.limit, self.steps = limit, 0

    def __call__(self, t, x) -> float:
        self.steps += 1
        if self.steps > self.limit:
            raise _StepLimit(float(t))
        return 1.0

    def segment_started(self) -> None:
        self.steps -= 1  # the call at the segment's start is no step


def _too_many_steps(label: str, integrator, t: float, duration: float) -> IntegrationError:
    return IntegrationError(
        label,
        f"key 'integrator.max_steps': {integrator.method} took more than {integrator.max_steps:g} steps and "
        f"reached only t = {t:.6g} s of {duration:g} s; the scene's values (gravity, damping, initial "
        "state, rtol/atol) ask for very small steps. Raise the limit with integrator.max_steps in the "
        "scene, or change those values",
    )


def integrate(rhs, x0, duration, integrator, sample_times, breakpoints=(), label="simulate") -> Integration:
    bounds = _segments(duration, list(breakpoints))
    counter = _StepCounter(integrator.max_steps + 1) if integrator.adaptive else None  # + the first call
    steps_t, steps_x, samples_t, samples_x = [np.array([0.0])], [x0[None, :]], [], []
    nfev = 0
    x = np.asarray(x0, dtype=float)
    bar = _progress(len(bounds) - 1, label)
    for a, b in pairwise(bounds):
        last = b == bounds[-1]
        inside = sample_times[(sample_times >= a) & ((sample_times < b) | (last & (sample_times <= b)))]
        if integrator.adaptive:
            try:
                with _overflow_reported_as_failure():
                    sol = solve_ivp(
                        rhs,
                        (a, b),
                        x,
                        method=integrator.method,
                        rtol=integrator.rtol,
                        atol=integrator.atol,
                        dense_output=True,
                        events=counter,
                    )
            except _StepLimit as stop:
                if bar is not None:
                    bar.close()
                raise _too_many_steps(label, integrator, stop.t, duration) from None
            counter.segment_started()
            if sol.status != 0:
                raise IntegrationError(
                    label,
                    f"{integrator.method} failed at t = {sol.t[-1]:.6g} s: {sol.message.rstrip('.')}; the "
                    "scene's values (gravity, damping, initial state, rtol/atol) ask for more than the "
                    "integrator can follow in double precision",
                )
            ts, xs = sol.t, sol.y.T
            nfev += sol.nfev
            if inside.size:
                with _overflow_reported_as_failure():
                    dense = sol.sol(inside).T
                if not np.all(np.isfinite(dense)):
                    raise IntegrationError(
                        label,
                        f"{integrator.method}'s solution left double's range between t = {a:.6g} s and "
                        f"{b:.6g} s; the scene's values (gravity, damping, initial state, rtol/atol) are "
                        "beyond double precision",
                    )
                samples_x.append(dense)
        else:
            with _overflow_reported_as_failure():
                ts, xs, fs, n = _fixed_step_segment(
                    _finite(rhs, label, integrator.method),
                    a,
                    b,
                    x,
                    integrator.step,
                    TABLEAUX[integrator.method],
                )
            nfev += n
            if inside.size:
                samples_x.append(_hermite(ts, xs, fs, inside))
        samples_t.append(inside)
        steps_t.append(ts[1:])
        steps_x.append(xs[1:])
        x = xs[-1]
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    return Integration(
        steps_t=np.concatenate(steps_t),
        steps_x=np.vstack(steps_x),
        samples_t=np.concatenate(samples_t),
        samples_x=np.vstack(samples_x) if samples_x else np.empty((0, x0.size)),
        nfev=nfev,
        segments=len(bounds) - 1,
    )
