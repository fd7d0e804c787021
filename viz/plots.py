"""Energy and work-balance plots of a run (matplotlib, Agg, SVG).

Top panel: the energy flows of ``pendverify.simulation.invariants`` along the samples,

    ΔE(t) = E(t) − E(0),   W_in(t) = ∫ q̇ᵀ(B u + W w) dt,   W_diss(t) = ∫ q̇ᵀ D q̇ dt,

in [J]; curves of effects that are off are omitted.  Bottom panel: the balance
residual |r(t)| = |ΔE − W_in + W_diss| in [J] on a log scale, which the exact
flow keeps at zero; its size is the integration error the invariant bounds.
The invariant results (error/tolerance, pass or fail) are quoted in the title.

Figures are built with ``matplotlib.figure.Figure`` (no pyplot state, no
display) and written deterministically (fixed SVG ids, no date).
"""

from __future__ import annotations

import io

import numpy as np

EPS = float(np.finfo(float).eps)
SIZE_IN = (7.0, 5.0)


def energy_flows(run) -> dict[str, np.ndarray]:
    """ΔE, W_in, W_diss and r at the run's samples, in [J]."""
    n = run.dynamics.nv
    x = run.integration.samples_x
    w_in, w_diss = x[:, 2 * n], x[:, 2 * n + 1]
    delta = run.energy - run.energy[0]
    return {"ΔE": delta, "W_in": w_in, "W_diss": w_diss, "r": delta - w_in + w_diss}


def short_name(name: str) -> str:
    """An invariant's name without its formula: "energy drift |E(t) − E(0)|" → "energy drift"."""
    cut = min((name.find(m) for m in (" |", " E(", " ∫") if m in name), default=len(name))
    return name[:cut]


def energy_plot_svg(run) -> str:
    """The two-panel energy / work-balance figure of a ``Run`` as SVG text."""
    import matplotlib
    from matplotlib.figure import Figure

    flows = energy_flows(run)
    scene = run.scene
    fig = Figure(figsize=SIZE_IN, layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(3, 2))
    top.plot(run.t, flows["ΔE"], color="#1f77b4", label="ΔE = E(t) − E(0)")
    if scene.actuation is not None or scene.disturbance is not None:
        top.plot(run.t, flows["W_in"], color="#2ca02c", ls="--", label="W_in  (work of u and w)")
    if scene.damping is not None:
        top.plot(run.t, -flows["W_diss"], color="#d62728", ls="-.", label="−W_diss  (friction)")
    top.axhline(0.0, color="0.6", lw=0.8)
    top.set_ylabel("energy [J]")
    top.legend(loc="best", fontsize=8)
    top.grid(alpha=0.3)
    verdicts = "\n".join(
        f"{short_name(i.name)} {'pass' if i.passed else 'FAIL'} "
        f"(relative error {i.error:.1e}, tolerance {i.tolerance:.1e})"
        for i in run.invariants
    )
    top.set_title(f"{scene.name}\n{verdicts}", fontsize=9)
    bottom.semilogy(
        run.t, np.abs(flows["r"]) + EPS, color="#9467bd", lw=1.0, label="|r| = |ΔE − W_in + W_diss|"
    )
    bottom.set_ylabel("residual [J]")
    bottom.legend(loc="lower right", fontsize=8)
    bottom.set_xlabel("t [s]")
    bottom.grid(alpha=0.3, which="both")
    buf = io.StringIO()
    with matplotlib.rc_context({"svg.hashsalt": "pendverify", "svg.fonttype": "none"}):
        fig.savefig(buf, format="svg", metadata={"Date": None})
    return buf.getvalue()
