"""A check report as JUnit XML, the format CI systems show as test results.

One ``<testsuite>`` per model (target) and one ``<testcase>`` per check: ``classname``
is the model, ``name`` the check.  A failed check carries a ``<failure>`` whose
message is the table's row (error, tolerance, worst state) and whose text holds the
check's notes; a refused check carries an ``<error>`` (not judged: neither pass nor
fail); a warning passes and puts its sentence in ``<system-out>``.  A failing case's
text carries its notes and the model's diagnosis (``pendverify.diagnosis.explain``); notes
and warnings go to the suite's ``<system-out>``.  The attribute counts (tests, failures, errors) are
computed from the cases, so a CI system's totals equal the table's.  Text is escaped
by ``xml.etree.ElementTree``; the file is UTF-8.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from pendverify.checks.verdict import FAIL, REFUSED, WARN


def _row(r) -> str:
    state = r.label
    return f"{r.name}: error {r.error:.3e}, tolerance {r.tolerance:.3e}, worst state {state}"


def _case(r, seconds: float, diagnosis: list[str]) -> ET.Element:
    case = ET.Element("testcase", classname=r.model, name=r.name, time=f"{seconds:.3f}")
    notes = "\n".join(r.notes)
    if r.status == FAIL:
        text = "\n".join([*r.notes, *(f"diagnosis: {line}" for line in diagnosis)])
        ET.SubElement(case, "failure", message=_row(r), type="verification failed").text = text
    elif r.status == REFUSED:
        ET.SubElement(case, "error", message=_row(r), type="refused by the trust rule").text = notes
    elif r.status == WARN:
        ET.SubElement(case, "system-out").text = f"warning: {_row(r)}\n{notes}"
    return case


def to_junit(report) -> str:
    """The JUnit XML text of a ``pendverify.checks.report.Report``."""
    root = ET.Element("testsuites", name="pendverify check")
    models = list(dict.fromkeys(r.model for r in report.results))
    per_case = report.elapsed_s / max(len(report.results), 1)  # the checks are not timed one by one
    for model in models:
        results = [r for r in report.results if r.model == model]
        suite = ET.SubElement(
            root,
            "testsuite",
            name=model,
            tests=str(len(results)),
            failures=str(sum(r.status == FAIL for r in results)),
            errors=str(sum(r.status == REFUSED for r in results)),
            skipped="0",
            time=f"{per_case * len(results):.3f}",
        )
        diagnosis = [f.message for f in report.diagnoses.get(model, [])]
        suite.extend(_case(r, per_case, diagnosis) for r in results)
        lines = [*report.notes.get(model, []), *report.warnings.get(model, [])]
        if lines:
            ET.SubElement(suite, "system-out").text = "\n".join(lines)
    root.set("tests", str(len(report.results)))
    root.set("failures", str(sum(r.status == FAIL for r in report.results)))
    root.set("errors", str(sum(r.status == REFUSED for r in report.results)))
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
