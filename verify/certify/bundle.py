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
from pendverify.certify.model_source import MODEL_SUFFIXES
from pendverify.certify.names import envelope_name, target_inside
from pendverify.certify.reading import MAX_CERTIFICATE_BYTES, read_limited
from pendverify.certify.signing import (
    MAX_ENVELOPE_BYTES,
    envelope_line,
    fingerprint,
    load_public_key,
    open_envelope,
    sha256_bytes,
    statement,
    statement_subjects,
)
from pendverify.display import shortened
from pendverify.errors import CertificateError, PendverifyError, SigningError
from pendverify.export.names import export_file_names
from pendverify.robot.description import FILE_SUFFIXES, text_suffix


def bundle_paths(directory, name: str, description_suffix: str = ".urdf") -> tuple[Path, Path, Path]:
    """NAME.urdf (or NAME.mjcf.xml, ...: ``description_suffix``), NAME.params.toml, NAME.cert.json."""
    d = Path(directory)
    return d / f"{name}{description_suffix}", d / f"{name}.params.toml", d / f"{name}.cert.json"


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
    *,
    description_format: str,
    extra_files: dict[str, str] | None = None,
) -> Path:
    """Write the bundle (``key``, an Ed25519 private key, signs it: NAME.intoto.jsonl), the
    certificate last.  An existing bundle is never replaced unless ``force``.
    ``description_format``: the format of ``urdf`` as its reading found it
    (``BatteryRun.description_format``), which gives its file's suffix."""
    refuse_existing(directory, name, force)
    Path(directory).mkdir(parents=True, exist_ok=True)
    suffix = FILE_SUFFIXES[description_format]
    urdf_path, params_path, cert_path = bundle_paths(directory, name, suffix)
    files = {urdf_path: urdf, params_path: params.to_toml(name)}
    if model is not None and not model.builtin:
        files[model_path(directory, name, model.file)] = model.text
        for relative, text in model.companions:  # the files it reads, where it reads them
            files[Path(directory) / relative] = text
    for file_name, text in (extra_files or {}).items():  # the model's code (certify --export)
        path = Path(directory) / file_name
        if path.exists() and not force:
            raise CertificateError(f"{path} exists; pass --force to replace it")
        files[path] = text
    text = certificate_text(cert)
    if key is not None:
        contents = {
            Path(p).relative_to(directory).as_posix(): t.encode()
            for p, t in {**files, cert_path: text}.items()
        }
        configuration = {"schema": cert["schema"], "model": cert["model"], **cert["settings"]}
        files[envelope_path(directory, name)] = envelope_line(
            statement(contents, cert["checks"], configuration), key
        )
    for path, data in {**files, cert_path: text}.items():
        write_atomic(target_inside(directory, path), data)
    return cert_path


def bundle_file_names(name: str, cert: dict | None = None) -> set[str]:
    """Every file name set ``name``'s bundle may hold besides its envelope (what a signed statement
    may name as subjects): with the certificate ``cert``, the files its model reads too (a
    declaration's .m files, by their paths relative to the bundle)."""
    record = (cert or {}).get("model_source") or {}
    companions = {c["file"] for c in record.get("companions", ())}
    if cert is not None and isinstance(cert.get("model"), str):
        companions |= export_file_names(cert["model"])  # certify --export's files
    descriptions = {f"{name}{suffix}" for suffix in FILE_SUFFIXES.values()}
    models = {model_path(".", name, f"model{suffix}").name for suffix in MODEL_SUFFIXES}
    return {*descriptions, *models, *companions, *(p.name for p in bundle_paths(".", name))}


def check_files_beside(cert_path: str | Path, cert: dict) -> None:
    """Refuse a bundle whose description or model file beside ``NAME.cert.json`` is not the text the
    certificate embeds (a file not copied along is fine).  A certificate file under another name
    than its set's is not in a bundle: nothing beside it is compared."""
    cert_path = Path(cert_path)
    name = cert["name"]
    if cert_path.name != bundle_paths(".", name)[2].name:
        return
    try:
        suffix = text_suffix(cert["urdf"]["text"])
    except PendverifyError:
        suffix = None  # not a description at all: the battery's re-run says so
    embedded = {f"{name}{suffix}": cert["urdf"]["text"]} if suffix else {}
    record = cert.get("model_source")
    if record is not None:
        embedded[model_path(".", name, record["file"]).name] = record["text"]
        embedded.update({c["file"]: c["text"] for c in record.get("companions", ())})
    for file_name, text in embedded.items():
        path = cert_path.parent / file_name
        if not path.is_file():
            continue
        data = read_limited(path, MAX_CERTIFICATE_BYTES, "bundle file", CertificateError)
        if sha256_bytes(data) != sha256_bytes(text.encode()):
            raise CertificateError(
                f"{path}: not the text {cert_path.name} embeds (sha256 {sha256_bytes(data)}, embedded "
                f"{sha256_bytes(text.encode())}): the bundle's file was replaced or edited"
            )


def verify_signature(cert_path: str | Path, cert: dict, trust: str | Path, data: bytes) -> str:
    """Check a certificate against the key in ``trust`` (a public-key PEM); return a line saying so
    (``verify_signed_by``)."""
    return verify_signed_by(cert_path, cert, load_public_key(trust), data, str(trust))


def verify_signed_by(cert_path: str | Path, cert: dict, trusted, data: bytes, key_name: str) -> str:
    """Check a certificate against the public key ``trusted`` (named ``key_name`` in messages);
    return a line saying so.

    ``data`` is the certificate file's bytes as read (and parsed into ``cert``).  The file
    must be its set's ``NAME.cert.json`` and name its envelope ``NAME.intoto.jsonl``; the
    envelope must be signed by the trusted key; its statement (shape checked:
    ``signing.statement_subjects``) must name only files of set NAME's bundle and record
    ``data``'s SHA-256 for NAME.cert.json and the SHA-256 of every other subject present
    beside it.  Anything else raises SigningError, saying why.
    """
    cert_path = Path(cert_path)
    signature = cert.get("signature")
    if signature is None:
        raise SigningError(
            f"{cert_path}: unsigned: it names no envelope (it was issued without --key), and --trust "
            f"accepts only a certificate signed by the trusted key {fingerprint(trusted)}; rejected"
        )
    name = cert["name"]
    own = bundle_paths(".", name)[2].name  # NAME.cert.json
    if cert_path.name != own:
        raise SigningError(
            f"{cert_path}: holds the certificate of set {name!r} (its file is {own}), not of the set "
            f"this file names; a bundle's NAME.cert.json must hold set NAME's certificate; rejected"
        )
    if signature["envelope"] != envelope_name(name):
        raise SigningError(
            f"{cert_path}: key 'signature.envelope' = {shortened(signature['envelope'], 80)!r}: "
            f"set {name!r}'s envelope is {envelope_name(name)}; rejected"
        )
    envelope = cert_path.parent / signature["envelope"]
    text = read_limited(envelope, MAX_ENVELOPE_BYTES, "envelope (NAME.intoto.jsonl)", SigningError)
    lines = [line for line in text.decode("utf-8", "replace").splitlines() if line.strip()]
    if len(lines) != 1:
        raise SigningError(f"{envelope}: expected one DSSE envelope (one line), found {len(lines)}")
    stmt = open_envelope(lines[0], trusted, str(envelope), key_name)
    subjects = statement_subjects(stmt, str(envelope))
    if own not in subjects:
        raise SigningError(f"{envelope}: the signed statement does not name {own}; rejected")
    foreign = sorted(set(subjects) - bundle_file_names(name, cert))
    if foreign:
        raise SigningError(
            f"{envelope}: the signed statement names {shortened(foreign[0], 80)!r}, not a file of set "
            f"{name!r}'s bundle; rejected"
        )
    for subject, recorded in sorted(subjects.items()):
        path = cert_path.parent / subject
        if subject == own:
            computed = sha256_bytes(data)
        elif path.is_file():
            computed = sha256_bytes(read_limited(path, MAX_CERTIFICATE_BYTES, "bundle file", SigningError))
        else:
            continue  # a bundle file not copied along: the certificate embeds what recheck needs
        if computed != recorded:
            raise SigningError(
                f"{path}: sha256 {computed}, but the signed statement records {recorded} for {subject}: "
                "the file was edited after it was signed; rejected"
            )
    return f"signature ok: signed by the trusted key {fingerprint(trusted)} ({envelope.name})"
