"""A certificate bundle on disk: which files, written how.

``DIR/NAME.urdf`` (the verified description: ``NAME.mjcf.xml`` for an MJCF; a xacro file's is the
URDF it expanded to), ``DIR/NAME.params.toml``, ``DIR/NAME.model.py`` or ``.model.toml`` (a model file's
bundle), ``DIR/NAME.intoto.jsonl`` (a signed certificate's DSSE envelope) and, last,
``DIR/NAME.cert.json``, each written atomically (``pendverify.atomic``).  The
certificate is written last, so an interruption never leaves a certificate without
its files.  Every target is resolved (symbolic links included) and must lie directly
inside the resolved output folder (``pendverify.certify.names.target_inside``).
"""

from __future__ import annotations

from pathlib import Path

from pendverify.analytic import ParameterSet
from pendverify.atomic import write_atomic
from pendverify.certify.certificate import certificate_text
from pendverify.certify.names import envelope_name, target_inside
from pendverify.certify.signing import (
    envelope_line,
    fingerprint,
    load_public_key,
    open_envelope,
    sha256_bytes,
    statement,
)
from pendverify.errors import CertificateError, SigningError
from pendverify.robot.description import FILE_SUFFIXES, text_suffix


def bundle_paths(directory, name: str, description_suffix: str = ".urdf") -> tuple[Path, Path, Path]:
    """NAME.urdf (or NAME.mjcf.xml, ...: ``description_suffix``), NAME.params.toml, NAME.cert.json."""
    d = Path(directory)
    return d / f"{name}{description_suffix}", d / f"{name}.params.toml", d / f"{name}.cert.json"


MODEL_SUFFIXES = (".py", ".toml")  # a Python model file, or a text one


def model_path(directory, name: str, file: str = "model.py") -> Path:
    """Where a plug-in's bundle keeps a copy of the certified model file: NAME.model.py, or
    NAME.model.toml for a text model (``file``: the model file's name)."""
    suffix = ".toml" if str(file).endswith(".toml") else ".py"
    return Path(directory) / f"{name}.model{suffix}"


def envelope_path(directory, name: str) -> Path:
    return Path(directory) / envelope_name(name)


def refuse_existing(directory, name: str, force: bool) -> None:
    """Raise unless ``force`` when any file of the bundle already exists; refuse a target
    outside the output folder whatever ``force`` says."""
    models = (model_path(directory, name, f"model{suffix}") for suffix in MODEL_SUFFIXES)
    descriptions = (Path(directory) / f"{name}{suffix}" for suffix in sorted(set(FILE_SUFFIXES.values())))
    extra = (*models, *descriptions, envelope_path(directory, name))
    paths = (*reversed(bundle_paths(directory, name)), *extra)
    if Path(directory).exists():
        for path in paths:
            target_inside(directory, path)
    if force:
        return
    for path in paths:
        if path.exists() or path.is_symlink():
            raise CertificateError(f"{path} exists; pass --force to replace it")


def write_bundle(
    directory,
    name: str,
    params: ParameterSet,
    urdf: str,
    cert: dict,
    force: bool = False,
    model=None,
    key=None,
) -> Path:
    """Write the bundle (``key``, an Ed25519 private key, signs it: NAME.intoto.jsonl), the
    certificate last.  An existing bundle is never replaced unless ``force``."""
    refuse_existing(directory, name, force)
    Path(directory).mkdir(parents=True, exist_ok=True)
    urdf_path, params_path, cert_path = bundle_paths(directory, name, text_suffix(urdf))
    files = {urdf_path: urdf, params_path: params.to_toml(name)}
    if model is not None and not model.builtin:
        files[model_path(directory, name, model.file)] = model.text
    text = certificate_text(cert)
    if key is not None:
        contents = {p.name: t.encode() for p, t in {**files, cert_path: text}.items()}
        configuration = {"schema": cert["schema"], "model": cert["model"], **cert["settings"]}
        files[envelope_path(directory, name)] = envelope_line(
            statement(contents, cert["checks"], configuration), key
        )
    for path, data in {**files, cert_path: text}.items():
        write_atomic(target_inside(directory, path), data)
    return cert_path


def verify_signature(cert_path: str | Path, cert: dict, trust: str | Path) -> str:
    """Check a certificate against the key in ``trust`` (a public-key PEM); return a line saying so.

    The certificate must name its envelope; the envelope must be signed by the trusted
    key and its statement must record this certificate file's SHA-256 (and of every
    other subject present beside it).  Anything else raises SigningError, saying why.
    """
    cert_path = Path(cert_path)
    trusted = load_public_key(trust)
    signature = cert.get("signature")
    if signature is None:
        raise SigningError(
            f"{cert_path}: unsigned: it names no envelope (it was issued without --key), and --trust "
            f"accepts only a certificate signed by the trusted key {fingerprint(trusted)}; rejected"
        )
    envelope = cert_path.parent / signature["envelope"]
    try:
        text = envelope.read_text(encoding="utf-8")
    except OSError as exc:
        raise SigningError(
            f"{cert_path}: its envelope {envelope} cannot be read ({exc.strerror or exc}); rejected"
        ) from None
    lines = [line for line in text.splitlines() if line.strip()]
    if len(lines) != 1:
        raise SigningError(f"{envelope}: expected one DSSE envelope (one line), found {len(lines)}")
    stmt = open_envelope(lines[0], trusted, str(envelope), str(trust))
    subjects = {s.get("name"): s.get("digest", {}).get("sha256") for s in stmt.get("subject", [])}
    own = f"{cert['name']}.cert.json"  # the certificate's subject, whatever the file is called now
    if own not in subjects:
        raise SigningError(f"{envelope}: the signed statement does not name {own}; rejected")
    for name, recorded in subjects.items():
        path = cert_path if name == own else cert_path.parent / name
        if not path.is_file():
            continue  # a bundle file not copied along: the certificate embeds what recheck needs
        computed = sha256_bytes(path.read_bytes())
        if computed != recorded:
            raise SigningError(
                f"{path}: sha256 {computed}, but the signed statement records {recorded} for {name}: "
                "the file was edited after it was signed; rejected"
            )
    return f"signature ok: signed by the trusted key {fingerprint(trusted)} ({envelope.name})"
