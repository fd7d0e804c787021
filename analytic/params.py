"""Parameter files: a model's parameter set (``pendverify.analytic.parameter_set``) in TOML.

A parameter file looks like::

    model = "double_pendulum"
    name = "default"            # optional
    [parameters]
    m1 = 1.0
    ...

Unknown and missing keys are errors, as are booleans, strings and non-finite
numbers.  Every error names the file, the key, the value and the rule.

``ParameterSet``, ``quantity`` and ``check_value`` live in ``pendverify.analytic.parameter_set``
(a model file imports the first two as ``from pendverify import ParameterSet, quantity``); reached
through this module they still work, with a ``DeprecationWarning`` naming their home.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pendverify.errors import ParameterError, folder_given, missing_file, unreadable_file, wrong_kind
from pendverify.file_kinds import KINDS, expect_kind, suffix_kind

if TYPE_CHECKING:
    from pendverify.analytic.parameter_set import ParameterSet

#: the names that moved to ``pendverify.analytic.parameter_set``, each with the import to use now
MOVED = {
    "ParameterSet": "from pendverify import ParameterSet",
    "quantity": "from pendverify import quantity",
    "check_value": "from pendverify.analytic.parameter_set import check_value",
}

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib


def read_toml(path: Path, what: str = "TOML file") -> dict[str, Any]:
    """Parse a TOML file (a ``what``: "parameter file", "scene file", ... in messages).

    A missing, unreadable or folder path is a ``UserFileError`` naming the file and the next
    step, as is a file whose name says it is another kind (``model.py``, ``robot.urdf``); a
    syntax error, a ParameterError that names the file."""
    if not path.name.lower().endswith(".toml"):
        kind = suffix_kind(path)
        if kind is not None:
            raise wrong_kind(path, what, KINDS[kind].noun, KINDS[kind].given_as)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except FileNotFoundError:
        raise missing_file(path, what) from None
    except IsADirectoryError:
        raise folder_given(path, what) from None
    except OSError as exc:
        raise unreadable_file(path, what, exc.strerror or str(exc)) from None
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark is allowed, as in URDFs
    except UnicodeDecodeError as exc:
        raise ParameterError(
            str(path), "<file>", str(path), f"not UTF-8 text (byte {exc.start}: {exc.reason}); TOML is UTF-8"
        ) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(str(path), "<file>", str(path), f"not valid TOML: {exc}") from None
    except RecursionError:
        raise ParameterError(str(path), "<file>", str(path), "not valid TOML: nested too deeply") from None


def parse_parameter_document(data: dict[str, Any], source: str, registry: dict[str, type[ParameterSet]]):
    """Split a parameter document into (model name, set name, parameter set)."""
    allowed = {"model", "name", "parameters"}
    for key, value in data.items():
        if key not in allowed:
            raise ParameterError(
                source,
                key,
                value,
                f"unknown key; a parameter file has {', '.join(sorted(allowed))}",
            )
    model = data.get("model")
    if model not in registry:
        raise ParameterError(
            source,
            "model",
            model,
            f"must be one of {', '.join(registry)}; the parameters of a model file of your own go with "
            "that file (--analytic FILE)",
        )
    name = data.get("name", Path(source).stem if source != "<inline>" else model)
    if not isinstance(name, str):
        raise ParameterError(source, "name", name, "must be a string")
    table = data.get("parameters")
    if not isinstance(table, dict):
        raise ParameterError(source, "parameters", table, "must be a table of parameter values")
    return model, name, registry[model].from_mapping(table, source, prefix="parameters.")


def load_parameter_file(path: str | Path, registry: dict[str, type[ParameterSet]] | None = None):
    """Read a parameter file: returns (model name, set name, validated parameter set)."""
    if registry is None:  # the built-in models' registry; pendverify.analytic imports this module
        from pendverify.analytic import PARAMETER_TYPES as registry
    path = Path(path)
    return parse_parameter_document(read_parameter_toml(path), str(path), registry)


def read_parameter_toml(path: Path) -> dict[str, Any]:
    """A parameter file's TOML document; another kind of file (a text model, a scene) is refused
    with what it is and how to give it (``pendverify.file_kinds``)."""
    data = read_toml(path, "parameter file")
    expect_kind(data, path, "params")
    return data


def default_parameter_file(model: str) -> Path:
    """The shipped default parameter file of a model."""
    from importlib.resources import files

    return Path(str(files("pendverify.analytic") / "params" / f"{model}.toml"))


def __getattr__(name: str) -> Any:
    """A name that moved to ``pendverify.analytic.parameter_set``, with a ``DeprecationWarning``."""
    if name not in MOVED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    warnings.warn(
        f"pendverify.analytic.params.{name} moved to pendverify.analytic.parameter_set.{name}; "
        f"import it as `{MOVED[name]}`",
        DeprecationWarning,
        stacklevel=2,
    )
    from pendverify.analytic import parameter_set

    return getattr(parameter_set, name)
