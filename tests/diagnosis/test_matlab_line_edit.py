"""A confirmed repair of a ``.m`` model printed as the one line of its file to change
(``pendverify.analytic.matlab_edit``): the line is the one whose change makes exactly the repaired
entries right; the test applies the printed line to the file and checks the model again, which
must then pass.  A temporary that also serves a right entry is not the line edited; an entry no
single assignment computes keeps its whole repair.

The robot: tests/analytic/data/pendulum_functions.urdf, 2 kg at 0.5 m below a hinge with
damping 0.1; M = m l², G = m g l sin θ, D = b.
"""

from __future__ import annotations

import re
from pathlib import Path

from tests.cli_run import run_main

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "tests" / "analytic" / "data" / "pendulum_functions.urdf"
DECLARATION = """name = "pendulum_m"
M = "M"
H = "G"
C = [["0"]]
D = [["b"]]
[coordinates]
theta = "angle"
[parameters]
m = { kind = "mass" }
l = { kind = "length" }
b = { kind = "damping" }
g = { kind = "gravity" }
[urdf]
joints = ["hinge"]
[matlab]
files = ["pend.m"]
[matlab.arguments]
in1 = ["theta"]
"""
PARAMS = 'model = "pendulum_m"\n[parameters]\nm = 2.0\nl = 0.5\nb = 0.1\ng = 9.81\n'


def _check(tmp_path: Path, body: str, declaration: str = DECLARATION):
    (tmp_path / "pend.m").write_text(body)
    (tmp_path / "pend.toml").write_text(declaration)
    (tmp_path / "params.toml").write_text(PARAMS)
    argv = ["check", "--analytic", str(tmp_path / "pend.toml"), "--urdf", str(URDF)]
    return run_main([*argv, "--params", str(tmp_path / "params.toml"), "--samples", "20"])


def _repair(stdout: str) -> str:
    lines = [line for line in stdout.splitlines() if "M[1,1]: " in line and "makes every check pass" in line]
    assert lines, stdout[-3000:]
    return lines[0]


def _applied(tmp_path: Path, repair: str) -> str:
    """pend.m with the printed line edit made: the line it names replaced by the suggested one."""
    found = re.search(r"M\[1,1\]: (.*?;) → (.*?;) makes every check pass", repair)
    line = int(re.search(r"pend\.m, line (\d+), which computes M\[1,1\]", repair).group(1))
    written, suggested = found.group(1), found.group(2)
    lines = (tmp_path / "pend.m").read_text().split("\n")
    assert lines[line - 1].strip() == written, (lines[line - 1], written)
    lines[line - 1] = suggested
    return "\n".join(lines)


def test_the_temporary_that_is_wrong_is_the_line_edited_and_the_edit_passes(tmp_path):
    body = (
        "function [M,G] = pend(in1,m,l,g)\n"
        "theta = in1(1,:);\n"
        "t2 = l.^2;\n"
        "t3 = m.*t2.*2.0;\n"  # line 4: twice m l²
        "M = t3;\n"
        "if nargout > 1\n    G = g.*l.*m.*sin(theta);\nend\n"
    )
    done = _check(tmp_path, body)
    assert done.returncode == 1, done.stdout[-3000:]
    repair = _repair(done.stdout)
    assert "pend.m, line 4, which computes M[1,1]" in repair, repair
    assert "t3 = m.*t2.*2.0; → t3 = m.*t2;" in repair, repair  # in the file's own names
    fixed = _applied(tmp_path, repair)
    assert _check(tmp_path, fixed).returncode == 0


def test_a_temporary_that_also_serves_a_right_entry_is_not_the_line_edited(tmp_path):
    """t3 = 2 m l² is wrong for M but G = g t3 sin θ / (2 l) is right: changing t3 would break G,
    so the line edited is M's own, and the edit passes."""
    body = (
        "function [M,G] = pend(in1,m,l,g)\n"
        "theta = in1(1,:);\n"
        "t3 = m.*l.^2.*2.0;\n"
        "M = t3;\n"  # line 4
        "if nargout > 1\n    G = g.*t3.*sin(theta)./l./2.0;\nend\n"
    )
    done = _check(tmp_path, body)
    assert done.returncode == 1, done.stdout[-3000:]
    repair = _repair(done.stdout)
    assert "pend.m, line 4, which computes M[1,1]" in repair, repair
    assert _check(tmp_path, _applied(tmp_path, repair)).returncode == 0


def test_a_one_element_matrix_literal_is_a_scalar_assignment_and_its_line_is_edited(tmp_path):
    """M = [2 m l²]: a 1×1 matrix is a scalar in MATLAB, so the line is an assignment of M[1,1]."""
    body = (
        "function [M,G] = pend(in1,m,l,g)\n"
        "theta = in1(1,:);\n"
        "M = [m.*l.^2.*2.0];\n"
        "if nargout > 1\n    G = g.*l.*m.*sin(theta);\nend\n"
    )
    done = _check(tmp_path, body)
    repair = _repair(done.stdout)
    assert "pend.m, line 3, which computes M[1,1]" in repair, repair
    assert _check(tmp_path, _applied(tmp_path, repair)).returncode == 0


def test_an_entry_no_assignment_computes_alone_keeps_its_whole_repair(tmp_path):
    """The minimal double pendulum's M from a .m file with M[1,1] written inside the reshape, 4 β cos θ2
    for 2 β cos θ2: no scalar assignment is M[1,1] (t2 = β cos θ2 is right), so the repair is the
    entry's, at the reshape's line."""
    text = (REPO / "examples" / "minimal_double_pendulum_text.toml").read_text()
    start, end = text.index("M = ["), text.index("C = [")
    declaration = text[:start] + 'M = "W"\n' + text[end:]
    declaration += '\n[matlab]\nfiles = ["mass.m"]\n[matlab.arguments]\nin1 = ["theta1", "theta2"]\n'
    (tmp_path / "model.toml").write_text(declaration)
    (tmp_path / "mass.m").write_text(
        "function W = mass(in1,m1,m2,l1,r1,r2,I1,I2)\n"
        "theta2 = in1(2,:);\n"
        "t2 = m2.*l1.*r2.*cos(theta2);\n"
        "t3 = I2 + m2.*r2.^2;\n"
        "W = reshape([I1 + I2 + m1.*r1.^2 + m2.*(l1.^2 + r2.^2) + 4.0.*t2,t3 + t2,t3 + t2,t3],[2,2]);\n"
    )
    argv = [
        "check",
        "--analytic",
        str(tmp_path / "model.toml"),
        "--urdf",
        str(REPO / "urdf" / "double_pendulum.urdf"),
    ]
    done = run_main(
        [*argv, "--params", str(REPO / "examples" / "minimal_double_pendulum.toml"), "--samples", "20"]
    )
    assert done.returncode == 1, done.stdout[-3000:] + done.stderr[-2000:]
    repair = _repair(done.stdout)
    assert "which computes" not in repair and "mass.m, line 5, entry M[1,1]" in repair, repair


def test_an_entry_the_declaration_writes_negated_is_repaired_at_its_temporary(tmp_path):
    """OptimTraj's layout: the file returns −M entry by entry (M = [["-M11"]]); the wrong temporary
    t3 = 2 m l² is −M11's negative, and its line is the one printed."""
    body = (
        "function [M11,G1] = pend(in1,m,l,g)\n"
        "theta = in1(1,:);\n"
        "t2 = l.^2;\n"
        "t3 = m.*t2.*2.0;\n"  # line 4
        "M11 = -t3;\n"
        "G1 = g.*l.*m.*sin(theta);\n"
    )
    declaration = DECLARATION.replace('M = "M"\nH = "G"', 'M = [["-M11"]]\nH = ["G1"]')
    done = _check(tmp_path, body, declaration)
    assert done.returncode == 1, done.stdout[-3000:] + done.stderr[-2000:]
    repair = _repair(done.stdout)
    assert "pend.m, line 4, which computes M[1,1]" in repair and "→ t3 = m.*t2;" in repair, repair
    assert _check(tmp_path, _applied(tmp_path, repair), declaration).returncode == 0
