"""The shapes public ``matlabFunction`` output takes, each read and verified against its robot file.

The conformance matrix's ``matlab`` format writes M and [C, G, B, V] with vector arguments.  The
files engineers publish take other shapes; each is written here from the systems' independently
derived closed forms (``tests/conformance/closed_forms.py``), in ``matlabFunction``'s layout
(``formats.matlab_function``), and checked with ``pendverify check`` against the system's URDF:

* OptimTraj's acrobot (github.com/MatthewPeterKelly/OptimTraj, ``autoGen_acrobotDynamics.m``):
  ``[M11,M12,M21,M22,f1,f2] = f(q1,q2,dq1,dq2,u,m1,…)``, scalar arguments and outputs, later
  outputs in ``if nargout > K`` blocks, and balance equations (torques about the base and about
  the elbow, negated): the matrix is not the symmetric mass matrix (``balance = true``);
* OptimTraj's cart-pole (``autoGen_cartPoleDynamics.m``): ``[ddx,ddq] = f(q,dq,u,…)``, the
  accelerations themselves, the cart's coordinate not an argument;
* the cart double pendulum of a course (NTNU TTK4130, ``PendulumODEMatrices.m``):
  ``[W,RHS] = f(in1,F,in3)``, W·q̈ = RHS, W refilled by ``reshape`` column by column, in1 the
  state and in3 the parameters.

A planted error (10 % on W(1,2) and W(2,1) of the course's file) is named at the ``.m`` file's
line and its repair printed in MATLAB syntax; a certificate of a declaration embeds its ``.m`` files,
and ``recheck`` reads those, not the files at their paths now.
"""

from __future__ import annotations

import json
import re

import pytest
import sympy as sp

from pendverify.certify import model_source
from tests.cli_run import run_main
from tests.conformance.closed_forms import model_forms
from tests.conformance.formats import FACTOR, _toml_value, matlab_function
from tests.conformance.systems import SYSTEMS, parameter_file, write_description

pytestmark = pytest.mark.conformance


def _declaration(system, keys: dict[str, str], files: list[str], arguments: dict) -> str:
    kinds = system.parameter_kinds("urdf")
    coordinates = {
        f"q{i + 1}": "angle" if k == "revolute" else "position" for i, (k, _) in enumerate(system.joints)
    }
    lines = [f'name = "{system.name}"', f"inputs = {_toml_value(list(system.inputs))}"]
    lines += [f"{k} = {v}" for k, v in keys.items()]
    lines += ["", "[coordinates]", *(f'{c} = "{k}"' for c, k in coordinates.items())]
    lines += ["", "[parameters]", *(f'{p} = {{ kind = "{k}" }}' for p, k in kinds.items())]
    lines += ["", "[urdf]", f"joints = {_toml_value(list(system.joint_names))}"]
    lines += ["", "[matlab]", f"files = {_toml_value(files)}"]
    if arguments:
        lines += ["", "[matlab.arguments]", *(f"{a} = {_toml_value(v)}" for a, v in arguments.items())]
    return "\n".join(lines) + "\n"


def _scalar_arguments(expressions, system) -> dict[str, None]:
    """The symbols the expressions use, in matlabFunction's order (coordinates, rates, inputs,
    parameters), each a scalar argument."""
    used = {s.name for e in expressions for s in sp.sympify(e).free_symbols}
    order = [f"q{i + 1}" for i in range(system.dof)] + [f"dq{i + 1}" for i in range(system.dof)]
    order += [*system.inputs, *system.parameter_kinds("urdf")]
    return {name: None for name in order if name in used}


def acrobot_optimtraj(system, plant: bool = False):
    """Balance equations: the first row the torque about the base of both links, the second about
    the elbow (row 1 + row 2, row 2 of M q̈ = forcing), as Newton–Euler gives them: T·M is not
    symmetric, and the file writes it negated (MM·q̈ = ff with MM = −T·M)."""
    forms = model_forms(system.name, "urdf")
    T = sp.Matrix([[1, 1], [0, 1]])
    MM, ff = -(T * forms.M), -(T * forms.forcing)
    if plant:  # 10 % on one entry: balance equations need not be symmetric, so only q̈ shows it
        MM[0, 1] = FACTOR * MM[0, 1]
    outputs = {f"M{i + 1}{j + 1}": sp.Matrix([[MM[i, j]]]) for i in range(2) for j in range(2)}
    outputs |= {f"f{i + 1}": sp.Matrix([[ff[i]]]) for i in range(2)}
    arguments = _scalar_arguments([*MM, *ff], system)
    text = matlab_function("autoGen_acrobotDynamics", outputs, arguments)
    B = _toml_value([[str(e) for e in forms.B.row(i)] for i in range(2)])
    keys = {"M": '[["-M11", "-M12"], ["-M21", "-M22"]]', "f": '["-f1", "-f2"]', "balance": "true", "B": B}
    if system.damping:  # q̈ alone does not determine D (balance equations: M is not the mass matrix)
        keys["D"] = _toml_value([[str(e) for e in forms.D.row(i)] for i in range(2)])
    return {"autoGen_acrobotDynamics.m": text}, keys, {}


def cart_pole_optimtraj(system):
    forms = model_forms(system.name, "urdf")
    qddot = forms.M.LUsolve(forms.forcing).applyfunc(sp.cancel)
    outputs = {f"ddq{i + 1}": sp.Matrix([[qddot[i]]]) for i in range(2)}
    text = matlab_function("autoGen_cartPoleDynamics", outputs, _scalar_arguments(qddot, system))
    B = _toml_value([[str(e) for e in forms.B.row(i)] for i in range(2)])
    return {"autoGen_cartPoleDynamics.m": text}, {"qddot": '["ddq1", "ddq2"]', "B": B}, {}


def cart_double_pendulum_course(system, plant: bool = False):
    forms = model_forms(system.name, "urdf")
    state = [str(s) for s in (*forms.q, *forms.dq)]
    params = list(system.parameter_kinds("urdf"))
    W = forms.M.copy()
    if plant:  # 10 % on W(1,2) and W(2,1): an error of the derivation, W stays symmetric
        W[0, 1] = W[1, 0] = FACTOR * W[0, 1]
    outputs = {"W": W, "RHS": forms.forcing}
    arguments = {"in1": state, **dict.fromkeys(system.inputs), "in3": params}
    text = matlab_function("PendulumODEMatrices", outputs, arguments)
    return {"PendulumODEMatrices.m": text}, {"M": '"W"', "f": '"RHS"'}, {"in1": state, "in3": params}


SHAPES = {
    "acrobot": acrobot_optimtraj,
    "cart_pole": cart_pole_optimtraj,
    "cart_double_pendulum": cart_double_pendulum_course,
}


def _write(tmp_path, name: str, plant: bool = False):
    system = SYSTEMS[name]
    files, keys, arguments = SHAPES[name](system, plant) if plant else SHAPES[name](system)
    for file, text in files.items():
        (tmp_path / file).write_text(text)
    model = tmp_path / f"{name}.toml"
    model.write_text(_declaration(system, keys, list(files), arguments))
    params = tmp_path / f"{name}.params.toml"
    params.write_text(parameter_file(system, "urdf"))
    return model, write_description(system, "urdf", tmp_path), params


def _files(model, urdf, params) -> list[str]:
    return ["--analytic", str(model), "--urdf", str(urdf), "--params", str(params)]


@pytest.mark.parametrize("name", SHAPES)
def test_the_published_shapes_verify(tmp_path, name):
    model, urdf, params = _write(tmp_path, name)
    done = run_main(["check", *_files(model, urdf, params), "--samples", "20"])
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]


def test_a_planted_error_is_named_at_the_m_files_line_in_matlab_syntax(tmp_path):
    """The error planted in M[1,2] (= M[2,1], one temporary of matlabFunction's layout) is repaired
    as the line of that temporary, in MATLAB's operators and the file's names; the line edited as
    printed, the model passes."""
    model, urdf, params = _write(tmp_path, "cart_double_pendulum", plant=True)
    done = run_main(["check", *_files(model, urdf, params), "--samples", "20"])
    assert done.returncode == 1, done.stdout[-3000:] + done.stderr[-2000:]
    repairs = [r for r in done.stdout.splitlines() if "M[1,2]: " in r and "makes every check pass" in r]
    assert repairs, done.stdout[-3000:]
    found = re.search(r"PendulumODEMatrices\.m, line (\d+), which computes M\[1,2\], M\[2,1\]", repairs[0])
    assert found, repairs[0]
    written, suggested = re.search(r"M\[1,2\]: (.*?;) → (.*?;) makes", repairs[0]).groups()
    assert re.fullmatch(r"t\d+ = .*", suggested) and "**" not in suggested, repairs[0]  # MATLAB, its names
    path = tmp_path / "PendulumODEMatrices.m"
    lines = path.read_text().split("\n")
    assert lines[int(found.group(1)) - 1].strip() == written
    lines[int(found.group(1)) - 1] = suggested
    path.write_text("\n".join(lines))
    done = run_main(["check", *_files(model, urdf, params), "--samples", "20"])
    assert done.returncode == 0, done.stdout[-3000:]


def test_an_error_in_balance_equations_fails(tmp_path):
    """balance = true reads q̈ = M⁻¹ f: an error in one entry of the balance matrix fails aba."""
    model, urdf, params = _write(tmp_path, "acrobot", plant=True)
    done = run_main(["check", *_files(model, urdf, params), "--samples", "20"])
    assert done.returncode == 1, done.stdout[-3000:] + done.stderr[-2000:]
    assert re.search(r"aba .* FAIL", done.stdout) and "qddot[" in done.stdout, done.stdout[-3000:]


def test_a_certificate_embeds_the_m_files(tmp_path, signing_keys):
    """``recheck`` reads the .m files the certificate embeds: in a fresh process's place (the
    classes loaded in this one forgotten), with the files at their old paths edited."""
    model, urdf, params = _write(tmp_path, "cart_double_pendulum")
    out = tmp_path / "certs"
    key, public = signing_keys / "pendverify-signing.key.pem", signing_keys / "pendverify-signing.pub.pem"
    argv = ["certify", "--analytic", str(model), "--urdf", str(urdf), "--params", str(params)]
    done = run_main([*argv, "-o", str(out), "--samples", "30", "--key", str(key)])
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    cert_path = next(out.glob("*.cert.json"))
    record = json.loads(cert_path.read_text())["model_source"]
    assert [c["file"] for c in record["companions"]] == ["PendulumODEMatrices.m"]
    assert (out / "PendulumODEMatrices.m").read_text() == (tmp_path / "PendulumODEMatrices.m").read_text()
    (tmp_path / "PendulumODEMatrices.m").write_text("function [W,RHS] = PendulumODEMatrices(in1,in3)\n")
    model_source._LOADED.clear()
    done = run_main(["recheck", str(cert_path), "--trust", str(public)])
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    bundled = out / "PendulumODEMatrices.m"  # a bundle's .m file edited: refused, naming it
    bundled.write_text(bundled.read_text().replace("W = reshape", "W = 2.*reshape"))
    done = run_main(["recheck", str(cert_path), "--trust", str(public)])
    assert done.returncode == 2 and "PendulumODEMatrices.m" in done.stderr, done.stderr[-2000:]
