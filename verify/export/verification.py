"""Exported code checked as a model before it is reported: never trusted for being generated.

The files of one language are written into a private temporary folder and read back as a model
file pendverify reads, which ``check`` then compares with the robot on its usual states and
tolerances:

* **NumPy**: the module is a NumPy-functions model file (``pendverify.analytic.numpy_model``);
* **MATLAB**: the declaration reads the ``.m`` files through the MATLAB reader (docs/matlab.md);
* **C**: the source is compiled by the system's C compiler (``$CC``, else ``cc``) into a shared
  library, and a NumPy-functions shim calls its functions through ``ctypes`` (a ``double`` array
  per argument, the parameters as the ``NAME_params`` structure).  No compiler is one line: the
  files are written, marked unverified.

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
        else:
            built = _compile(folder, prefix)
            if isinstance(built, Verification):
                return built
            model = folder / f"{prefix}_c_shim.py"
            model.write_text(_shim(forms, built), encoding="utf-8")
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
    counted = f"{len(report.results)} checks on {states} states, largest relative error {worst:.2e}"
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


def _shim(forms: ExportForms, library: Path) -> str:
    """A NumPy-functions model whose functions call the compiled C through ``ctypes``."""
    prefix = c_name(forms.name)
    names = [p.name for p in forms.p]
    n = len(forms.coordinates)
    lines = [
        '"""The exported C code as a NumPy-functions model (pendverify.export.verification)."""',
        "import ctypes",
        "import numpy",
        "",
        f"_lib = ctypes.CDLL({str(library)!r})",
        "",
        "",
        f"_NAMES = {names!r}",
        "",
        "",
        "class _Params(ctypes.Structure):",
        "    _fields_ = [(name, ctypes.c_double) for name in _NAMES]",
        "",
        "",
        "def _params(p):",
        "    return _Params(*[float(p[name]) for name in _NAMES])",
        "",
        "",
        "def _vector(x):",
        f"    return (ctypes.c_double * {n})(*[float(e) for e in x])",
        "",
        "",
    ]
    for key, matrix in forms.quantities.items():
        method, args, _ = QUANTITIES[key]
        parameters = [*(["q"] if "q" in args else []), *(["v"] if "v" in args else []), "p"]
        call = [*(["_vector(q)"] if "q" in args else []), *(["_vector(v)"] if "v" in args else [])]
        size = matrix.rows * matrix.cols
        shape = f"({matrix.rows},)" if key in ("Cqdot", "G") else f"({matrix.rows}, {matrix.cols})"
        lines += [
            f"def {key}({', '.join(parameters)}):",
            f"    out = (ctypes.c_double * {size})()",
            f"    _lib.{prefix}_{method}({', '.join([*call, 'ctypes.byref(_params(p))', 'out'])})",
            f"    return numpy.array(out[:], dtype=float).reshape{shape}",
            "",
            "",
        ]
    lines.append(f"DECLARATION = {forms.declaration()!r}")
    return "\n".join(lines) + "\n"
