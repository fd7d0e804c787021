"""The review page: verification table, animations, energy plots and invariants on one page.

``review_page(report, scenes)`` returns the HTML text of ``index.html``.  The
page is static and self-contained apart from the files it links, which sit
beside it (``scenes/<stem>.html`` animations, ``plots/<stem>.svg`` figures), so
the whole directory can be opened from file:// or copied anywhere.

Every string that comes from a user (scene names, file paths, notes) goes
through ``html.escape``; link targets are also percent-encoded.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from urllib.parse import quote

from pendverify.diagnosis.ranking import explanations_first
from pendverify.jsonio import versions

_STYLE = """
body { font-family: sans-serif; margin: 24px auto; max-width: 1200px; color: #222; padding: 0 16px; }
h1 { font-size: 22px; margin-bottom: 4px; }
h2 { font-size: 18px; margin: 28px 0 6px; border-top: 1px solid #ccc; padding-top: 14px; }
.meta { color: #666; font-size: 13px; }
.verdict { font-weight: bold; padding: 2px 8px; border-radius: 4px; }
.pass { color: #17621c; } .fail { color: #b00020; }
.verdict.pass { background: #e3f4e4; } .verdict.fail { background: #fbe3e6; }
table { border-collapse: collapse; font-size: 12px; margin: 6px 0 10px; }
.table-box { max-width: 100%; overflow-x: auto; }
th, td { border-bottom: 1px solid #e2e2e2; padding: 3px 8px; text-align: left; }
th { background: #f4f4f4; }
td.num { text-align: right; font-family: monospace; white-space: nowrap; }
.scene { display: grid; grid-template-columns: 560px 1fr; gap: 16px; align-items: start; }
.scene > div { min-width: 0; }
iframe { width: 560px; height: 380px; border: 1px solid #ccc; }
.scene img { width: 100%; max-width: 620px; border: 1px solid #eee; }
.notes { font-size: 12px; color: #555; }
"""


@dataclass
class SceneReview:
    """One scene's entry: where its animation and plot are, and its invariant results."""

    name: str
    source: str  # the scene file's name, relative to the folder of scenes
    animation: str  # path of the animation, relative to index.html
    plot: str  # path of the energy plot, relative to index.html
    invariants: list  # pendverify.checks.evidence.Evidence, one per invariant
    passed: bool
    model: str = ""
    duration_s: float = 0.0
    notes: list[str] = field(default_factory=list)


def _e(text: object) -> str:
    return html.escape(str(text))


def _href(path: str) -> str:
    return html.escape(quote(path))


def _verdict(passed: bool) -> str:
    return f'<span class="verdict {"pass" if passed else "fail"}">{"pass" if passed else "FAIL"}</span>'


def _state(state: dict) -> str:
    q = ", ".join(f"{x:.3g}" for x in state["q"])
    return f"{state['label']} q=({q})"


def _boxed(table: str) -> str:
    """A table in its own box, which scrolls sideways when the table is wider than the page."""
    return f'<div class="table-box">{table}</div>\n'


def _breakable(name: str) -> str:
    """A model's name, escaped, that may wrap after "_" and ":" (a long name makes a narrow column)."""
    return _e(name).replace("_", "_<wbr>").replace(":", ":<wbr>")


def check_matrix(report) -> str:
    """One row per check, one column per model: error / tolerance and the verdict."""
    models = list(dict.fromkeys(r.model for r in report.results))
    checks = list(dict.fromkeys(r.name for r in report.results))
    cell = {(r.name, r.model): r for r in report.results}

    def td(check: str, model: str) -> str:
        r = cell.get((check, model))
        if r is None:
            return "<td></td>"
        verdict = "pass" if r.passed else "fail"
        tip = f"worst state {_state(r.at)}"
        return (
            f'<td class="num {verdict}" title="{_e(tip)}">{r.error:.1e} / {r.tolerance:.1e} '
            f"{'✓' if r.passed else '✗ FAIL'}</td>"
        )

    head = "".join(f"<th>{_breakable(m)}</th>" for m in models)
    rows = "\n".join(f"<tr><th>{_e(c)}</th>{''.join(td(c, m) for m in models)}</tr>" for c in checks)
    return _boxed(f"<table><tr><th>check \\ model</th>{head}</tr>\n{rows}\n</table>")


def diagnosis_block(report) -> str:
    """What is wrong in each failing model and how to fix it, under the check matrix: the
    diagnosis's findings (``pendverify.diagnosis.explain``), the most likely fix first
    (``pendverify.diagnosis.ranking``)."""
    out = []
    for model, findings in report.diagnoses.items():
        items = "".join(
            f'<li class="{_e(f.kind)}"><strong>{_e(f.kind)}</strong> {_e(f.message)}</li>'
            for f in explanations_first(findings)
        )
        out.append(
            f'<div class="diagnosis"><p class="fail">what is wrong in {_e(model)}, and how to fix it:</p>'
            f"<ul>{items}</ul></div>\n"
        )
    return "".join(out)


def check_table(report) -> str:
    """The verification table of ``pendverify check`` (a ``pendverify.checks.report.Report``).

    A check × model matrix of error / tolerance first, then the table exactly as
    the command prints it (with the worst states) in a collapsible block.
    """
    rows = "\n".join(
        "<tr>"
        f"<td>{_e(r.model)}</td><td>{_e(r.name)}</td>"
        f'<td class="num">{r.error:.2e}</td><td class="num">{r.tolerance:.2e}</td>'
        f"<td>{_e(_state(r.at))}</td><td>{_verdict(r.passed)}</td>"
        "</tr>"
        for r in report.results
    )
    notes = "".join(
        f"<li>[{_e(model)}] {_e(note)}</li>" for model, items in report.notes.items() for note in items
    )
    total = sum(report.states.values())
    return (
        check_matrix(report)
        + diagnosis_block(report)
        + f'<p class="meta">{len(report.results)} checks on {len(report.states)} model(s), {total} states '
        f"(seed {report.seed}); each cell: largest error / tolerance, relative, in diagonally scaled "
        "coordinates: tolerance = K·ε·(1 + |θ|max)·cond(T)² (+ model-form allowance).</p>\n"
        "<details><summary>the full table, with the worst states</summary>\n"
        + _boxed(
            "<table><tr><th>model</th><th>check</th><th>error</th><th>tolerance</th>"
            f"<th>worst state</th><th>result</th></tr>\n{rows}\n</table>"
        )
        + "</details>\n"
        + (f'<ul class="notes">{notes}</ul>\n' if notes else "")
    )


def invariant_table(scene: SceneReview) -> str:
    rows = "\n".join(
        "<tr>"
        f'<td>{_e(i.name)}</td><td class="num">{i.error:.2e}</td><td class="num">{i.tolerance:.2e}</td>'
        f"<td>{_verdict(i.passed)}</td><td>{_e(i.detail)}</td>"
        "</tr>"
        for i in scene.invariants
    )
    return _boxed(
        "<table><tr><th>invariant</th><th>error</th><th>tolerance</th><th>result</th><th>where</th></tr>\n"
        f"{rows}\n</table>"
    )


def scene_section(scene: SceneReview) -> str:
    notes = "".join(f"<li>{_e(n)}</li>" for n in scene.notes)
    return (
        f"<h2>{_e(scene.name)} {_verdict(scene.passed)}</h2>\n"
        f'<p class="meta">{_e(scene.source)} · {_e(scene.model)} · {scene.duration_s:g} s · '
        f'<a href="{_href(scene.animation)}">open the animation</a></p>\n'
        '<div class="scene">\n'
        f'<iframe src="{_href(scene.animation)}" title="{_e(scene.name)}" loading="lazy"></iframe>\n'
        f'<div><img src="{_href(scene.plot)}" alt="energy and work balance of {_e(scene.name)}">\n'
        f"{invariant_table(scene)}\n"
        + (f'<ul class="notes">{notes}</ul>\n' if notes else "")
        + "</div>\n</div>\n"
    )


def review_page(report, scenes: list[SceneReview], title: str = "pendverify review") -> str:
    """The whole ``index.html``."""
    passed = report.passed and all(s.passed for s in scenes)
    v = versions()
    versions_line = (
        f"pendverify {v['pendverify']} · Pinocchio {v['pinocchio']} · numpy {v['numpy']} · "
        f"Python {v['python']}"
    )
    summary = (
        f"{len(report.results)} checks {_verdict(report.passed)} · "
        f"{len(scenes)} scenes, invariants {_verdict(all(s.passed for s in scenes))}"
    )
    contents = "".join(f'<li><a href="#scene-{i}">{_e(s.name)}</a></li>' for i, s in enumerate(scenes))
    sections = "".join(
        f'<section id="scene-{i}">\n{scene_section(s)}</section>\n' for i, s in enumerate(scenes)
    )
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>{_e(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n"
        f"<h1>{_e(title)} {_verdict(passed)}</h1>\n"
        f'<p class="meta">{_e(versions_line)}</p>\n<p>{summary}</p>\n'
        f"<h2>Pinocchio against the closed forms</h2>\n{check_table(report)}"
        f"<h2>Scenes</h2>\n<ol>{contents}</ol>\n{sections}"
        "</body>\n</html>\n"
    )
