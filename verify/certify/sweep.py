"""Sweeps: certify many parameter sets in parallel through ``concurrent.futures``.

A sweep file (TOML)::

    model = "double_pendulum"  # a built-in model, or a model file relative to the sweep file
    base = "default"       # the set the ranges vary ("default" or a parameter file)
    # urdf = "arm.urdf"    # a model file's: the URDF of the base set, relative to the sweep file
    mode = "random"        # random (seeded, uniform or log-uniform) | grid
    count = 200            # random only
    seed = 7
    samples = 200          # battery states per set (default 200)
    duration = 1.0         # s of simulation per effect (default 1)
    [ranges]
    m1 = [0.5, 2.0]                                      # linear, [min, max]
    I1 = { min = 0.01, max = 0.05, scale = "log", points = 3 }   # points: grid only

For a model file, each set's URDF is the base URDF with the varied parameters'
values rewritten where the base set's values sit (``pendverify.robot.rebind``); a
range over a parameter the URDF does not show is refused, naming it.  Tasks carry
the model file's source text, not the class, and load it once per worker.

A sweep's ``seed``, ``samples`` and ``duration`` obey the rule of certify's options and
of a certificate's settings (``pendverify.certify.settings_rules``: ``samples`` at most
``PENDVERIFY_MAX_SAMPLES``).  A sweep of more than ``max_sets`` sets (a
count, or the product of a grid's points) is refused before any set is made.  ``pendverify.certify.sweep_run``
runs the tasks (``pendverify.certify.sweep_task``), on local processes or a Dask
cluster; the task is the same pure function either way, so both produce the same
certificates.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import plugin_parameters
from pendverify.certify.battery import BatterySettings
from pendverify.certify.model_source import ModelSource
from pendverify.certify.settings_rules import settings_problem
from pendverify.certify.sweep_limits import DEFAULT_MAX_SETS
from pendverify.documents import (
    Key,
    Table,
    check_keys,
    check_table,
    check_value,
    check_values,
    is_finite,
    is_integer,
    is_string,
    is_table,
    raising,
    read_toml,
)
from pendverify.errors import PendverifyError, SweepError
from pendverify.file_kinds import expect_kind
from pendverify.robot.description import urdf_text
from pendverify.robot.rebind import Binding

MODES = ("random", "grid")
SCALES = ("linear", "log")


@dataclass(frozen=True)
class Sweep:
    model: ModelSource
    sets: list[tuple[str, dict]]  # (name, parameter values)
    settings: BatterySettings
    urdf: str | None = None  # a model file's: the URDF of the base set (text)
    base: dict | None = None  # a model file's: the base set's values


def _setting(key: str, unit: str = ""):
    """The rule of a battery setting: certify's options' and recheck's (``settings_rules``)."""
    name = "sim_duration" if key == "duration" else key
    return ((lambda v: not settings_problem(name, v), lambda v: settings_problem(name, v) + unit),)


def _at_least_one(v) -> bool:
    return is_integer(v) and v >= 1


#: a sweep file's top level; ``model``, ``base`` and ``urdf`` name files (``_model_and_base``)
SWEEP = Table(
    {
        "model": Key(required=False),
        "base": Key(
            ((lambda v: is_string(v) and bool(v), 'expected "default" or a parameter file (a string)'),),
            required=False,
            default="default",
        ),
        "urdf": Key(required=False),
        "mode": Key(((lambda v: v in MODES, "expected random or grid"),), required=False, default="random"),
        "count": Key(((_at_least_one, "expected an integer >= 1"),), required=False, default=100),
        "seed": Key(_setting("seed"), required=False, default=0),
        "samples": Key(_setting("samples"), required=False, default=200),
        "duration": Key(_setting("duration", " (s, per simulated effect)"), required=False, default=1.0),
        "ranges": Key(
            ((lambda v: is_table(v) and bool(v), "expected a table of at least one parameter range"),)
        ),
    },
    missing="{rule}",
)
#: one range given as a table (``[min, max]`` is the table of those two)
RANGE = Table(
    {
        "min": Key(((is_finite, "expected a finite number"),)),
        "max": Key(((is_finite, "expected a finite number"),)),
        "scale": Key(((lambda v: v in SCALES, "expected linear or log"),), required=False, default="linear"),
        "points": Key(((_at_least_one, "expected an integer >= 1"),), required=False, default=3),
    },
    unknown="unknown key; expected {keys}",
    missing="{rule}",
)


def _range(source, key, value):
    """(min, max, scale, points) of ``ranges.KEY``."""
    if isinstance(value, list) and len(value) == 2:
        table = {"min": value[0], "max": value[1]}
    elif isinstance(value, dict):
        table = value
    else:
        raise SweepError(source, f"ranges.{key}", value, "expected [min, max] or a table {min, max, ...}")
    spec = check_table(table, RANGE, raising(SweepError, source), f"ranges.{key}.")
    if spec["max"] < spec["min"]:
        raise SweepError(source, f"ranges.{key}", value, "expected min <= max")
    if spec["scale"] == "log" and spec["min"] <= 0:
        raise SweepError(source, f"ranges.{key}.min", spec["min"], "a log range needs min > 0")
    return float(spec["min"]), float(spec["max"]), spec["scale"], spec["points"]


def _count(source, mode: str, count: int, specs: dict, max_sets: int) -> int:
    """The number of sets, refused (naming the key, the count and the limit) above ``max_sets``."""
    if mode == "grid":
        n = math.prod(spec[3] for spec in specs.values())
        key, value = "ranges", " × ".join(f"{k}: {spec[3]} points" for k, spec in specs.items())
    else:
        n, key, value = count, "count", count
    if n > max_sets:
        raise SweepError(
            source, key, value, f"{n:,} sets exceed the limit of {max_sets:,}; raise it with --max-sets N"
        )
    return n


def load_sweep(path: str | Path, max_sets: int = DEFAULT_MAX_SETS) -> Sweep:
    """A sweep file's sets; more than ``max_sets`` of them is refused before any is made."""
    path = Path(path)
    source = str(path)
    data = read_toml(path, "sweep file")
    expect_kind(data, path, "sweep")
    check_keys(data, SWEEP, raising(SweepError, source))
    model, base, urdf = _model_and_base(path, data)
    values = check_values(data, SWEEP, raising(SweepError, source))
    mode, count, ranges = values["mode"], values["count"], values["ranges"]
    known = base.keys()
    binding = Binding.of(urdf, base, data["urdf"]) if urdf is not None else None
    specs = {}
    for key, value in ranges.items():
        if key not in known:
            raise SweepError(
                source, f"ranges.{key}", value, f"unknown parameter; {model.name} has {', '.join(known)}"
            )
        if binding is not None and key in binding.reasons:
            raise SweepError(source, f"ranges.{key}", value, f"cannot be varied: {binding.reasons[key]}")
        specs[key] = _range(source, key, value)

    count = _count(source, mode, count, specs, max_sets)
    sets = SweepSets(model.name, base.as_dict(), specs, mode, count, values["seed"])
    settings = BatterySettings(
        samples=values["samples"], seed=values["seed"], sim_duration=float(values["duration"])
    )
    return Sweep(model, sets, settings, urdf, None if urdf is None else base.as_dict())


class SweepSets(Sequence):
    """A sweep's sets (name, values), made one at a time as they are iterated, never all at once.

    Each pass makes them again, the same every time: a grid in ``itertools.product``
    order, or ``count`` seeded rows, one ``uniform()`` draw per range in order.  Indexing
    walks from the start (O(i): for tests and messages, not for loops).
    """

    def __init__(self, prefix: str, base: dict, specs: dict, mode: str, count: int, seed: int):
        self.prefix, self.base, self.specs = prefix, dict(base), dict(specs)
        self.mode, self.count, self.seed = mode, count, seed

    def __len__(self) -> int:
        return self.count

    def __iter__(self) -> Iterator[tuple[str, dict]]:
        width = len(str(self.count - 1))
        for i, row in enumerate(self._rows()):
            yield f"{self.prefix}-{i:0{width}d}", {**self.base, **row}

    def __getitem__(self, i):
        if isinstance(i, slice):
            return list(itertools.islice(self, *i.indices(self.count)))
        if not -self.count <= i < self.count:
            raise IndexError(i)
        return next(itertools.islice(self, i % self.count, None))

    def _rows(self) -> Iterator[dict]:
        specs = self.specs
        if self.mode == "grid":
            axes = [
                np.geomspace(lo, hi, n) if scale == "log" else np.linspace(lo, hi, n)
                for lo, hi, scale, n in specs.values()
            ]
            for combo in itertools.product(*axes):
                yield dict(zip(specs, (float(x) for x in combo), strict=True))
            return
        rng = np.random.default_rng(self.seed)
        for _ in range(self.count):
            row = {}
            for key, (lo, hi, scale, _) in specs.items():
                u = rng.uniform()
                row[key] = float(
                    np.exp(np.log(lo) + u * (np.log(hi) - np.log(lo)))
                    if scale == "log"
                    else lo + u * (hi - lo)
                )
            yield row


def _model_and_base(path: Path, data: dict):
    """(model source, base parameter set, base URDF text or None) of a sweep file."""
    source = str(path)
    ref = data.get("model")
    base_ref = check_value(
        "base", data.get("base", "default"), SWEEP.keys["base"], raising(SweepError, source)
    )
    if isinstance(ref, str) and ref.endswith((".py", ".toml")):
        model_file = path.parent / ref
        try:
            model = ModelSource.of_file(model_file)
        except PendverifyError as exc:
            raise SweepError(source, "model", ref, f"not a usable model file: {exc}") from None
        cls = model.load()
        if base_ref == "default":
            raise SweepError(
                source, "base", base_ref, "a model file has no default set: give a parameter file"
            )
        base = plugin_parameters(cls, str(model_file), str(path.parent / base_ref))
        if not hasattr(base, "g"):
            raise SweepError(source, "model", ref, "certify needs a gravity parameter g in the model's set")
        urdf_ref = data.get("urdf")
        if not isinstance(urdf_ref, str) or not (path.parent / urdf_ref).is_file():
            raise SweepError(source, "urdf", urdf_ref, "a model file needs the URDF of its base set (a file)")
        return model, base, urdf_text(path.parent / urdf_ref, "a sweep")
    if not isinstance(ref, str) or ref not in MODELS:
        raise SweepError(source, "model", ref, f"expected a model file (.py) or one of {', '.join(MODELS)}")
    if "urdf" in data:
        raise SweepError(
            source, "urdf", data["urdf"], "a built-in model's sets use the URDF the project writes"
        )
    base_path = default_parameter_file(ref) if base_ref == "default" else path.parent / base_ref
    base_model, _, base = load_parameter_file(base_path)
    if base_model != ref:
        raise SweepError(source, "base", base_ref, f"that parameter file is for {base_model!r}")
    return ModelSource(ref), base, None
