"""The work–precision plot: error against wall time, log–log, one line per method.

One panel per problem.  x: minimum wall time of the integration [s]; y: the
final-state error (max over components) for the state problems, the max
relative energy error over the run for the energy-only ones.  Adaptive methods are
joined across their tolerances, fixed-step methods across their step sizes.
The fast path is the thick line; scipy's methods are solid, fixed-step methods
dotted.  Rendering uses matplotlib's Agg backend (no display needed).
"""

from __future__ import annotations

import io
import math

from pendverify.bench.run import Results

STYLE = {
    "DOP853 (fast path)": dict(color="#d62728", lw=2.8, marker="o", ms=5, zorder=5),
    "DOP853 (scipy)": dict(color="#1f77b4", lw=1.5, marker="s", ms=4),
    "RK45 (scipy)": dict(color="#17becf", lw=1.5, marker="^", ms=4),
    "Radau (scipy)": dict(color="#9467bd", lw=1.5, marker="v", ms=4),
    "LSODA (scipy)": dict(color="#8c564b", lw=1.5, marker="D", ms=3.5),
    "euler": dict(color="#7f7f7f", lw=1.2, ls=":", marker=".", ms=5),
    "symplectic_euler": dict(color="#bcbd22", lw=1.2, ls=":", marker="x", ms=4),
    "implicit_midpoint": dict(color="#2ca02c", lw=1.2, ls=":", marker="+", ms=6),
    "rk4": dict(color="#ff7f0e", lw=1.2, ls=":", marker="*", ms=5),
}
LABELS = {
    "DOP853 (fast path)": "DOP853, fast path (compiled)",
    "euler": "explicit Euler (compiled)",
    "symplectic_euler": "symplectic Euler (compiled)",
    "implicit_midpoint": "implicit midpoint (compiled)",
    "rk4": "RK4 (compiled)",
}


def figure(results: Results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import LogLocator, NullFormatter

    problems = results.problems
    cols = 2
    rows = math.ceil(len(problems) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(12, 4.6 * rows), squeeze=False)
    for ax, problem in zip(axes.flat, problems, strict=False):
        methods = []
        for p in results.points:
            if p.problem == problem.key and p.method not in methods:
                methods.append(p.method)
        for method in methods:
            pts = [
                p
                for p in results.points
                if p.problem == problem.key and p.method == method and p.ok and p.plotted_error > 0
            ]
            pts = [p for p in pts if math.isfinite(p.plotted_error) and p.plotted_error < 1e3]
            if not pts:
                continue
            engine = "" if method in LABELS else f" + {pts[0].engine}"
            ax.loglog(
                [p.t_min for p in pts],
                [p.plotted_error for p in pts],
                label=LABELS.get(method, method) + engine,
                **STYLE.get(method, {}),
            )
        what = "max relative energy error" if problem.metric == "energy" else "error at final time"
        ax.set_title(f"{problem.title}, T = {problem.duration:g} s", fontsize=11)
        ax.set_xlabel("wall time [s] (minimum of runs)")
        ax.set_ylabel(what)
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(LogLocator(base=10, numticks=12))
            axis.set_minor_formatter(NullFormatter())
        ax.grid(True, which="major", alpha=0.35)
        ax.grid(True, which="minor", alpha=0.12)
    for ax in list(axes.flat)[len(problems) :]:
        ax.axis("off")
    handles, labels = {}, []
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in handles:
                handles[lab] = h
                labels.append(lab)
    fig.legend(
        [handles[lab] for lab in labels], labels, loc="lower center", ncol=3, fontsize=9, frameon=False
    )
    m = results.machine
    fig.suptitle(
        f"Work–precision ({results.config.name}): {m['cpu']}, BLAS threads {m['blas_threads']}",
        fontsize=12,
    )
    fig.tight_layout(rect=(0, 0.08 if rows > 1 else 0.14, 1, 0.97))
    return fig


def render(results: Results, fmt: str = "png") -> bytes:
    import matplotlib.pyplot as plt

    fig = figure(results)
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=110)
    plt.close(fig)
    return buf.getvalue()
