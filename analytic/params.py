"""Parameter sets: frozen dataclasses, validated at construction, loaded from TOML.

Each model declares its parameters as dataclass fields whose metadata names the
*kind* of quantity.  The kind fixes the unit and the rule a value must satisfy:

========  ===========================  =========
kind      rule                         unit
========  ===========================  =========
mass      finite and > 0               kg
length    finite and > 0               m
offset    finite and >= 0              m
inertia   finite and >= 0              kg·m²
damping   finite and >= 0              N·m·s/rad (revolute), N·s/m (prismatic)
gravity   finite and >= 0              m/s²
========  ===========================  =========

A parameter file looks like::

    model = "double_pendulum"
    name = "default"            # optional
    [parameters]
    m1 = 1.0
    ...

Unknown and missing keys are errors, as are booleans, strings and non-finite
numbers.  Every error names the file, the key, the value and the rule.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import Any, ClassVar, TypeVar

from pendverify.errors import FileAccessError, ParameterError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

_RULES: dict[str, tuple[str, str]] = {
    # kind: (comparison, unit)
    "mass": ("> 0", "kg"),
    "length": ("> 0", "m"),
    "offset": (">= 0", "m"),
    "inertia": (">= 0", "kg·m²"),
    "damping": (">= 0", "N·m·s/rad or N·s/m"),
    "gravity": (">= 0", "m/s²"),
}


def quantity(kind: str, doc: str) -> Any:
    """A dataclass field holding one physical quantity of the given kind."""
    if kind not in _RULES:
        raise ValueError(f"unknown quantity kind {kind!r}")
    return dataclasses.field(metadata={"kind": kind, "doc": doc})


def _rule_text(kind: str) -> str:
    comparison, unit = _RULES[kind]
    article = "an" if kind[0] in "aeiou" else "a"
    return f"{article} {kind} must be a finite number {comparison} (in {unit})"


def check_value(source: str, key: str, value: object, kind: str) -> float:
    """Return ``value`` as a float, or raise a ParameterError naming the rule."""
    rule = _rule_text(kind)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(source, key, value, rule + f"; got a {type(value).__name__}")
    try:
        x = float(value)
    except OverflowError:  # a TOML integer beyond a double
        x = math.inf
    if not math.isfinite(x):
        raise ParameterError(source, key, value, rule)
    strict = _RULES[kind][0] == "> 0"
    if (strict and not x > 0) or (not strict and not x >= 0):
        raise ParameterError(source, key, value, rule)
    return x


P = TypeVar("P", bound="ParameterSet")


@dataclasses.dataclass(frozen=True)
class ParameterSet:
    """Base of every model's parameter set; validates all fields on construction."""

    model: ClassVar[str] = ""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = check_value(
                f"<{self.model} parameters>", f.name, getattr(self, f.name), f.metadata["kind"]
            )
            object.__setattr__(self, f.name, value)

    @classmethod
    def keys(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def from_mapping(cls: type[P], data: dict[str, Any], source: str = "<inline>", prefix: str = "") -> P:
        """Build a set from a mapping, rejecting unknown and missing keys."""
        known = cls.keys()
        for key, value in data.items():
            if key not in known:
                raise ParameterError(
                    source,
                    prefix + key,
                    value,
                    f"unknown key; the {cls.model} parameters are {', '.join(known)}",
                )
        values = {}
        for f in dataclasses.fields(cls):
            if f.name not in data:
                raise ParameterError(source, prefix + f.name, None, f"missing key ({f.metadata['doc']})")
            values[f.name] = check_value(source, prefix + f.name, data[f.name], f.metadata["kind"])
        try:
            return cls(**values)
        except ParameterError as exc:  # a rule across fields: name the file
            raise ParameterError(source, prefix + exc.key, exc.value, exc.rule) from None
        except OverflowError:  # a rule across fields computed x**2 beyond a double
            key = max(values, key=lambda k: abs(values[k]))
            raise ParameterError(
                source,
                prefix + key,
                values[key],
                f"too large: the {cls.model} terms built from it overflow a double",
            ) from None

    def as_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)

    def replace(self: P, **changes: float) -> P:
        return dataclasses.replace(self, **changes)

    def to_toml(self, name: str = "") -> str:
        """The set as a parameter file that ``load_parameter_file`` reads back exactly."""
        lines = [f'model = "{self.model}"']
        if name:
            lines.append(f'name = "{name}"')
        lines.append("")
        lines.append("[parameters]")
        for f in dataclasses.fields(self):
            lines.append(f"{f.name} = {getattr(self, f.name)!r}  # {f.metadata['doc']}")
        return "\n".join(lines) + "\n"


def read_toml(path: Path) -> dict[str, Any]:
    """Parse a TOML file, turning syntax errors into a ParameterError that names the file."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except FileNotFoundError:
        raise ParameterError(str(path), "<file>", str(path), "file not found") from None
    except IsADirectoryError:
        raise ParameterError(str(path), "<file>", str(path), "is a directory, not a TOML file") from None
    except OSError as exc:
        raise FileAccessError(str(path), "read", exc.strerror or str(exc)) from None
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
        raise ParameterError(source, "model", model, f"must be one of {', '.join(registry)}")
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
    return parse_parameter_document(read_toml(path), str(path), registry)


def default_parameter_file(model: str) -> Path:
    """The shipped default parameter file of a model."""
    from importlib.resources import files

    return Path(str(files("pendverify.analytic") / "params" / f"{model}.toml"))
