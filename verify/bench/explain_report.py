"""The text of ``pendverify bench explain``: one row per model file, the totals against the 90 %
target, the repairs printed as confirmed or with their ambiguity stated, the wrong ones printed
as confirmed (the target is none), the largest diagnosis against the time bound
(``pendverify.bench.explain`` measures)."""

from __future__ import annotations

import numpy as np

from pendverify.bench.explain import BOUND_S, ExplainBench


def _rate(part: int, whole: int) -> str:
    return f"{part}/{whole} ({100 * part / whole:.1f} %)" if whole else "–"


def table(bench: ExplainBench) -> str:
    """The figures as text: one row per model file, the totals, the time against the bound."""
    header = (
        "model file",
        "dof",
        "planted",
        "detected",
        "named",
        "repaired",
        "restored",
        "confirmed",
        "ambiguous",
        "wrong conf.",
        "clean",
        "mean s",
        "max s",
    )
    rows = []
    for m in bench.models:
        seconds = [s.seconds for s in m.scores if s.detected] or [0.0]
        detected = m.count("detected")
        rows.append(
            (
                m.label,
                str(bench.dof[m.label]),
                str(len(m.scores)),
                str(detected),
                _rate(m.count("named"), detected),
                _rate(m.count("repaired"), detected),
                _rate(m.count("restored"), detected),
                str(m.count("confirmed")),
                str(m.count("ambiguity_stated")),
                str(m.count("wrong_confirmed")),
                "yes" if m.clean else "NO",
                f"{np.mean(seconds):.2f}",
                f"{max(seconds):.2f}",
            )
        )
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True))]
    lines.append("-" * len(lines[0]))
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    t = bench.totals()
    slowest = max((s.seconds for m in bench.models for s in m.scores if s.detected), default=0.0)
    lines += [
        "",
        f"{'a seeded sample' if bench.quick else 'every'} planted error ({t['planted']}), "
        f"{t['detected']} detected by the checks: entry named {_rate(t['named'], t['detected'])}, "
        f"repaired {_rate(t['repaired'], t['detected'])}, the planted edit or an equivalent one "
        f"{_rate(t['restored'], t['detected'])} (target ≥ 90 %: "
        f"{'met' if t['detected'] and t['restored'] >= 0.9 * t['detected'] else 'NOT met'})",
        f"restored and confirmed {_rate(t['confirmed'], t['detected'])}, restored with the ambiguity "
        f"stated {_rate(t['ambiguity_stated'], t['detected'])}; wrong repairs printed as confirmed: "
        f"{t['wrong_confirmed']} (target 0: {'met' if t['wrong_confirmed'] == 0 else 'NOT met'})",
        f"untouched models clean: {sum(m.clean for m in bench.models)}/{len(bench.models)}; "
        f"largest diagnosis {slowest:.2f} s (bound {BOUND_S:g} s for up to 3 degrees of freedom: "
        f"{'met' if slowest <= BOUND_S else 'NOT met'})",
    ]
    return "\n".join(lines)
