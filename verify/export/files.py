"""``export``'s files: the banner every file starts with, and the files written into the output folder.

The banner names what the code is of (the model file and its SHA-256, the parameter set and its
SHA-256, the certificate's digest when ``certify`` exports) and how it was verified
(``pendverify.export.verification``).  The code is written only after it was verified, with the
verification's line in its banner; a file is never half written (``write_atomic``) and never
written outside the output folder.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.metadata
from dataclasses import dataclass
from pathlib import Path

from pendverify.atomic import check_output, write_atomic
from pendverify.errors import PendverifyError
from pendverify.export.closed_forms import ExportForms, export_forms
from pendverify.export.verification import FAILED, Verification, verify
from pendverify.export.writers import WRITERS

LANGUAGES = tuple(WRITERS)
#: the verification line of the draft that is verified, replaced by the outcome's line
PENDING = "(being verified)"


@dataclass(frozen=True)
class ExportResult:
    """The files ``export`` wrote and how their code was verified."""

    lang: str
    files: tuple[Path, ...]
    verification: Verification

    @property
    def failed(self) -> bool:
        return self.verification.status == FAILED


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def banner(
    forms: ExportForms, lang: str, params: Path | None, certificate: str | None, verified: str
) -> list[str]:
    """The lines every exported file starts with (module docstring)."""
    version = importlib.metadata.version("pendverify")
    source = (
        f"{forms.source} (sha256 {_sha256(forms.source)})"
        if forms.source
        else f"the built-in model {forms.name}"
    )
    lines = [f"The closed forms of model {forms.name}, written by pendverify {version} export --lang {lang}."]
    lines.append(f"Model: {source}.")
    if forms.companions:
        read = ", ".join(f"{path.name} (sha256 {_sha256(path)})" for path in forms.companions)
        lines.append(f"Its .m files: {read}.")
    if params is not None:
        lines.append(
            f"Parameter set: {params} (sha256 {_sha256(params)}); the code takes the parameters as p."
        )
    elif certificate:
        lines.append("Parameter set: the certificate's; the code takes the parameters as p.")
    else:
        lines.append("Parameter set: none; the code takes the parameters as p.")
    if certificate:
        lines.append(f"Certificate: sha256 {certificate}.")
    lines.append(f"Verification: {verified}.")
    return lines


def exported_files(
    model_cls, lang: str, check, *, urdf=None, params=None, certificate: str | None = None
) -> tuple[dict[str, str], Verification]:
    """The files of ``model_cls``'s quantities in ``lang`` (name → text), verified by ``check``
    (``pendverify.api.check``, given by the caller: the library does not import the API), the
    verification's line in their banner."""
    if lang not in WRITERS:
        raise PendverifyError(f"export: --lang {lang!r}: one of {', '.join(LANGUAGES)}")
    forms = export_forms(model_cls)
    if urdf is not None and model_cls.geometry_reader:
        forms = dataclasses.replace(forms, urdf=_read_map(model_cls, urdf))
    params_path = Path(params) if isinstance(params, str | Path) else None
    draft = WRITERS[lang](forms, banner(forms, lang, params_path, certificate, PENDING))
    verification = verify(lang, draft, forms, urdf, params, check)
    # the code verified is the code written: only its banner's last line changes
    done = f"Verification: {verification.line}."
    return {
        name: text.replace(f"Verification: {PENDING}.", done, 1) for name, text in draft.items()
    }, verification


def export_model(
    model_cls, lang: str, output: Path, check, *, urdf=None, params=None, force: bool = False
) -> ExportResult:
    """Write ``model_cls``'s quantities as ``lang`` code into ``output``, verified first
    (``exported_files``)."""
    check_output(output, folder=True)
    files, verification = exported_files(model_cls, lang, check, urdf=urdf, params=params)
    existing = sorted(name for name in files if (output / name).exists())
    if existing and not force:
        raise PendverifyError(f"{output / existing[0]}: exists; give --force to replace the exported files")
    output.mkdir(parents=True, exist_ok=True)
    written = tuple(write_atomic(output / name, text) for name, text in files.items())
    return ExportResult(lang, written, verification)


def _read_map(model_cls, urdf) -> dict:
    """The URDF table of a model that reads its coordinate map off the robot's geometry (a reference
    system): the joints, T and θ0 it reads there, which the exported code's declaration states."""
    from pendverify.robot.system import PinocchioSystem

    system = PinocchioSystem.for_model(model_cls, urdf)
    joints = [system.model.names[j] for j in range(1, system.model.njoints)]
    return {
        "joints": joints,
        "transform": [[float(x) for x in row] for row in system.cmap.T],
        "offset": [float(x) for x in system.cmap.theta0],
    }
