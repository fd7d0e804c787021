"""The corpus of a model SymPy cannot read: one parameter read wrongly wherever its code reads it.

``pendverify.diagnosis.corpus`` plants errors in a model's expressions through SymPy; the code of
NumPy functions (``pendverify.analytic.numpy_model``) and dynamics as code
(``pendverify.analytic.python_dynamics``) has none to edit.  What it has is one place where it
reads its parameters: the object ``p`` each function is given, the keyword parameters of
``DYNAMICS``.  A planted error here is an edit of what that place hands the code
(``planted_model``: the model's own functions, each given the edited parameters), one per
parameter (or pair) and operator (``OPERATORS``):

factor 2, factor ½
    the code reads 2·p (p/2) wherever it reads p: a mass doubled, a half-length;
sign
    g read as −g (gravity only: a sign of a mass or a length is not a slip one makes);
exchange
    two parameters of the same units read each as the other (``parameter_repair``'s ``alike``);
pivot
    an inertia read as about the pivot, I − m·x² in place of I for each product m·x² of a mass and a
    length (the code that adds no parallel-axis term, given an inertia about the centre of mass).

A Python class reads its parameters wherever its methods do: it has no such place, and gets no
corpus here.  The scores are those of ``corpus.Score``, with *restored* meaning: the repair
printed (what the code is to be given, ``details["suggested"]`` for ``details["written"]``),
composed with the plant, gives every parameter its own value back, at the file's values and at
``RESTORED_DRAWS`` random sets (the same function of the parameters, not the same numbers);
*named*: the diagnosis names an entry (the plant changes every entry the parameter enters).
"""

from __future__ import annotations

import dataclasses
import random
import time
from fractions import Fraction

import numpy as np
import sympy as sp

from pendverify.analytic.numpy_model import NumpyFunctionModel, Parameters
from pendverify.analytic.python_dynamics import PythonDynamicsModel
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.acceptance import passes
from pendverify.diagnosis.corpus import CORPUS_SAMPLES, CORPUS_SEED, ModelScores, Score
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.parameter_edits import ParameterEdit, alike

OPERATORS = ("factor 2", "factor ½", "sign", "exchange", "pivot")
#: random parameter sets a repair's composition with the plant is checked at, besides the file's
RESTORED_DRAWS = 2
#: relative difference of a value given back from its own: a few roundings of a sum of products
RESTORED_RTOL = 1e-12


@dataclasses.dataclass(frozen=True)
class CodePlant:
    """One planted error: the code reads ``edit`` applied to its parameters (module docstring)."""

    operator: str
    edit: ParameterEdit
    what: str


def code_plants(model) -> list[CodePlant]:
    """Every planted error of the corpus for one model (module docstring); none for a class."""
    if not reads_parameters_in_one_place(type(model)):
        return []
    params = model.params
    kinds = {f.name: f.metadata.get("kind") for f in dataclasses.fields(params)}
    values = params.as_dict()
    names = [n for n in kinds if values[n] != 0]
    out = []
    for name in names:
        for operator, factor in (("factor 2", Fraction(2)), ("factor ½", Fraction(1, 2))):
            out.append(
                CodePlant(
                    operator, ParameterEdit("scale", name, factor=factor), f"{name} read as {factor}·{name}"
                )
            )
        if kinds[name] == "gravity":
            out.append(
                CodePlant(
                    "sign", ParameterEdit("scale", name, factor=Fraction(-1)), f"{name} read as −{name}"
                )
            )
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            if alike(a, b, kinds, values):
                out.append(
                    CodePlant("exchange", ParameterEdit("exchange", a, b), f"{a} and {b} read as each other")
                )
    masses = [n for n in names if kinds[n] == "mass"]
    lengths = [n for n in names if kinds[n] in ("length", "offset")]
    for inertia in (n for n in names if kinds[n] == "inertia"):
        for m in masses:
            for x in lengths:
                term = -sp.Symbol(m) * sp.Symbol(x) ** 2
                out.append(
                    CodePlant(
                        "pivot",
                        ParameterEdit("add", inertia, term=term),
                        f"{inertia} read as {inertia} + {term}",
                    )
                )
    return out


def sample_code_plants(model, per_operator: int, seed: int = CORPUS_SEED) -> list[CodePlant]:
    """Up to ``per_operator`` planted errors of each operator, drawn with ``seed``."""
    rng = random.Random(seed)
    every = code_plants(model)
    chosen = []
    for operator in OPERATORS:
        group = [p for p in every if p.operator == operator]
        chosen += rng.sample(group, min(per_operator, len(group)))
    return chosen


def reads_parameters_in_one_place(model_cls) -> bool:
    """Whether the model's code is given its parameters in one place (module docstring)."""
    return issubclass(model_cls, (NumpyFunctionModel, PythonDynamicsModel))


def planted_model(model, edit: ParameterEdit):
    """``model`` with its code given ``edit`` applied to its parameters where it reads them, or
    None for a model with no such place (a class: module docstring)."""
    cls = type(model)
    if issubclass(cls, NumpyFunctionModel):
        functions = {key: _given_p(function, edit) for key, function in cls.functions.items()}
        planted = type(cls.__name__, (cls,), {"functions": functions, "__module__": cls.__module__})
    elif issubclass(cls, PythonDynamicsModel):
        dynamics = staticmethod(_given_keywords(cls.dynamics, edit))
        planted = type(cls.__name__, (cls,), {"dynamics": dynamics, "__module__": cls.__module__})
    else:
        return None
    return planted(model.params)


def _given_p(function, edit: ParameterEdit):
    """A NumPy-model function whose parameter object ``p`` (its last argument) has ``edit`` applied."""

    def planted(*args):
        *state, p = args
        values = {name: p[name] for name in p}
        return function(*state, Parameters({**values, **edit.given(values)}))

    return planted


def _given_keywords(function, edit: ParameterEdit):
    """A ``DYNAMICS`` function whose keyword parameters have ``edit`` applied."""

    def planted(*args, **parameters):
        return function(*args, **{**parameters, **edit.given(parameters)})

    return planted


def _restored(findings, plant: CodePlant, params, confirmed: bool | None = None) -> bool:
    """Whether a repair that makes every check pass (and is ``confirmed``, or not, when that is
    given) composed with the plant gives every parameter its value back (module docstring)."""
    rng = random.Random(CORPUS_SEED)
    own = params.as_dict()
    draws = [own] + [{n: v * rng.uniform(0.5, 2.0) for n, v in own.items()} for _ in range(RESTORED_DRAWS)]
    for f in findings:
        if f.kind != "repair" or not f.details.get("checks_pass"):
            continue
        if confirmed is not None and bool(f.details.get("confirmed")) is not confirmed:
            continue
        names = f.details["written"].split(", ")
        given = [sp.sympify(e) for e in f.details["suggested"].split(", ")]
        if len(names) != len(given):
            continue
        back = True
        for values in draws:
            symbols = {sp.Symbol(n): v for n, v in values.items()}
            repaired = {
                **values,
                **{n: float(e.xreplace(symbols)) for n, e in zip(names, given, strict=True)},
            }
            read = {**repaired, **plant.edit.given(repaired)}
            back = back and all(np.isclose(read[n], values[n], rtol=RESTORED_RTOL, atol=0) for n in values)
        if back:
            return True
    return False


def score_code_model(label: str, model, system, chosen=None, deadline_s: float = 10.0, progress=None):
    """The corpus of one model SymPy cannot read (``chosen``: a subset of its plants), each scored
    as ``corpus.score_model`` scores a planted expression."""
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    out = ModelScores(label)
    results = run_checks(label, model, system, states, CORPUS_SEED, applicable_checks(model, system))
    out.clean = passes(results)
    for plant in code_plants(model) if chosen is None else chosen:
        score = Score(plant)
        planted = planted_model(model, plant.edit)
        with np.errstate(all="ignore"):
            batch = CheckBatch(planted, system, states)
            try:
                results = run_checks(
                    label, planted, system, states, CORPUS_SEED, applicable_checks(planted, system), batch
                )
            except (ArithmeticError, ValueError, np.linalg.LinAlgError):
                results = None
        if results is not None and not passes(results):
            score.detected = True
            start = time.perf_counter()
            findings = explain(batch, results, deadline_s)
            score.seconds = time.perf_counter() - start
            score.named = any(f.kind == "entry" for f in findings)
            score.repaired = any(f.kind == "repair" and f.details.get("checks_pass") for f in findings)
            score.restored = _restored(findings, plant, model.params)
            printed_confirmed = any(f.kind == "repair" and f.details.get("confirmed") for f in findings)
            score.confirmed = _restored(findings, plant, model.params, confirmed=True)
            score.wrong_confirmed = printed_confirmed and not score.confirmed
            score.ambiguity_stated = not printed_confirmed and _restored(
                findings, plant, model.params, confirmed=False
            )
            score.message = next((f.message for f in findings if f.kind == "repair"), "")
        out.scores.append(score)
        if progress is not None:
            progress.update(1)
    return out
