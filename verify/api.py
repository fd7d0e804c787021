"""pendverify as a Python library: the calls behind ``pendverify check`` and ``simulate``, without the CLI.

Everything here composes the functions the commands call (``pendverify.checks.targets``,
``pendverify.checks.verification``, ``pendverify.simulation``); nothing re-implements them, so
a report made here has the same results, verdicts and table as the command line::

    import pendverify

    report = pendverify.check("double_pendulum")      # as `pendverify check --model double_pendulum`
    report = pendverify.check("examples/cart_pole.py", "examples/cart_pole.urdf",
                              "examples/cart_pole.toml")        # a model file, as --analytic
    report.passed, report.status                                  # True, "pass"
    report["crba"]                                                # that check's rows, one per model
    print(report)                                                 # the table `pendverify check` prints
    run = pendverify.simulate("scenes/damped_double_pendulum.toml")
    run.t, run.q, run.v, run.passed

``check`` and ``pendverify check`` choose their targets through one dispatcher
(``pendverify.checks.targets.select_targets``), so the same arguments check the same models.

Models are given as a built-in name (``pendverify.analytic.MODELS``), a model file (``.py``,
one ``ClosedFormModel`` subclass, as ``--analytic``) or a ``ClosedFormModel`` subclass.  Bad
input raises a ``pendverify.errors.PendverifyError`` whose message is one line naming the
file or key, the value and the rule, as the CLI prints it.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pendverify.analytic import MODELS, ClosedFormModel, ParameterSet
from pendverify.analytic.parameter_set import check_value
from pendverify.analytic.plugin import load_model_class, validate_model_class
from pendverify.certify.battery import BatterySettings
from pendverify.certify.issue import certification_input, issue
from pendverify.certify.signing import load_private_key
from pendverify.checks.report import CheckReport
from pendverify.checks.sampling import DEFAULT_RANDOM_STATES, DEFAULT_SEED
from pendverify.checks.targets import is_builtin, parameter_values, select_targets
from pendverify.checks.verification import build_report
from pendverify.errors import InputError, PendverifyError, UnknownNameError
from pendverify.robot import erd as erd_data
from pendverify.robot.geometry import MODEL_FORM_RTOL
from pendverify.robot.system import PinocchioSystem

if TYPE_CHECKING:
    from pendverify.simulation.scene import Scene
    from pendverify.simulation.simulate import Run

#: A model: a built-in name, a model file (``.py``) or a ``ClosedFormModel`` subclass.
ModelLike = str | Path | type[ClosedFormModel]
#: Parameters: a TOML parameter file, the flat mapping of parameter values, or a parameter set.
ParamsLike = str | Path | Mapping[str, float] | ParameterSet
#: A URDF: a file path or the XML text itself.
UrdfLike = str | Path

#: ``source`` of the errors about the arguments of these functions.
OPTIONS_SOURCE = "<pendverify API arguments>"

__all__ = [
    "ModelLike",
    "ParamsLike",
    "UrdfLike",
    "certify_set",
    "check",
    "load_model",
    "load_params",
    "load_urdf",
    "simulate",
]


# --- loading ----------------------------------------------------------------------------------------
def load_model(source: ModelLike) -> type[ClosedFormModel]:
    """A closed-form model class.

    ``source`` is a built-in model's name (``"double_pendulum"``, ``"cart_double_pendulum"``), the
    path of a model file (``.py``, exactly one ``ClosedFormModel`` subclass: what ``--analytic``
    takes) or a ``ClosedFormModel`` subclass, which is validated as a model file's class is and
    returned as is.
    """
    if isinstance(source, type):
        if not issubclass(source, ClosedFormModel) or source is ClosedFormModel:
            raise PendverifyError(
                f"{source.__name__} is not a subclass of pendverify.analytic.ClosedFormModel"
            )
        if not is_builtin(source):
            validate_model_class(source)
        return source
    if isinstance(source, (str, Path)):
        text = str(source)
        if isinstance(source, str) and text in MODELS:
            return MODELS[text]
        path = Path(text)
        if (
            isinstance(source, Path)
            or path.suffix in (".py", ".toml")
            or len(path.parts) > 1
            or path.is_file()
        ):
            return load_model_class(text)
        raise PendverifyError(
            f"unknown model {text!r}: give a built-in model ({', '.join(MODELS)}), "
            "a model file (.py) or a ClosedFormModel subclass"
        )
    raise PendverifyError(
        "a model is a built-in name, a model file (.py) or a ClosedFormModel subclass; "
        f"got a {type(source).__name__}"
    )


def load_params(model_cls: ModelLike, source: ParamsLike) -> ParameterSet:
    """A validated parameter set of ``model_cls`` (a model as ``load_model`` takes it).

    ``source`` is one of

    * a parameter file (TOML: ``model``, optional ``name``, a ``[parameters]`` table), whose
      ``model`` must be the model's name — read as ``pendverify check --params`` reads it;
    * a mapping of the parameter values themselves, flat: ``{"m1": 1.0, "m2": 0.8, ...}`` (not a
      ``{"parameters": {...}}`` document); unknown and missing keys are errors;
    * a parameter set of the model's ``params_type``, returned as is.

    Every value is checked against its quantity's rule (masses and lengths finite and > 0, the
    rest finite and ≥ 0); an error names the file (or ``<inline>``), the key, the value and the rule.
    """
    return parameter_values(load_model(model_cls), source)


def load_urdf(model_cls: ModelLike, urdf: UrdfLike, g: float | None = None) -> PinocchioSystem:
    """A URDF (file path or XML text) loaded in Pinocchio and seen in ``model_cls``'s coordinates.

    The URDF is read strictly and its base anchored at the origin; the coordinate map is the
    one the model reads off the geometry (built-in models) or declares (``urdf_joints``,
    ``joint_transform``, ``joint_offset``).  ``g`` is the closed form's gravity (Pinocchio's
    9.81 m/s² when None), a finite number ≥ 0.  This is ``PinocchioSystem.for_model``.
    """
    cls = load_model(model_cls)
    if g is not None:
        g = check_value(OPTIONS_SOURCE, "g", g, "gravity")
    return PinocchioSystem.for_model(cls, _urdf_arg(urdf), g)


# --- check -----------------------------------------------------------------------------------------
def _urdf_arg(urdf: UrdfLike) -> str:
    if not isinstance(urdf, (str, Path)):
        raise PendverifyError(f"a URDF is a file path or its XML text; got a {type(urdf).__name__}")
    return str(urdf)


def _count(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(OPTIONS_SOURCE, key, value, "must be an integer >= 0")
    return value


def _flag(key: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise InputError(OPTIONS_SOURCE, key, value, "must be True or False")
    return value


def check(
    model: ModelLike | None = None,
    urdf: UrdfLike | None = None,
    params: ParamsLike | None = None,
    *,
    erd: bool = True,
    samples: int = DEFAULT_RANDOM_STATES,
    seed: int = DEFAULT_SEED,
    strict: bool = False,
    model_form_rtol: float = MODEL_FORM_RTOL,
) -> CheckReport:
    """Compare Pinocchio on a URDF with a hand-derived closed form: ``pendverify check``.

    The arguments select the same targets as the command line's (one dispatcher,
    ``pendverify.checks.targets.select_targets``):

    * ``check()``: every built-in model's default parameter set against its committed URDF,
      and example-robot-data's double-pendulum URDFs (``pendverify check``);
    * ``check("double_pendulum")``: that model's default set, and example-robot-data's URDFs
      (``pendverify check --model double_pendulum``); ``erd=False`` leaves them out
      (``--no-erd``).  When example-robot-data is not installed they are skipped and
      ``report.skipped`` says so;
    * ``check("erd:double_pendulum")`` or ``check(urdf="erd:double_pendulum")``: one of
      example-robot-data's URDFs, with its parameters read off it (``--urdf erd:NAME``);
    * ``check(name, params=P)``: the closed form of P against the URDF the project writes for P
      (``--params``); ``check(params="file.toml")`` takes the model the file names;
    * ``check(model, urdf, params)``: the URDF against the closed form of the parameters
      (``--model``/``--analytic`` with ``--urdf`` and ``--params``); without ``params``, a
      built-in model reads its parameters off the URDF.  A model file or class needs ``urdf``.

    ``model``, ``params`` and ``urdf`` are taken as ``load_model``, ``load_params`` and
    ``load_urdf`` take them (``urdf`` may also be ``erd:NAME``).  ``samples`` random states are
    drawn with ``seed`` (plus each model's special states); ``strict`` counts warnings as
    failures; ``model_form_rtol`` is the largest relative size of a URDF term the closed form
    cannot express (``--model-form-rtol``).

    Returns a ``CheckReport``: ``report["crba"]`` is one check's rows, ``print(report)`` the
    CLI's table.  A failing check is a result, not an exception (see
    ``pendverify.testing.assert_verified`` for that).  Bad input raises ``PendverifyError``.
    """
    started = time.perf_counter()
    samples, seed = _count("samples", samples), _count("seed", seed)
    strict, erd = _flag("strict", strict), _flag("erd", erd)
    if (
        isinstance(model_form_rtol, bool)
        or not isinstance(model_form_rtol, (int, float))
        or not (0 < model_form_rtol < math.inf)
    ):
        raise InputError(OPTIONS_SOURCE, "model_form_rtol", model_form_rtol, "must be a finite number > 0")
    if erd_data.is_erd_spec(model):  # check("erd:NAME"): the target the default check labels so
        if urdf is not None:
            raise PendverifyError(
                f"{model}: names example-robot-data's URDF; give it as model or as urdf, not both"
            )
        model, urdf = None, model
    model_cls = None if model is None else load_model(model)
    if urdf is not None and not erd_data.is_erd_spec(urdf):
        urdf = _urdf_arg(urdf)
    selection = select_targets(model_cls, urdf, params, erd_urdfs=erd)
    report = build_report(
        selection.targets, samples, seed, strict=strict, model_form_rtol=float(model_form_rtol)
    )
    report.skipped = selection.skipped
    report.elapsed_s = time.perf_counter() - started
    return CheckReport.from_report(report)


# --- simulate --------------------------------------------------------------------------------------
def simulate(
    scene: str | Path | Mapping[str, Any] | Scene,
    urdf: UrdfLike | None = None,
    engine: str | None = None,
) -> Run:
    """Run a scene and check its invariants: ``pendverify simulate``.

    ``scene`` is a scene file (TOML), a scene document as a mapping (the TOML's tables as dicts;
    a ``params`` file named there is found relative to the current directory) or a ``Scene``.
    ``urdf`` (path or XML text) replaces the URDF the project writes for the scene's parameter
    set, for the ``aba`` and ``both`` engines.  ``engine`` (``aba``, ``closed_form`` or ``both``)
    overrides the scene's.

    Returns the ``pendverify.simulation.simulate.Run``: arrays ``t``, ``q``, ``v``, ``u``, ``w``,
    ``energy``; ``invariants`` (name, error, tolerance, passed, detail); ``engine_comparison``
    (engine ``both``); ``passed``; ``notes``; ``metadata()``, ``to_npz_bytes()``, ``to_csv()``.
    """
    # deferred on purpose: the simulator brings SciPy (0.7 s), which check() does not need
    from pendverify.simulation.scene import ENGINES, Scene, load_scene, parse_scene
    from pendverify.simulation.simulate import simulate as run_scene

    if isinstance(scene, Scene):
        loaded = scene
    elif isinstance(scene, Mapping):
        loaded = parse_scene(dict(scene), "<inline scene>")
    elif isinstance(scene, (str, Path)):
        loaded = load_scene(scene)
    else:
        raise PendverifyError(f"a scene is a scene file, a mapping or a Scene; got a {type(scene).__name__}")
    if engine is not None and engine not in ENGINES:
        raise UnknownNameError("engine", str(engine), ENGINES)
    if urdf is not None and (engine or loaded.engine) == "closed_form":
        raise PendverifyError(
            f"{loaded.source}: engine closed_form does not use a URDF; use engine aba or both"
        )
    return run_scene(loaded, engine, None if urdf is None else _urdf_arg(urdf))


def certify_set(
    output: str | Path,
    params: str | Path | None = None,
    *,
    urdf: str | Path | None = None,
    model: str | None = None,
    urdf_params: str | Path | None = None,
    analytic: str | Path | None = None,
    key: str | Path | None = None,
    samples: int | None = None,
    seed: int | None = None,
    force: bool = False,
):
    """Run the full battery and, if every item passes, write a certificate bundle into ``output``.

    As ``pendverify certify``: a parameter file ``params``; or a ``urdf`` (a path or
    ``erd:NAME``) with ``urdf_params`` (the set it must match) or a built-in ``model``
    whose parameters are read off the URDF; or a model file ``analytic`` with its
    ``urdf`` and ``urdf_params`` (the certificate then embeds the file's text).
    ``key``: an Ed25519 private key file (``pendverify keygen``) that signs it.
    Returns the issued result (``items``, ``certified``, ``certificate``, ``path``).
    (Not ``certify``: that name is the ``pendverify.certify`` sub-package.)
    """
    settings = BatterySettings()
    if samples is not None:
        settings = dataclasses.replace(settings, samples=_count("samples", samples))
    if seed is not None:
        settings = dataclasses.replace(settings, seed=_count("seed", seed))
    target = certification_input(
        None if params is None else str(params),
        None if urdf is None else str(urdf),
        model,
        None if urdf_params is None else str(urdf_params),
        None if analytic is None else str(analytic),
    )
    signer = None if key is None else load_private_key(key)  # a bad key fails before any work
    return issue(target, settings, str(output), force, key=signer)
