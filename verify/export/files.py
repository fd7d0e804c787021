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
import importlib.util
from dataclasses import dataclass
from pathlib import Path

from pendverify.atomic import check_output, write_atomic
from pendverify.errors import PendverifyError
from pendverify.export.casadi_code import NOT_INSTALLED, write_casadi
from pendverify.export.closed_forms import ExportForms, export_forms
from pendverify.export.verification import FAILED, Verification, verify
from pendverify.export.writers import write_c, write_matlab, write_numpy
from pendverify.robot.description import is_description_text

#: language → its files' writer (``pendverify.export.writers``, ``pendverify.export.casadi_code``)
WRITERS = {"c": write_c, "matlab": write_matlab, "numpy": write_numpy, "casadi": write_casadi}
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
    forms: ExportForms,
    lang: str,
    params: Path | None,
    certificate: str | None,
    verified: str,
    read_from: str | None = None,
) -> list[str]:
    """The lines every exported file starts with (module docstring)."""
    version = importlib.metadata.version("pendverify")
    source = (
        f"{forms.source} (sha256 {_sha256(forms.source)})"
        if forms.source
        else f"the built-in model {forms.name}"
    )
    option = "--casadi" if lang == "casadi" else f"--lang {lang}"
    lines = [f"The closed forms of model {forms.name}, written by pendverify {version} export {option}."]
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
    elif read_from:
        lines.append(
            f"Parameter set: the one the model reads off {read_from}; the code takes the parameters as p."
        )
    elif forms.default_params:
        lines.append("Parameter set: the model's own defaults; the code takes the parameters as p.")
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
    return _exported(_ExportInput.of(model_cls, urdf, params, certificate, (lang,)), lang, check)


@dataclass(frozen=True)
class _ExportInput:
    """What every language's files of one export are made from: the model's quantities, the robot
    and the parameter set the written code is checked with, and what the banner says of them."""

    forms: ExportForms
    urdf: object
    params: object  # what ``check`` takes: a file, a mapping, or None
    params_path: Path | None
    read_from: str | None
    certificate: str | None

    @classmethod
    def of(cls, model_cls, urdf, params, certificate: str | None, langs: tuple[str, ...]) -> _ExportInput:
        for lang in langs:
            if lang not in WRITERS:
                raise PendverifyError(f"export: --lang {lang!r}: one of {', '.join(LANGUAGES)}")
            if lang == "casadi" and importlib.util.find_spec("casadi") is None:
                raise PendverifyError(f"export --casadi: {NOT_INSTALLED}")
        forms = export_forms(model_cls)
        params_path = Path(params) if isinstance(params, str | Path) else None
        read_from = None
        if urdf is not None:  # the code is checked with the parameter set the model's check takes
            target = _target(model_cls, urdf, params)
            if model_cls.geometry_reader:
                forms = dataclasses.replace(forms, urdf=_joint_map(target.system))
            if params is None and model_cls.default_params is None:
                read_from = _description_name(urdf)
            params = target.model.params.as_dict()
        return cls(forms, urdf, params, params_path, read_from, certificate)


def _exported(given: _ExportInput, lang: str, check) -> tuple[dict[str, str], Verification]:
    head = banner(given.forms, lang, given.params_path, given.certificate, PENDING, given.read_from)
    draft = WRITERS[lang](given.forms, head)
    verification = verify(lang, draft, given.forms, given.urdf, given.params, check)
    # the code verified is the code written: only its banner's last line changes
    done = f"Verification: {verification.line}."
    return {
        name: text.replace(f"Verification: {PENDING}.", done, 1) for name, text in draft.items()
    }, verification


def export_model(
    model_cls, langs: tuple[str, ...], output: Path, check, *, urdf=None, params=None, force: bool = False
) -> tuple[ExportResult, ...]:
    """Write ``model_cls``'s quantities as code of each of ``langs`` into ``output``, each verified
    first (``exported_files``); no file is written when one of them exists and not ``force``."""
    check_output(output, folder=True)
    given = _ExportInput.of(model_cls, urdf, params, None, langs)
    made = [(lang, *_exported(given, lang, check)) for lang in langs]
    existing = sorted(name for _, files, _ in made for name in files if (output / name).exists())
    if existing and not force:
        raise PendverifyError(f"{output / existing[0]}: exists; give --force to replace the exported files")
    output.mkdir(parents=True, exist_ok=True)
    return tuple(
        ExportResult(
            lang, tuple(write_atomic(output / name, text) for name, text in files.items()), verification
        )
        for lang, files, verification in made
    )


def _target(model_cls, urdf, params):
    """The model's target on ``urdf`` as ``check`` makes it: its parameter set is ``params`` (a
    file or a mapping), else the model's ``PARAMS``, else what the model reads off the robot, else
    refused naming what to give (``pendverify.targets.model_target``)."""
    from pendverify.targets import model_target, parameter_values

    return model_target(model_cls, urdf, None if params is None else parameter_values(model_cls, params))


def _joint_map(system) -> dict:
    """The URDF table of a model that reads its coordinate map off the robot's geometry (a reference
    system): the joints, T and θ0 it reads there, which the exported code's declaration states."""
    return {
        "joints": [system.model.names[j] for j in range(1, system.model.njoints)],
        "transform": [[float(x) for x in row] for row in system.cmap.T],
        "offset": [float(x) for x in system.cmap.theta0],
    }


def _description_name(urdf) -> str:
    """The robot description's file for the banner, or what it is when it is not a file (its XML
    text, or a Pinocchio model read)."""
    if isinstance(urdf, str | Path) and not is_description_text(str(urdf)):
        return f"the robot description {urdf}"
    return "the robot description given"
