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

With ``--resume --key KEY`` a certificate is kept only if it is signed by that key
(its ``signature.keyid`` is the key's fingerprint, its envelope verifies with the key
and records the certificate file's SHA-256); an unsigned certificate, or one signed by
another key, is recomputed and signed, and ``OutputState.resigned`` names those sets so
that the command says how many.
"""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from pendverify.certify.bundle import verify_signed_by
from pendverify.certify.certificate import verify_digest
from pendverify.certify.reading import read_certificate
from pendverify.errors import CertificateError, FileAccessError, InputError, SigningError

BUNDLE_SUFFIXES = (".cert.json", ".urdf", ".mjcf.xml", ".sdf", ".params.toml", ".model.py", ".model.toml")
TEMPORARY = re.compile(r"^\.(?P<file>.+)\.[a-z0-9_]+\.tmp$")  # pendverify.atomic's temporaries


@dataclass
class OutputState:
    done: set[str] = field(default_factory=set)  # sets whose valid certificate is there: skipped
    partial: set[str] = field(default_factory=set)  # sets with part of a bundle: recomputed, replaced
    resigned: set[str] = field(default_factory=set)  # of partial: certified, but not signed by --key


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


def prepare_output(sweep, output, force: bool, resume: bool, key=None) -> OutputState:
    """Check the folder and the bundles already in it (module docstring); ``key``: the
    private key the sweep signs with, or None."""
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
            path = out / f"{name}.cert.json"
            try:
                data, cert = _validate(path, sweep, name, params_type.from_mapping(values).as_dict())
            except CertificateError:
                if not force:
                    raise
                state.partial.add(name)
                continue
            if key is not None and not signed_by(path, data, cert, key):
                state.partial.add(name)
                state.resigned.add(name)
                continue
            state.done.add(name)
        elif any(name + suffix in files for suffix in BUNDLE_SUFFIXES):
            state.partial.add(name)
    return state


class SameFolder:
    """The output folder a sweep writes to, which must stay the one it started writing to.

    ``check()`` before each bundle raises FileAccessError once the folder was removed or
    replaced (the atomic writer would make a new, empty one: the sweep would then count
    certificates that are no longer anywhere); ``wrote()`` after it records the folder
    the first bundle created."""

    def __init__(self, output):
        self.path = Path(output)
        self.identity = self._now()

    def _now(self):
        try:
            st = os.stat(self.path)
        except OSError:
            return None
        return st.st_dev, st.st_ino

    def check(self) -> None:
        if self.identity is not None and self._now() != self.identity:
            raise FileAccessError(
                str(self.path),
                "write",
                "the folder was removed or replaced during the sweep; the sweep stopped "
                "(what is left there is kept: continue with --resume)",
            )

    def wrote(self) -> None:
        if self.identity is None:
            self.identity = self._now()


def certificates_in(sweep, output) -> int:
    """How many of the sweep's sets have a certificate in ``output`` now."""
    try:
        files = set(os.listdir(output))
    except OSError:
        return 0
    return sum(f"{name}.cert.json" in files for name, _ in sweep.sets)


def _remove_temporaries(out: Path, files: set[str], names: set[str]) -> None:
    bundles = {name + suffix for name in names for suffix in BUNDLE_SUFFIXES}
    for file in files:
        match = TEMPORARY.match(file)
        if match and match["file"] in bundles:
            (out / file).unlink(missing_ok=True)


def signed_by(path: Path, data: bytes, cert: dict, key) -> bool:
    """Whether the certificate ``cert`` (``data``, read from ``path``) is signed by ``key`` (a
    private key), by the rule ``recheck --trust`` applies (``bundle.verify_signed_by``)."""
    try:
        verify_signed_by(path, cert, key.public_key(), data, "--key")
    except (SigningError, CertificateError):
        return False
    return True


def _validate(path: Path, sweep, name: str, parameters: dict) -> tuple[bytes, dict]:
    """``path``'s bytes and certificate (read bounded: ``reading.read_certificate``);
    CertificateError unless it is an intact certificate of this sweep's set ``name``."""
    hint = "; remove it, or pass --force to recompute that set"
    try:
        data, cert = read_certificate(path)
    except CertificateError as exc:
        raise CertificateError(f"{exc}{hint}") from None
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
    return data, cert
