"""Which model a certificate speaks for: a built-in one by name, or a model file by its source text.

A plug-in model (``--analytic FILE``) is certified *as written*: the certificate
embeds the file's text and its SHA-256, and ``recheck`` loads the class from that
text (written to a private temporary file and imported by
``pendverify.analytic.plugin.load_model_class``, the loader ``check --analytic``
uses), never from whatever file is at the original path now.  A ``ModelSource`` holds
only strings, so it crosses process boundaries (sweeps on local processes or Dask)
and each worker loads the class from the text once.
"""

from __future__ import annotations

import hashlib
import tempfile
from dataclasses import dataclass
from pathlib import Path

from pendverify.analytic import MODELS, ClosedFormModel
from pendverify.analytic.plugin import load_model_class
from pendverify.display import shortened
from pendverify.errors import PendverifyError
from pendverify.numerics.codegen.cache import remember_text

MODEL_SUFFIXES = (".py", ".toml")  # Python source (runs when imported), or a text model (parsed)
MAX_FILE_NAME_BYTES = 255  # what a file system takes as one name
MODEL_FILE_RULE = (
    "a plain file name ending in .py or .toml: no folder, separator or control character, "
    f"at most {MAX_FILE_NAME_BYTES} bytes"
)

#: the files a text model reads beside itself (its ``[matlab]`` files): a relative path of plain
#: names ending in .m, inside the model file's folder
COMPANION_RULE = "a plain file name ending in .m, of a file beside the model file (no folder)"

_LOADED: dict[tuple, type[ClosedFormModel]] = {}  # (file name, sha256s) -> class, per process


def sha256_text(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True)
class ModelSource:
    """A built-in model (``text`` empty) or a model file's name and source text."""

    name: str  # the model's name (the class's ``name``)
    file: str = ""  # the model file's name, for messages and the bundle
    text: str = ""  # the model file's source; "" for a built-in model
    #: the files the model file reads (a declaration's .m files, beside it): (file name, text)
    companions: tuple[tuple[str, str], ...] = ()

    @property
    def builtin(self) -> bool:
        return not self.text

    @property
    def runs_code(self) -> bool:
        """Whether loading it imports Python source (a text model is parsed, never executed)."""
        return not self.builtin and not self.file.endswith(".toml")

    @classmethod
    def of_builtin(cls, name: str) -> ModelSource:
        if name not in MODELS:
            raise PendverifyError(f"unknown model {name!r}; built-in models: {', '.join(MODELS)}")
        return cls(name)

    @classmethod
    def of_file(cls, path: str | Path) -> ModelSource:
        """A model file: loaded (and validated) once here, so a bad file fails before any work."""
        path = Path(path)
        model_cls = load_model_class(path)
        text = path.read_text(encoding="utf-8")
        source = cls(model_cls.name, path.name, text, _companions(model_cls, path))
        _LOADED[source.key] = model_cls
        return source

    @property
    def key(self) -> tuple:
        return (self.file, self.sha256, *(sha256_text(t) for _, t in self.companions))

    @property
    def sha256(self) -> str:
        return sha256_text(self.text)

    def load(self) -> type[ClosedFormModel]:
        """The model class: built in, or imported from the embedded text (once per process)."""
        if self.builtin:
            return MODELS[self.name]
        key = self.key
        if key not in _LOADED:
            _LOADED[key] = load_from_text(self.text, self.file, self.companions)
        model_cls = _LOADED[key]
        if model_cls.name != self.name:
            raise PendverifyError(
                f"{self.file}: the embedded source defines model {model_cls.name!r}, not {self.name!r}"
            )
        return model_cls

    def as_record(self) -> dict:
        """The certificate's ``model_source`` field (plug-ins only)."""
        record = {"file": self.file, "text": self.text, "sha256": self.sha256}
        if self.companions:
            record["companions"] = [
                {"file": f, "text": t, "sha256": sha256_text(t)} for f, t in self.companions
            ]
        return record

    @classmethod
    def from_certificate(cls, cert: dict, source: str) -> ModelSource:
        """The model a certificate names; a plug-in's embedded source must match its recorded SHA-256."""
        record = cert.get("model_source")
        name = cert.get("model")
        if record is None:
            if name not in MODELS:
                raise PendverifyError(
                    f"{source}: key 'model' = {name!r}: not a built-in model, and no model_source is embedded"
                )
            return cls(name)
        problem = source_problem(record)
        if problem:
            raise PendverifyError(f"{source}: {problem}")
        companions = tuple((c["file"], c["text"]) for c in record.get("companions", ()))
        return cls(name, record["file"], record["text"], companions)


def _companions(model_cls, path: Path) -> tuple[tuple[str, str], ...]:
    """The files a text model reads beside itself, as (relative path, text), each checked by
    ``COMPANION_RULE`` (a certificate embeds them, and its bundle writes them beside the model)."""
    matlab = getattr(getattr(model_cls, "text_spec", None), "matlab", None)
    if matlab is None:
        return ()
    # deferred on purpose: the MATLAB reader (SymPy, lark) loads only for a model that used it
    from pendverify.analytic.matlab_parse import read_source

    folder = path.resolve().parent
    out = []
    for file in matlab.files:
        resolved = Path(file).resolve()
        if resolved.parent != folder:
            raise PendverifyError(
                f"{path}: key 'matlab.files': {file} is not beside the model file; a certificate embeds "
                "the model's .m files, and its bundle holds them, beside the model file: move it there"
            )
        out.append((resolved.name, read_source(resolved)))  # decoded as the reader decoded it
    return tuple(out)


def _plain_file_name(name: str, suffixes: tuple[str, ...]) -> bool:
    """Whether ``name`` is one plain file name (no folder, separator or control character, at most
    ``MAX_FILE_NAME_BYTES``) ending in one of ``suffixes`` and not only that suffix."""
    return not (
        name in (".", "..")
        or any(c in "/\\" or ord(c) < 32 or ord(c) == 127 for c in name)
        or len(name.encode("utf-8", "surrogatepass")) > MAX_FILE_NAME_BYTES
        or not name.endswith(suffixes)
        or name in suffixes
    )


def companion_problem(name: str) -> str:
    """Why ``name`` cannot be an embedded companion's name (``COMPANION_RULE``), or ""."""
    return "" if _plain_file_name(name, (".m",)) and name != "..m" else COMPANION_RULE


def model_file_problem(name: str) -> str:
    """Why ``name`` cannot be an embedded model's file name (``MODEL_FILE_RULE``), or ""."""
    return "" if _plain_file_name(name, MODEL_SUFFIXES) else MODEL_FILE_RULE


def source_problem(record) -> str:
    """Why an embedded ``model_source`` record does not hold, or ""."""
    if not isinstance(record, dict) or not all(
        isinstance(record.get(k), str) for k in ("file", "text", "sha256")
    ):
        return "key 'model_source': expected a table of strings file, text and sha256"
    if model_file_problem(record["file"]):
        shown = shortened(record["file"], 60)
        return f"key 'model_source.file' = {shown!r}: expected {MODEL_FILE_RULE}"
    companions = record.get("companions", [])
    if not isinstance(companions, list) or not all(
        isinstance(c, dict)
        and set(c) == {"file", "text", "sha256"}
        and all(isinstance(v, str) for v in c.values())
        for c in companions
    ):
        return "key 'model_source.companions': expected a list of tables of strings file, text and sha256"
    for c in companions:
        if companion_problem(c["file"]):
            return (
                f"key 'model_source.companions' file {shortened(c['file'], 60)!r}: expected {COMPANION_RULE}"
            )
        if sha256_text(c["text"]) != c["sha256"]:
            return (
                f"key 'model_source.companions': the embedded {shortened(c['file'], 60)} does not match its "
                "sha256: the model was edited after it was certified"
            )
    computed = sha256_text(record["text"])
    if computed != record["sha256"]:
        return (
            f"key 'model_source.text': the embedded model source does not match its sha256 "
            f"(recorded {record['sha256']}, computed {computed}): the model was edited after it was certified"
        )
    return ""


def load_from_text(text: str, file_name: str, companions=()) -> type[ClosedFormModel]:
    """Import a model file's source through the plug-in loader, from a private temporary copy (and
    of the files it reads, ``companions``: (file name, text), checked by ``companion_problem``)."""
    name = Path(file_name).name or "model.py"
    with tempfile.TemporaryDirectory(prefix="pendverify-model-") as tmp:
        path = Path(tmp) / name
        path.write_text(text, encoding="utf-8")
        remember_text(path, text)  # the generated code's key outlives the temporary copy
        for companion_name, companion in companions:
            if companion_problem(companion_name):
                raise PendverifyError(
                    f"{name} (the embedded model source): {companion_name!r}: {COMPANION_RULE}"
                )
            target = Path(tmp) / companion_name
            target.write_text(companion, encoding="utf-8")
            remember_text(target, companion)
        try:
            return load_model_class(path)
        except PendverifyError as exc:
            raise PendverifyError(f"{name} (the embedded model source): {exc}") from None
