"""The conformance matrix: cells (system × model format × command × description), their expected
outcomes, and the deterministic sample the default run takes.

``EXPECTED`` is the one table of what each (format kind, command) must do, with the reason where
a command does not apply: a format whose closed forms SymPy cannot read (dynamics as code, NumPy
functions) is refused by ``show``, ``sympy`` and ``mutate`` in one line with exit 2
(docs/models.md: "the diagnosis, show, sympy and mutate refuse or say so in one line"), and
dynamics as code by every scene command (docs/models.md: "a scene (simulate) refuses a model
without a closed-form M"); ``stress`` refuses an MJCF in one line (it rewrites a URDF's numbers;
docs/commands/stress.md does not say so).  Every other cell must exit 0 on the true model; ``check planted``
must exit 1 and name the planted entry in a ``diagnosis`` line (``Plant.names``; where the format
gives C only as a force — whole equations, a mechanics derivation — the row of C·q̇,
``Cqdot[i]``; dynamics as code and NumPy functions are judged numerically only and no entry is
expected).  No cell may exit 3 or raise.

The full product is ``PENDVERIFY_CONFORMANCE=full``; otherwise ``sample()`` takes:

* ``CORE`` (``check`` on the true model and ``check planted``): every (system, format) pair, each
  with a seeded description, so that every format is checked on every system both ways;
* every other model command: as many cells as it takes for every system and every format to
  appear (pairing two seeded permutations cyclically), so that every (system, command) and
  (format, command) pair is run; a permutation pairing a ``HEAVY_SYSTEMS`` system with a format
  outside ``LIGHT_FORMATS``, or running one twice, is drawn again (seeded), since those cells cost
  the most (measured on a loaded 2-core machine: ``sympy`` on chain5's text model 39 s, ``check``
  on its whole equations 37 s, where a light pairing takes 0.1–3 s);
* ``bench accuracy``: the cells of ``certify+recheck`` (``SAME_CELLS``), whose compiled code it reuses;
* ``show --robot``, which reads no model: once per system and description.
"""

from __future__ import annotations

import dataclasses
import os
import random

import sympy as sp

from tests.conformance.formats import FORMATS, Plant
from tests.conformance.systems import SEED, SYSTEMS, descriptions

COMMANDS = (
    "check",
    "check planted",
    "show",
    "show --robot",
    "sympy",
    "mutate",
    "simulate",
    "render",
    "report",
    "certify+recheck",
    "stress",
    "bench accuracy",
    "export",
)
#: commands that take no model file (a format is meaningless for them)
MODEL_FREE = ("show --robot",)
#: commands the default sample runs on every (system, format) pair (module docstring)
CORE = ("check", "check planted")
#: the systems with the longest closed forms (5 and 3 joints): SymPy reading their text models,
#: and ``sympy``'s derivation, dominate a run
HEAVY_SYSTEMS = ("chain5", "triple_pendulum")
#: command → the command whose cells it takes (same system, format and description): both compile
#: the model's generated code with numba (~20–100 s a model, the run's largest cost), which the
#: code cache keeps for the second (it keys on the model file's name and contents)
SAME_CELLS = {"bench accuracy": "certify+recheck"}
#: the formats a heavy system is paired with outside ``CORE``: Python code, which pendverify imports
#: rather than parses with SymPy
LIGHT_FORMATS = ("class", "class_object_arrays", "dynamics_f", "dynamics_qddot", "numpy_functions")
NUMERIC_ONLY = ("dynamics_f", "dynamics_qddot", "numpy_functions")
DYNAMICS_CODE = ("dynamics_f", "dynamics_qddot")
SCENE_COMMANDS = ("simulate", "render", "report", "bench accuracy")

_NOT_SYMBOLIC = "SymPy does not read code: refused in one line (docs/models.md, 'Dynamics as code')"
_NO_CLOSED_M = "a scene refuses a model without a closed-form M (docs/models.md, 'Dynamics as code')"

_NO_CODE_FROM_FUNCTIONS = (
    "bench accuracy --scene generates code from SymPy's reading of the model; NumPy functions are not "
    "read by SymPy: refused in one line (docs/models.md, 'NumPy functions')"
)

_EXPORT_READS_SYMPY = (
    "export writes the closed forms SymPy reads from the model; code (NumPy functions, dynamics) is not "
    "read: refused in one line (docs/commands/export.md)"
)

_STRESS_URDF = (
    "stress --analytic rewrites the robot file's numbers for its cases: an MJCF is refused in one line "
    "('an MJCF description, but stress --analytic rewrites a URDF's numbers: give a URDF or xacro file')"
)

#: (format, command, description) → (exit status, reason), "*" for any format or description;
#: a cell not listed must exit 0 (1 for "check planted")
EXPECTED: dict[tuple[str, str, str], tuple[int, str]] = {
    **{(f, c, "*"): (2, _NOT_SYMBOLIC) for f in NUMERIC_ONLY for c in ("show", "sympy", "mutate")},
    **{(f, c, "*"): (2, _NO_CLOSED_M) for f in DYNAMICS_CODE for c in SCENE_COMMANDS},
    ("numpy_functions", "bench accuracy", "*"): (2, _NO_CODE_FROM_FUNCTIONS),
    **{(f, "export", "*"): (2, _EXPORT_READS_SYMPY) for f in NUMERIC_ONLY},
    ("*", "stress", "mjcf"): (2, _STRESS_URDF),
}
#: formats that give no V: pendverify integrates V from H when it reads the file
V_FROM_H = ("equations", "matrix_equation", "mechanics")
_NOT_A_GRADIENT = (
    "a planted H that is not the gradient of any potential, in a format whose V is integrated from H, "
    "is refused at reading in one line naming H ('is not the gradient of any potential … give V as well')"
)
#: formats whose C reaches pendverify as the force C·q̇ only (split from a forcing)
C_AS_FORCE = ("equations", "mechanics")


def expected_exit(format_name: str, command: str, description: str) -> tuple[int, str]:
    default = (1, "a planted error fails check") if command == "check planted" else (0, "the true model")
    for key in (
        (format_name, command, description),
        (format_name, command, "*"),
        ("*", command, description),
    ):
        if key in EXPECTED:
            return EXPECTED[key]
    return default


def planted_refusal(format_name: str, plant: Plant, system_name: str) -> tuple[int, str] | None:
    """(2, reason) where a planted H can have no potential and the format's V comes from H, else None.

    Whether the planted H is still a gradient (∂H_i/∂q_j = ∂H_j/∂q_i) is decided from the derived
    closed forms, not assumed: scaling an entry that depends on its own coordinate alone keeps it one."""
    if plant.matrix != "H" or format_name not in V_FROM_H:
        return None
    from tests.conformance.closed_forms import closed_forms

    forms = plant.apply(closed_forms(system_name))
    jacobian = forms.H.jacobian(list(forms.q))
    if all(sp.simplify(jacobian[i, j] - jacobian[j, i]) == 0 for i in range(len(forms.q)) for j in range(i)):
        return None
    return 2, _NOT_A_GRADIENT


def expected_names(format_name: str, plant: Plant) -> tuple[str, ...]:
    """The entry names one of which a planted cell's diagnosis must print (empty: none expected)."""
    if format_name in NUMERIC_ONLY:
        return ()
    if plant.matrix == "C" and format_name in C_AS_FORCE:
        return (f"Cqdot[{plant.i + 1}]",)
    return plant.names


@dataclasses.dataclass(frozen=True)
class Cell:
    system: str
    format: str  # "-" for a model-free command
    command: str
    description: str

    @property
    def id(self) -> str:
        return f"{self.system}-{self.format}-{self.command.replace(' ', '_')}-{self.description}"


def plant_for(system_name: str) -> Plant:
    """The seeded planted error of a system: M, C or H, at a non-zero entry."""
    from tests.conformance.closed_forms import closed_forms

    forms = closed_forms(system_name)
    rng = random.Random(f"{SEED}-{system_name}")
    matrix = rng.choice("MCH")
    shape = getattr(forms, matrix).shape
    entries = [
        (i, j)
        for i in range(shape[0])
        for j in range(shape[1])
        if getattr(forms, matrix)[i, j] != 0 and (matrix != "M" or i <= j)
    ]
    if not entries:  # a system whose C is zero (one joint): plant in M
        return Plant("M", 0, 0)
    i, j = rng.choice(entries)
    return Plant(matrix, i, j)


def full_product() -> list[Cell]:
    cells = []
    for system in SYSTEMS.values():
        for description in descriptions(system):
            for command in COMMANDS:
                formats = ("-",) if command in MODEL_FREE else tuple(FORMATS)
                cells += [Cell(system.name, f, command, description) for f in formats]
    return cells


def _pairing(rng: random.Random, systems: list[str], formats: list[str]) -> list[tuple[str, str]]:
    """Seeded (system, format) pairs covering every system and every format, no heavy system with a
    format outside ``LIGHT_FORMATS`` and none twice (module docstring): permutations are drawn until
    one is."""
    while True:
        s_perm, f_perm = rng.sample(systems, len(systems)), rng.sample(formats, len(formats))
        pairs = [
            (s_perm[k % len(systems)], f_perm[k % len(formats)])
            for k in range(max(len(systems), len(formats)))
        ]
        heavy = [s for s, f in pairs if s in HEAVY_SYSTEMS]
        if len(heavy) == len(set(heavy)) and not any(
            s in HEAVY_SYSTEMS and f not in LIGHT_FORMATS for s, f in pairs
        ):
            return pairs


def sample() -> list[Cell]:
    """The default run's cells (module docstring)."""
    cells = []
    systems, formats = list(SYSTEMS), list(FORMATS)
    for index, command in enumerate(COMMANDS):
        rng = random.Random(SEED + index)
        if command in MODEL_FREE:
            cells += [Cell(s, "-", command, d) for s in systems for d in descriptions(SYSTEMS[s])]
            continue
        if command in SAME_CELLS:
            same = [c for c in cells if c.command == SAME_CELLS[command]]
            cells += [dataclasses.replace(c, command=command) for c in same]
            continue
        pairs = (
            [(s, f) for s in systems for f in formats] if command in CORE else _pairing(rng, systems, formats)
        )
        cells += [Cell(s, f, command, rng.choice(descriptions(SYSTEMS[s]))) for s, f in pairs]
    return cells


def selected() -> list[Cell]:
    return full_product() if os.environ.get("PENDVERIFY_CONFORMANCE") == "full" else sample()


def summary() -> str:
    full, chosen = full_product(), selected()
    return (
        f"conformance: {len(SYSTEMS)} systems × {len(FORMATS)} formats × {len(COMMANDS)} commands "
        f"(× each system's descriptions; model-free commands once per description) = {len(full)} cells; "
        f"{'full run' if len(chosen) == len(full) else 'sampled'} {len(chosen)}"
    )
