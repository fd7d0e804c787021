"""``pendverify check --junit PATH`` and ``--quiet``: the verdict in a form CI systems read.

A passing run gives one test case per check and no failure; a planted mass-matrix
error gives a ``<failure>`` on ``crba`` carrying the table's row; refused and warned
checks map to ``<error>`` and ``<system-out>``; user text is escaped; the counts equal
the report's.  ``--quiet`` prints the verdict line only.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from pendverify.checks.evidence import Evidence
from pendverify.checks.junit import to_junit
from pendverify.checks.report import Report
from pendverify.checks.verdict import FAIL, PASS, REFUSED, WARN
from pendverify.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FILES = ["--urdf", str(EXAMPLES / "cart_pole.urdf"), "--params", str(EXAMPLES / "cart_pole.toml")]


def _cases(path: Path) -> dict[str, ET.Element]:
    root = ET.parse(path).getroot()
    return {case.get("name"): case for case in root.iter("testcase")}


def test_a_passing_check_is_one_passing_test_case_per_check(tmp_path, capsys):
    out = tmp_path / "junit.xml"
    argv = ["check", "--analytic", str(EXAMPLES / "cart_pole.py"), *FILES, "--samples", "30"]
    assert main([*argv, "--junit", str(out), "--json", str(tmp_path / "r.json")]) == 0
    cases = _cases(out)
    root = ET.parse(out).getroot()
    assert root.get("tests") == str(len(cases)) and root.get("failures") == "0" and root.get("errors") == "0"
    assert {"crba", "rnea", "aba", "energy"} <= set(cases)
    assert all(len(c) == 0 for c in cases.values())  # no failure, error or output element


def test_a_planted_error_is_a_failure_carrying_the_table_row(tmp_path, capsys):
    wrong = tmp_path / "wrong.py"
    wrong.write_text(
        "from pendverify.analytic.plugin import load_model_class\n\n"
        f"Base = load_model_class({str(EXAMPLES / 'cart_pole.py')!r})\n\n\n"
        "class Wrong(Base):\n"
        "    def mass_matrix(self, q):\n"
        "        M = super().mass_matrix(q)\n"
        "        M[0, 0] *= 1.001\n"
        "        return M\n"
    )
    out = tmp_path / "junit.xml"
    assert main(["check", "--analytic", str(wrong), *FILES, "--samples", "30", "--junit", str(out)]) == 1
    failure = _cases(out)["crba"].find("failure")
    assert failure is not None and failure.get("message").startswith("crba: error ")
    assert "tolerance" in failure.get("message") and "worst state" in failure.get("message")
    assert int(ET.parse(out).getroot().get("failures")) >= 1


def _result(check: str, status: str, note: str = "") -> Evidence:
    notes = [note] if note else []
    return Evidence("check", check, status, 1e-3, 1e-15, {"label": "s", "q": []}, notes=notes, model="m<&>")


def test_refused_and_warned_checks_and_escaping():
    report = Report(seed=1, states={"m<&>": 1}, results=[])
    report.results = [
        _result("crba", PASS),
        _result("rnea", FAIL, 'a <note> & "quote"'),
        _result("aba", REFUSED, "beyond the trust limit"),
        _result("coriolis", WARN, "a valid C·q̇, not the Christoffel C"),
    ]
    root = ET.fromstring(to_junit(report).split("\n", 1)[1])
    suite = root.find("testsuite")
    assert suite.get("name") == "m<&>" and suite.get("failures") == "1" and suite.get("errors") == "1"
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert cases["rnea"].find("failure").text == 'a <note> & "quote"'
    assert cases["aba"].find("error").get("type") == "refused by the trust rule"
    assert "Christoffel" in cases["coriolis"].find("system-out").text
    assert len(cases["crba"]) == 0


def test_quiet_prints_the_verdict_line_only(capsys):
    assert main(["check", "--model", "double_pendulum", "--no-erd", "--samples", "20", "--quiet"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 1 and lines[0].endswith("all checks pass")
