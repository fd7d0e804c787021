"""Parameter files: a model's parameter set (``pendverify.analytic.parameter_set``) in TOML.

A parameter file looks like::

    model = "double_pendulum"
    name = "default"            # optional
    [parameters]
    m1 = 1.0
    ...

Unknown and missing keys are errors, as are booleans, strings and non-finite
numbers.  Every error names the file, the key, the value and the rule.  The file is read, and
its top level checked, by ``pendverify.documents`` (``document_schema``).

``ParameterSet``, ``quantity`` and ``check_value`` live in ``pendverify.analytic.parameter_set``
(a model file imports the first two as ``from pendverify import ParameterSet, quantity``); reached
through this module they still work, with a ``DeprecationWarning`` naming their home.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pendverify.documents import Key, Table, check_table, is_string, is_table, raising, read_toml
from pendverify.errors import ParameterError
from pendverify.file_kinds import expect_kind

if TYPE_CHECKING:
    from pendverify.analytic.parameter_set import ParameterSet

#: the names that moved to ``pendverify.analytic.parameter_set``, each with the import to use now
MOVED = {
    "ParameterSet": "from pendverify import ParameterSet",
    "quantity": "from pendverify import quantity",
    "check_value": "from pendverify.analytic.parameter_set import check_value",
}


def document_schema(registry: dict[str, type[ParameterSet]]) -> Table:
    """A parameter file's top level: ``model`` one of ``registry``, ``name`` a string, ``parameters``
    a table (whose values ``ParameterSet.from_mapping`` checks)."""
    model_rule = (
        f"must be one of {', '.join(registry)}; the parameters of a model file of your own go with "
        "that file (--analytic FILE)"
    )
    return Table(
        {
            "model": Key(((lambda v: isinstance(v, str) and v in registry, model_rule),)),
            "name": Key(((is_string, "must be a string"),), required=False),
            "parameters": Key(((is_table, "must be a table of parameter values"),)),
        },
        unknown="unknown key; a parameter file has {keys}",
        missing="{rule}",
    )


def parse_parameter_document(data: dict[str, Any], source: str, registry: dict[str, type[ParameterSet]]):
    """Split a parameter document into (model name, set name, parameter set)."""
    values = check_table(data, document_schema(registry), raising(ParameterError, source))
    model = values["model"]
    name = values.get("name", Path(source).stem if source != "<inline>" else model)
    return model, name, registry[model].from_mapping(values["parameters"], source, prefix="parameters.")


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
