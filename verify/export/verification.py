"""Exported code checked as a model before it is reported: never trusted for being generated.

The files of one language are written into a private temporary folder and read back as a model
file pendverify reads, which ``check`` then compares with the robot on its usual states and
tolerances:

* **NumPy**: the module is a NumPy-functions model file (``pendverify.analytic.numpy_model``), or
  ``DYNAMICS`` code for a model of q̈ alone;
* **MATLAB**: the declaration reads the ``.m`` files through the MATLAB reader (docs/matlab.md);
* **C**: the source is compiled by the system's C compiler (``$CC``, else ``cc``) into a shared
  library, and a NumPy-functions shim calls its functions through ``ctypes`` (a ``double`` array
  per argument, the parameters as the ``NAME_params`` structure).  No compiler is one line: the
  files are written, marked unverified;
* **CasADi**: the module is imported and its ``casadi.Function`` objects are called on numbers by
  a shim.

Models of q̈ alone are read back as ``DYNAMICS`` code (``pendverify.analytic.python_dynamics``).

``Verification.status`` is ``verified`` (every check passes), ``failed`` (a check fails, or the
code does not compile or load: the line says which) or ``unverified`` (nothing compared it with
a robot: no compiler, or no robot description given).
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from pendverify.errors import PendverifyError
from pendverify.export.closed_forms import QUANTITIES, ExportForms
from pendverify.export.names import c_name

#: the longest a C compilation may take [s]: a 7-link arm's source compiles in a few seconds
COMPILE_SECONDS = 120

VERIFIED, FAILED, UNVERIFIED = "verified", "failed", "unverified"


@dataclass(frozen=True)
class Verification:
    """How the written code was verified: ``status`` (module docstring) and one line saying so."""

    status: str
    line: str


def verify(lang: str, files: dict[str, str], forms: ExportForms, urdf, params, check) -> Verification:
    """Read ``files`` (name → text) of ``lang`` back as a model and check it with ``check``
    (``pendverify.api.check``, given by the caller) (module docstring)."""
    if urdf is None:
        return Verification(
            UNVERIFIED, "no robot description given (--urdf): nothing compared the code with it"
        )
    with tempfile.TemporaryDirectory(prefix="pendverify-export-") as tmp:
        folder = Path(tmp)
        for name, text in files.items():
            (folder / name).write_text(text, encoding="utf-8")
        prefix = c_name(forms.name)
        if lang == "numpy":
            model = folder / f"{prefix}_numpy.py"
        elif lang == "matlab":
            model = folder / f"{prefix}_matlab.toml"
        elif lang == "casadi":
            model = folder / f"{prefix}_casadi_shim.py"
            model.write_text(_shim(forms, *_casadi_calls(folder / f"{prefix}_casadi.py")), encoding="utf-8")
        else:
            built = _compile(folder, prefix)
            if isinstance(built, Verification):
                return built
            model = folder / f"{prefix}_c_shim.py"
            model.write_text(_shim(forms, *_c_calls(forms, built)), encoding="utf-8")
        return _checked(model, urdf, params, check)


def _checked(model: Path, urdf, params, check) -> Verification:
    try:
        report = check(model, urdf, params, explain=False, erd=False)
    except PendverifyError as exc:
        return Verification(FAILED, f"the written code does not load as a model: {exc}")
    if not report.robot_compared:
        return Verification(
            UNVERIFIED, "no robot description given (--urdf): nothing compared the code with it"
        )
    errors = [r.largest_error for r in report.results if r.largest_error is not None]
    worst = max((e for e in errors if math.isfinite(e)), default=0.0)
    states = sum(report.states.values())
    checks = f"{len(report.results)} check{'s' * (len(report.results) != 1)}"
    counted = f"{checks} on {states} states, largest relative error {worst:.2e}"
    if report.passed:
        return Verification(VERIFIED, f"pendverify check of the written code: all checks pass ({counted})")
    failing = ", ".join(sorted({r.name for r in report.failures()}))
    return Verification(FAILED, f"pendverify check of the written code: {failing} FAIL ({counted})")


def _compile(folder: Path, prefix: str) -> Path | Verification:
    compiler = shutil.which(os.environ.get("CC") or "cc")
    if compiler is None:
        return Verification(
            UNVERIFIED,
            f"no C compiler ({os.environ.get('CC') or 'cc'}) on this machine: the C files are not compiled",
        )
    library = folder / f"lib{prefix}.so"
    command = [
        compiler,
        "-std=c99",
        "-O2",
        "-shared",
        "-fPIC",
        "-o",
        str(library),
        str(folder / f"{prefix}.c"),
        "-lm",
    ]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=COMPILE_SECONDS, check=False)
    except subprocess.TimeoutExpired:
        return Verification(FAILED, f"{compiler} took more than {COMPILE_SECONDS} s to compile {prefix}.c")
    except OSError as exc:
        return Verification(UNVERIFIED, f"{compiler} could not be run ({exc.strerror or exc})")
    if done.returncode != 0:
        first = next(
            (line for line in done.stderr.splitlines() if "error" in line), done.stderr.strip()[:200]
        )
        return Verification(FAILED, f"{compiler} refused {prefix}.c: {first}")
    return library


def _c_calls(forms: ExportForms, library: Path) -> tuple[list[str], object]:
    """The shim's head and body (``_shim``) that call the compiled C through ``ctypes``: a ``double``
    array per argument, the parameters as the ``NAME_params`` structure, the result into ``out``."""
    prefix = c_name(forms.name)
    head = [
        "import ctypes",
        "",
        f"_lib = ctypes.CDLL({str(library)!r})",
        f"_NAMES = {[p.name for p in forms.p]!r}",
        "",
        "",
        "class _Params(ctypes.Structure):",
        "    _fields_ = [(name, ctypes.c_double) for name in _NAMES]",
        "",
        "",
        "def _vector(x):",
        "    return (ctypes.c_double * len(x))(*[float(e) for e in x])",
    ]

    def body(key: str, arguments: list[str]) -> list[str]:
        size = forms.quantities[key].rows * forms.quantities[key].cols
        params = "ctypes.byref(_Params(*[float(p[name]) for name in _NAMES]))"
        call = [*(f"_vector({a})" for a in arguments), params, "out"]
        return [
            f"    out = (ctypes.c_double * {size})()",
            f"    _lib.{prefix}_{QUANTITIES[key][0]}({', '.join(call)})",
            "    value = numpy.array(out[:], dtype=float)",
        ]

    return head, body


def _casadi_calls(module: Path) -> tuple[list[str], object]:
    """The shim's head and body (``_shim``) that call the CasADi module's functions on numbers."""
    head = [
        "import importlib.util",
        "",
        f"_spec = importlib.util.spec_from_file_location('exported_casadi', {str(module)!r})",
        "_casadi = importlib.util.module_from_spec(_spec)",
        "_spec.loader.exec_module(_casadi)",
    ]

    def body(key: str, arguments: list[str]) -> list[str]:
        call = [*(f"numpy.asarray({a}, dtype=float)" for a in arguments), "_casadi.parameters(p)"]
        return [f"    value = numpy.array(_casadi.{key}({', '.join(call)}), dtype=float).reshape(-1)"]

    return head, body


def _shim(forms: ExportForms, head: list[str], body) -> str:
    """A model pendverify reads whose functions call the written code: NumPy functions
    (``pendverify.analytic.numpy_model``), or ``DYNAMICS`` code for a model of q̈ alone.  ``body(key,
    arguments)`` gives the lines that set ``value``, the quantity's entries row-major, from the
    arrays named ``arguments`` and the parameters ``p``."""
    lines = [
        '"""The exported code as a model (pendverify.export.verification)."""',
        "import numpy",
        *head,
        "",
        "",
    ]
    alone = "M" not in forms.quantities  # q̈ alone: DYNAMICS code, u the inputs then the disturbances
    for key, matrix in forms.quantities.items():
        if alone:
            parameters = ["q", "v", "u", "**p"]
            given = forms.dynamics_arrays()
        else:
            parameters = [*QUANTITIES[key][1], "p"]
            given = {a: a for a in "qvuw"}
        shape = {"matrix": f".reshape({matrix.rows}, {matrix.cols})", "vector": "", "number": "[0]"}
        lines += [
            f"def {key}({', '.join(parameters)}):",
            *body(key, [given[a] for a in forms.arguments(key)]),
            f"    return value{shape[forms.shape(key)]}",
            "",
            "",
        ]
    if alone:
        lines += ["DYNAMICS = qddot", f"DECLARATION = {forms.dynamics_declaration()!r}"]
    else:
        lines.append(f"DECLARATION = {forms.declaration()!r}")
    return "\n".join(lines) + "\n"
