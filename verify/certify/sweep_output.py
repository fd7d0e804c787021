"""A sweep's output folder, checked before any set is computed, and what ``--resume`` skips.

``prepare_output`` refuses, in one line and before any work, an output folder
that cannot be written (a missing parent, a file in its place, no write
permission) and — without ``--force`` or ``--resume`` — any file of any set's
bundle already there.  With ``--resume`` a set whose certificate is there is
skipped once the certificate's digest, name, model, parameters and settings are
found to be this sweep's (anything else is refused, or recomputed with
``--force``); a set with only part of its bundle (no certificate: it is written
last) is recomputed and its files replaced; temporaries that a killed writer
left beside the sweep's bundles are removed.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from pendverify.certify.certificate import verify_digest
from pendverify.errors import CertificateError, InputError

BUNDLE_SUFFIXES = (".cert.json", ".urdf", ".mjcf.xml", ".sdf", ".params.toml", ".model.py", ".model.toml")
TEMPORARY = re.compile(r"^\.(?P<file>.+)\.[a-z0-9_]+\.tmp$")  # pendverify.atomic's temporaries


@dataclass
class OutputState:
    done: set[str] = field(default_factory=set)  # sets whose valid certificate is there: skipped
    partial: set[str] = field(default_factory=set)  # sets with part of a bundle: recomputed, replaced


def check_output_folder(output) -> Path:
    """The output folder, refused in one line unless it is (or can be made as) a writable folder."""
    out = Path(output)

    def refuse(rule: str):
        return InputError("<command line>", "output", str(out), rule)

    if out.exists() and not out.is_dir():
        raise refuse("exists and is not a folder")
    if not out.exists() and not out.parent.is_dir():
        raise refuse(f"its parent folder {out.parent} does not exist")
    try:
        fd, probe = tempfile.mkstemp(prefix=".pendverify-probe.", dir=out if out.is_dir() else out.parent)
    except OSError as exc:
        raise refuse(f"cannot write there: {exc.strerror}") from None
    os.close(fd)
    os.unlink(probe)
    return out


def prepare_output(sweep, output, force: bool, resume: bool) -> OutputState:
    """Check the folder and the bundles already in it (module docstring)."""
    out = check_output_folder(output)
    files = set(os.listdir(out)) if out.is_dir() else set()
    state = OutputState()
    if not files or (force and not resume):
        return state
    if not resume:
        for name, _ in sweep.sets:
            for suffix in BUNDLE_SUFFIXES:
                if name + suffix in files:
                    raise CertificateError(
                        f"{out / (name + suffix)} exists; pass --resume to continue the sweep "
                        "or --force to replace it"
                    )
        return state
    _remove_temporaries(out, files, {name for name, _ in sweep.sets})
    params_type = sweep.model.load().params_type
    for name, values in sweep.sets:
        if name + ".cert.json" in files:
            try:
                _validate(out / f"{name}.cert.json", sweep, name, params_type.from_mapping(values).as_dict())
            except CertificateError:
                if not force:
                    raise
                state.partial.add(name)
                continue
            state.done.add(name)
        elif any(name + suffix in files for suffix in BUNDLE_SUFFIXES):
            state.partial.add(name)
    return state


def _remove_temporaries(out: Path, files: set[str], names: set[str]) -> None:
    bundles = {name + suffix for name in names for suffix in BUNDLE_SUFFIXES}
    for file in files:
        match = TEMPORARY.match(file)
        if match and match["file"] in bundles:
            (out / file).unlink(missing_ok=True)


def _validate(path: Path, sweep, name: str, parameters: dict) -> None:
    """Raise CertificateError unless ``path`` is an intact certificate of this sweep's set ``name``."""
    hint = "; remove it, or pass --force to recompute that set"
    try:
        cert = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CertificateError(f"{path}: not a readable certificate: {exc}{hint}") from None
    if not isinstance(cert, dict):
        raise CertificateError(f"{path}: not a certificate{hint}")
    try:
        verify_digest(cert, str(path))
    except CertificateError as exc:
        raise CertificateError(f"{exc}{hint}") from None
    expected = {
        "name": name,
        "model": sweep.model.name,
        "parameters": parameters,
        "settings": sweep.settings.as_dict(),
    }
    for key, value in expected.items():
        if cert.get(key) != value:
            raise CertificateError(f"{path}: its {key} {cert.get(key)!r} is not this sweep's {value!r}{hint}")
