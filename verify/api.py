"""pendverify as a Python library, and the one dispatcher the commands call.

Every command of the command line parses its options, calls one function here and formats
what it returns; so the library and the command line share every result, verdict and
table::

    import pendverify

    report = pendverify.check("double_pendulum")      # as `pendverify check --model double_pendulum`
    report = pendverify.check("examples/cart_pole.py", "examples/cart_pole.urdf",
                              "examples/cart_pole.toml")        # a model file, as --analytic
    report.passed, report.status                                  # True, "pass"
    report["crba"]                                                # that check's rows, one per model
    print(report)                                                 # the table `pendverify check` prints
    run = pendverify.simulate("scenes/damped_double_pendulum.toml")
    run.t, run.q, run.v, run.passed

``check`` chooses its targets through ``pendverify.targets.select_targets``, so the same
arguments check the same models.  The other functions are those behind ``mutate``,
``sympy``, ``show``, ``simulate``, ``render``, ``report``, ``stress``, ``bench``,
``keygen``, ``certify`` (``certify_set``, and ``sweep`` for ``--sweep``), ``recheck`` and
``example``; each imports what it needs when it
is called, so importing this module imports neither SymPy nor SciPy.

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
from typing import TYPE_CHECKING, Any, NamedTuple

import pinocchio as pin

from pendverify.analytic import MODELS, ClosedFormModel, ParameterSet
from pendverify.analytic.parameter_set import check_value
from pendverify.analytic.plugin import load_model_class, validate_model_class
from pendverify.certify.sweep_limits import DEFAULT_MAX_SETS, WORKER_TIMEOUT_S
from pendverify.checks.report import CheckReport
from pendverify.checks.sampling import DEFAULT_RANDOM_STATES, DEFAULT_SEED
from pendverify.checks.trust import REFUSE_REL as REFUSE_REL  # re-exported: the bound stress reports
from pendverify.checks.verification import build_report, model_report
from pendverify.display import REPR_LIMIT, html_table, shortened
from pendverify.errors import InputError, PendverifyError, UnknownNameError, missing_file
from pendverify.robot import erd as erd_data
from pendverify.robot.description import LoadedDescription
from pendverify.robot.geometry import MODEL_FORM_RTOL
from pendverify.robot.pinocchio_model import PinocchioRobot, describe_model, is_pinocchio_object
from pendverify.robot.system import PinocchioSystem
from pendverify.targets import is_builtin, parameter_values, select_targets

if TYPE_CHECKING:
    from pendverify.bench.certify import SetCost
    from pendverify.bench.run import Results
    from pendverify.certify.battery import BatterySettings
    from pendverify.certify.issue import Issued, Rechecked
    from pendverify.certify.sweep_run import SweepRun
    from pendverify.robot.summary import RobotSummary
    from pendverify.simulation.scene import Scene
    from pendverify.simulation.simulate import Run
    from pendverify.stress.catalogue import StressReport
    from pendverify.symbolic.compare import SymbolicReport
    from pendverify.symbolic.mutation_report import MutationReport
    from pendverify.viz.animation import AnimationPage, Trajectory
    from pendverify.viz.review_folder import ReviewFolder
    from pendverify.worked_examples import WorkedExample

#: A model: a built-in name, a model file (``.py``) or a ``ClosedFormModel`` subclass.
ModelLike = str | Path | type[ClosedFormModel]
#: Parameters: a TOML parameter file, the flat mapping of parameter values, or a parameter set.
ParamsLike = str | Path | Mapping[str, float] | ParameterSet
#: A URDF: a file path, the XML text itself, or a robot given as a Pinocchio object: a
#: ``pinocchio.Model``, a ``pinocchio.RobotWrapper`` or a ``PinocchioRobot`` (a model with its
#: visual model and URDF text), read by ``pendverify.robot.pinocchio_model``.
UrdfLike = str | Path | pin.Model | pin.RobotWrapper | PinocchioRobot

#: ``source`` of the errors about the arguments of these functions.
OPTIONS_SOURCE = "<pendverify API arguments>"

__all__ = [
    "Equation",
    "ModelLike",
    "ModelReading",
    "ParamsLike",
    "PinocchioRobot",
    "SweepCertificates",
    "UrdfLike",
    "animation_html",
    "animation_page",
    "bench_accuracy",
    "bench_certify",
    "bench_explain",
    "certify_set",
    "check",
    "check_animation_length",
    "compare_symbolic",
    "copy_example",
    "export",
    "generate_keys",
    "implied_parameters",
    "load_model",
    "load_params",
    "load_scene",
    "load_urdf",
    "mutate",
    "read_model",
    "read_robot",
    "recheck",
    "review",
    "review_scenes",
    "ros_packages",
    "simulate",
    "stress",
    "sweep",
    "trajectory",
    "worked_example",
    "worked_examples",
]


# --- loading ----------------------------------------------------------------------------------------
def load_model(
    source: ModelLike | Any, declaration: Mapping[str, Any] | None = None
) -> type[ClosedFormModel]:
    """A closed-form model class.

    ``source`` is a built-in model's name (``"double_pendulum"``, ``"cart_double_pendulum"``), the
    path of a model file (``.py``, exactly one ``ClosedFormModel`` subclass, or a ``METHOD`` and
    its ``DECLARATION``; ``.toml``, a text model: what ``--analytic`` takes), a ``ClosedFormModel``
    subclass, which is validated as a model file's class is and returned as is, or a
    ``sympy.physics.mechanics`` derivation — a ``LagrangesMethod``, a ``KanesMethod`` or a
    ``(mass_matrix, forcing)`` pair — with its ``declaration``: the coordinates' kinds, the
    parameters' kinds, the inputs and the URDF map, as a text model file declares them
    (``pendverify.analytic.mechanics_model``), or a right-hand side in Python — ẋ = f(x, u),
    f(t, x, u) or q̈ = qddot(q, v, u) — with its ``declaration``, which adds the signature, the
    state layout and B, D, W (``pendverify.analytic.python_dynamics``).
    """
    if callable(source) and not isinstance(source, type):
        from pendverify.analytic.python_dynamics import python_dynamics_model

        if declaration is None:
            raise PendverifyError(
                f"a function ({getattr(source, '__name__', type(source).__name__)}) needs a declaration: "
                "its coordinates, parameters, inputs, B and urdf joints "
                "(see pendverify.analytic.python_dynamics)"
            )
        cls = python_dynamics_model(source, declaration)
        validate_model_class(cls, "<declaration>")
        return cls
    if declaration is not None or _is_mechanics(source):
        from pendverify.analytic.mechanics_model import is_mechanics, mechanics_model

        if not is_mechanics(source):
            raise PendverifyError(
                "a declaration goes with a LagrangesMethod, a KanesMethod, a (mass_matrix, forcing) "
                f"pair or a right-hand side function; got a {type(source).__name__}"
            )
        if declaration is None:
            raise PendverifyError(
                f"a {type(source).__name__} needs a declaration: its coordinates' and parameters' kinds, "
                "inputs and urdf joints (see pendverify.analytic.mechanics_model)"
            )
        cls = mechanics_model(source, declaration)
        validate_model_class(cls, "<declaration>")
        return cls
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


def _is_mechanics(source) -> bool:
    """Whether ``source`` looks like a SymPy mechanics derivation (without importing SymPy for others)."""
    module = type(source).__module__
    return module.startswith("sympy") or (isinstance(source, tuple) and len(source) == 2)


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
    """A URDF (file path or XML text; or a ``pinocchio.Model``, ``RobotWrapper`` or
    ``PinocchioRobot``, copied) loaded in Pinocchio and seen in ``model_cls``'s coordinates.

    The URDF is read strictly and its base anchored at the origin; the coordinate map is the
    one the model reads off the geometry (built-in models) or declares (``urdf_joints``,
    ``joint_transform``, ``joint_offset``).  ``g`` is the closed form's gravity (Pinocchio's
    9.81 m/s² when None), a finite number ≥ 0.  This is ``PinocchioSystem.for_model``.
    """
    cls = load_model(model_cls)
    if g is not None:
        g = check_value(OPTIONS_SOURCE, "g", g, "gravity")
    return PinocchioSystem.for_model(cls, _urdf_arg(urdf), g)


def ros_packages(*folders: str | Path):
    """Inside ``with pendverify.ros_packages(DIR, ...):`` the folders hold ROS packages for
    ``$(find PKG)`` in xacro and ``package://PKG/...`` meshes (``--package-path DIR`` on the
    command line).

    Every function that takes a URDF reads it there: the folders are searched (each is a
    package or holds packages below it) before ``ROS_PACKAGE_PATH`` and
    ``AMENT_PREFIX_PATH/share`` (``pendverify.robot.packages``).  A folder that does not exist
    raises ``PendverifyError``; an unknown package, one line naming it and the folders searched.
    """
    from pendverify.robot.packages import package_path

    for folder in folders:
        if not isinstance(folder, (str, Path)):
            raise PendverifyError(f"a package folder is a path; got a {type(folder).__name__}")
    return package_path(folders)


# --- check -----------------------------------------------------------------------------------------
def _urdf_arg(urdf: UrdfLike) -> str | LoadedDescription:
    """A URDF argument as the readers take it: a path or text as a string, a Pinocchio object read."""
    if is_pinocchio_object(urdf):
        return describe_model(urdf)
    if not isinstance(urdf, (str, Path)):
        raise PendverifyError(
            "a URDF is a file path, its XML text, a pinocchio.Model or a RobotWrapper; "
            f"got a {type(urdf).__name__}"
        )
    return str(urdf)


def _urdf_file_arg(urdf: UrdfLike, command: str) -> str:
    """A URDF that ``command`` re-reads by name (a file path or XML text); a Pinocchio object is refused."""
    if is_pinocchio_object(urdf):
        raise PendverifyError(
            f"{command} takes the URDF as a file path or its XML text (it reads the description again "
            f"for each case); got a {type(urdf).__name__}: give the file the model was built from"
        )
    return str(_urdf_arg(urdf))


def _count(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(OPTIONS_SOURCE, key, value, "must be an integer >= 0")
    return value


def _at_least_one(key: str, value: Any) -> int:
    if _count(key, value) < 1:
        raise InputError(OPTIONS_SOURCE, key, value, "must be an integer >= 1")
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
    explain: bool = True,
    declaration: Mapping[str, Any] | None = None,
) -> CheckReport:
    """Compare Pinocchio on a URDF with a hand-derived closed form: ``pendverify check``.

    The arguments select the same targets as the command line's (one dispatcher,
    ``pendverify.targets.select_targets``):

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
      built-in model reads its parameters off the URDF;
    * ``check(model)``, a model file or class without ``urdf``: its ``units`` check alone (one
      dimension per entry, from the parameters' kinds: ``pendverify.checks.units``), which needs
      no robot; a model SymPy cannot read needs ``urdf``.  Every report with a model SymPy reads
      has its ``units`` row first.

    ``model``, ``params`` and ``urdf`` are taken as ``load_model``, ``load_params`` and
    ``load_urdf`` take them (``urdf`` may also be ``erd:NAME``).  ``samples`` random states are
    drawn with ``seed`` (plus each model's special states); ``strict`` counts warnings as
    failures; ``model_form_rtol`` is the largest relative size of a URDF term the closed form
    cannot express (``--model-form-rtol``); ``explain=False`` skips the diagnosis of failing
    models (``--no-explain``).  ``declaration`` goes with a ``sympy.physics.mechanics`` model or a
    right-hand side function (``load_model``): ``check(model=f, urdf=..., params=..., declaration={...})``.

    Returns a ``CheckReport``: ``report["crba"]`` is one check's rows, ``print(report)`` the
    CLI's table.  A failing check is a result, not an exception (see
    ``pendverify.testing.assert_verified`` for that).  Bad input raises ``PendverifyError``.
    """
    started = time.perf_counter()
    samples, seed = _count("samples", samples), _count("seed", seed)
    strict, erd, explain = _flag("strict", strict), _flag("erd", erd), _flag("explain", explain)
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
    model_cls = None if model is None else load_model(model, declaration)
    if urdf is None and model_cls is not None and not is_builtin(model_cls):
        # a model alone: what its own expressions can show, the units (checks.verification.model_report)
        if params is not None:
            parameter_values(model_cls, params)  # a parameter file given is read, and refused if bad
        report = model_report(model_cls, seed)
        report.strict, report.explain = strict, explain
        report.elapsed_s = time.perf_counter() - started
        return CheckReport.from_report(report)
    if urdf is not None and not erd_data.is_erd_spec(urdf):
        urdf = _urdf_arg(urdf)
    selection = select_targets(model_cls, urdf, params, erd_urdfs=erd)
    report = build_report(
        selection.targets,
        samples,
        seed,
        strict=strict,
        model_form_rtol=float(model_form_rtol),
        explain=explain,
    )
    report.skipped = selection.skipped
    report.elapsed_s = time.perf_counter() - started
    return CheckReport.from_report(report)


def implied_parameters(
    model: ModelLike,
    urdf: UrdfLike,
    params: ParamsLike,
    *,
    samples: int = DEFAULT_RANDOM_STATES,
    seed: int = DEFAULT_SEED,
):
    """Which inertial parameters of the URDF's tree does the hand model assume?

    The hand model's M, C·q̇ and H at ``samples`` random states (drawn with ``seed``) are fitted
    by Pinocchio's joint torque regressor (``pendverify.diagnosis.implied``).  Returns an
    ``ImpliedParameters``: ``exact`` (some inertial parameters reproduce the equations to
    rounding), ``agrees`` (the URDF's own do), ``combinations`` (each identifiable combination
    with the model's and the URDF's value and its rounding) and ``unexplained`` (the entries
    no parameters reproduce, when not ``exact``).  Bad input raises ``PendverifyError``.
    """
    from pendverify.checks.batch import CheckBatch
    from pendverify.checks.sampling import sample_states
    from pendverify.diagnosis.implied import implied_parameters as fit

    cls = load_model(model)
    parameter_set = load_params(cls, params)
    system = load_urdf(cls, urdf, getattr(parameter_set, "g", None))
    hand = cls(parameter_set)
    states = sample_states(hand, _count("samples", samples), _count("seed", seed))
    return fit(CheckBatch(hand, system, states))


# --- simulate and draw -----------------------------------------------------------------------------
def load_scene(scene: str | Path | Mapping[str, Any] | Scene) -> Scene:
    """A scene: a scene file (TOML), a scene document as a mapping (the TOML's tables as dicts;
    a ``params`` file named there is found relative to the current directory) or a ``Scene``,
    returned as is."""
    # imported when a scene is loaded: the simulation sub-package is of no use to check()
    from pendverify.simulation.scene import Scene, parse_scene
    from pendverify.simulation.scene import load_scene as read_scene_file

    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, Mapping):
        return parse_scene(dict(scene), "<inline scene>")
    if isinstance(scene, (str, Path)):
        return read_scene_file(scene)
    raise PendverifyError(f"a scene is a scene file, a mapping or a Scene; got a {type(scene).__name__}")


def simulate(
    scene: str | Path | Mapping[str, Any] | Scene,
    urdf: UrdfLike | None = None,
    engine: str | None = None,
) -> Run:
    """Run a scene and check its invariants: ``pendverify simulate``.

    ``scene`` is taken as ``load_scene`` takes it.  ``urdf`` (path or XML text) replaces the
    URDF the project writes for the scene's parameter set: the URDF ABA integrates (engines
    ``aba`` and ``both``) and an LQR controller is designed on.  ``engine`` (``aba``,
    ``closed_form`` or ``both``) overrides the scene's.

    Returns the ``pendverify.simulation.simulate.Run``: arrays ``t``, ``q``, ``v``, ``u``, ``w``,
    ``energy``; ``invariants`` (name, error, tolerance, passed, detail); ``engine_comparison``
    (engine ``both``); ``passed``; ``notes``; ``metadata()``, ``to_npz_bytes()``, ``to_csv()``.
    """
    from pendverify.simulation.engine_names import SCENE_ENGINE_CHOICES
    from pendverify.simulation.simulate import run_scene

    loaded = load_scene(scene)
    if engine is not None and engine not in SCENE_ENGINE_CHOICES:
        raise UnknownNameError("engine", str(engine), SCENE_ENGINE_CHOICES)
    lqr = loaded.actuation is not None and loaded.actuation.kind == "lqr"
    if urdf is not None and (engine or loaded.engine) == "closed_form" and not lqr:
        raise PendverifyError(
            f"{loaded.source}: engine closed_form does not use a URDF; use engine aba or both"
        )
    return run_scene(loaded, engine, None if urdf is None else _urdf_arg(urdf))


def check_animation_length(scene: Scene) -> None:
    """Refuse, before it is simulated, a scene whose animation would hold more frames than
    ``pendverify.viz.animation.max_frames()`` (the error names ``time.duration``)."""
    from pendverify.viz.animation import check_frame_count

    check_frame_count(scene.source, "time.duration", scene.duration, scene.duration)


def trajectory(run: Run | str | Path, model_file: str | Path | None = None) -> Trajectory:
    """What an animation draws: of a ``Run``, or of a saved run (the npz ``pendverify simulate -o``
    writes: its t, q and the metadata's model and parameters, from which the same URDF is
    written again).  A saved run of a Python model file is drawn only with that file given as
    ``model_file``: the npz is data and never makes pendverify import what it names."""
    from pendverify.viz.animation import Trajectory

    if isinstance(run, (str, Path)):
        return Trajectory.from_npz(run, model_file)
    if model_file is not None:
        raise PendverifyError("model_file is for a saved run (npz); a Run carries its model")
    return Trajectory.from_run(run)


def animation_html(source: Trajectory, trace: bool = False) -> str:
    """The self-contained HTML page (meshcat, plays from file://) that animates ``source`` in
    real time; ``trace`` draws the path of the tip.  ``pendverify render``."""
    return animation_page(source, trace).html


def animation_page(source: Trajectory, trace: bool = False) -> AnimationPage:
    """``animation_html``'s page (``.html``) with what drawing it noticed (``.notes``: e.g. that
    a description without visual geometry is drawn as a skeleton).  ``pendverify render``."""
    from pendverify.viz.animation import animation_page as page

    return page(source, trace=_flag("trace", trace))


def review_scenes(folder: str | Path | None = None) -> list[Path]:
    """The scene files ``review`` runs: those in ``folder``, or the scenes installed with
    pendverify (``pendverify.shipped``) when None.  A TOML file that is plainly another kind
    (a parameter file or a text model beside the scenes, ``pendverify.file_kinds``) is left out;
    ``review`` notes each one it leaves out."""
    return _scene_files(folder)[0]


def _scene_files(folder: str | Path | None) -> tuple[list[Path], list[str]]:
    """(the scene files of ``folder``, one note per TOML file left out as another kind)."""
    from pendverify.documents import file_kind
    from pendverify.file_kinds import KINDS
    from pendverify.shipped import shipped_folder

    path = Path(folder) if folder else shipped_folder("scenes")
    if folder and not path.exists():
        raise missing_file(path, "folder of scenes")
    if folder and not path.is_dir():
        raise InputError(OPTIONS_SOURCE, "scenes", str(path), "not a folder: give the folder of scene files")
    scenes, skipped = [], []
    for file in sorted(path.glob("*.toml")) if path.is_dir() else []:
        kind = file_kind(file)
        if kind in (None, "scene"):  # one whose keys tell no kind is read as a scene, and its error shown
            scenes.append(file)
        else:
            skipped.append(f"skipped {file.name}: a {KINDS[kind].noun}, not a scene")
    if not scenes:
        raise InputError(OPTIONS_SOURCE, "scenes", str(path), "no scene files (*.toml) in that folder")
    return scenes, skipped


def review(
    output: str | Path,
    scenes: str | Path | None = None,
    *,
    samples: int = DEFAULT_RANDOM_STATES,
    seed: int = DEFAULT_SEED,
    erd: bool = True,
    trace: bool = False,
    force: bool = False,
    log=print,
) -> ReviewFolder:
    """Write the review page ``output/index.html``: ``pendverify report``.

    Every model the scenes (``review_scenes(scenes)``) simulate is checked (``samples``
    random states drawn with ``seed``; example-robot-data's URDFs too when ``erd``), and
    every scene is run, animated (``trace``: the tip's path) and plotted; a TOML file of another
    kind in the folder is skipped with a note to ``log``.  An existing
    ``output`` is refused unless ``force``.  ``log`` takes each progress line.  Returns
    the ``pendverify.viz.review_folder.ReviewFolder`` (``report``, ``reviews``, ``index``,
    ``passed``).
    """
    from pendverify.viz.review_folder import write_review

    paths, skipped = _scene_files(scenes)
    samples, seed = _count("samples", samples), _count("seed", seed)
    erd, trace, force = _flag("erd", erd), _flag("trace", trace), _flag("force", force)
    for note in skipped:
        log(f"note: {note}")
    return write_review(paths, Path(output), samples, seed, erd, trace, log=log, force=force)


# --- the symbolic tools ----------------------------------------------------------------------------
def mutate(
    model: str | Path | None = None,
    urdf: str | Path | None = None,
    params: str | Path | None = None,
    *,
    samples: int | None = None,
    seed: int = DEFAULT_SEED,
    all_checks: bool = False,
    methods: tuple[str, ...] | None = None,
) -> list[MutationReport]:
    """Mutation sensitivity: ``pendverify mutate``.

    Every single-term mutant of the closed forms (of ``methods`` only, if given) is run
    through the checks on ``samples`` states (default ``DEFAULT_MUTATION_STATES``) drawn with
    ``seed``; ``all_checks`` runs every check on every mutant instead of stopping at the first
    that fails.  ``model``: None (both reference systems), a built-in model's name, or a
    model file (``.py``) with its ``urdf`` and ``params`` file.  One
    ``pendverify.symbolic.mutation_report.MutationReport`` per model.
    """
    from pendverify.symbolic.mutate import DEFAULT_MUTATION_STATES, run_mutation

    samples = DEFAULT_MUTATION_STATES if samples is None else _count("samples", samples)
    seed, all_checks = _count("seed", seed), _flag("all_checks", all_checks)
    methods = None if methods is None else tuple(methods)
    model_cls = None if model is None else load_model(model)
    if (model_cls is None or is_builtin(model_cls)) and (urdf is not None or params is not None):
        raise PendverifyError(
            "urdf and params go with a model file; built-in models use their default set and URDF"
        )
    urdf = None if urdf is None else _urdf_file_arg(urdf, "mutate")
    params = None if params is None else str(params)
    targets = select_targets(model_cls, urdf, params, erd_urdfs=False).targets
    return [run_mutation(t, samples, seed, all_checks, methods) for t in targets]


def compare_symbolic(model: ModelLike | None = None) -> list[SymbolicReport]:
    """Each closed form against the one SymPy derives from the model's energies by Lagrange's
    equations, term by term: ``pendverify sympy``.  ``model``: as ``load_model`` takes it, or
    None for both reference systems.  One ``pendverify.symbolic.compare.SymbolicReport`` per model."""
    from pendverify.symbolic.compare import compare

    classes = list(MODELS.values()) if model is None else [load_model(model)]
    return [compare(cls) for cls in classes]


class Equation(NamedTuple):
    """One closed form of a model as SymPy reads it."""

    method: str  # e.g. "mass_matrix"
    derived: str | None  # for a text model's derived closed form: how it is derived
    value: Any  # a SymPy expression or matrix


class ModelReading(NamedTuple):
    """A model as SymPy reads it: its class, its parameters' symbols and its equations, and for a
    LaTeX model the symbols its equations read by convention (``"\\theta_1 → theta1"``)."""

    model_cls: type[ClosedFormModel]
    parameters: tuple[str, ...]
    equations: list[Equation]
    conventions: tuple[str, ...] = ()

    def __repr__(self) -> str:
        methods = ", ".join(e.method for e in self.equations)
        head = f"<ModelReading {self.model_cls.name!r}: {len(self.equations)} closed forms ("
        return f"{head}{shortened(methods, REPR_LIMIT - len(head) - 40)}), {len(self.parameters)} parameters>"

    def _repr_html_(self) -> str:
        """Each closed form as SymPy reads it (its text; a derived one says how it is derived)."""
        rows = [(e.method, e.derived or "written", str(e.value)) for e in self.equations]
        return html_table(("closed form", "", "as SymPy reads it"), rows, f"model {self.model_cls.name}")


def read_model(model: ModelLike) -> ModelReading:
    """Each closed form of ``model`` (as ``load_model`` takes it) as SymPy reads it, to confirm
    the reading: ``pendverify show``."""
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.analytic.text_model import METHODS

    cls = load_model(model)
    sm = SymbolicModel.of(cls)
    spec = getattr(cls, "text_spec", None)
    derived = spec.derived if spec is not None else {}
    keys = {method: key for key, (method, _) in METHODS.items()}
    equations = [
        Equation(method, derived.get(keys.get(method, "")) or None, sm.evaluate(method, form.args))
        for method, form in cls.written_closed_forms().items()
    ]
    conventions = tuple(spec.latex_conventions) if spec is not None else ()
    return ModelReading(cls, tuple(sm.parameters), equations, conventions)


def read_robot(description: str | Path) -> RobotSummary:
    """A robot description as Pinocchio will use it, each number with where it came from:
    ``pendverify show --robot`` (``pendverify.robot.summary``)."""
    from pendverify.robot.description import load_description
    from pendverify.robot.summary import robot_summary

    return robot_summary(load_description(_urdf_arg(description)))


# --- stress and benchmarks -------------------------------------------------------------------------
# REFUSE_REL (pendverify.checks.trust): the predicted relative error above which a result is refused,
# the bound the near-singular study of ``stress`` holds each quantity to.


def stress(
    model: str | Path | None = None,
    urdf: str | Path | None = None,
    params: str | Path | None = None,
    *,
    quick: bool = False,
    cases: list[str] | None = None,
    seed: int | None = None,
) -> StressReport:
    """The catalogue of numerically hard cases: ``pendverify stress``.

    ``model`` None runs the catalogue of the reference systems (``cases``: only these);
    a model file (``.py``) with its ``urdf`` and ``params`` file (None: the file's ``PARAMS``) runs
    the hard cases derived
    from its parameters' kinds.  ``quick``: fewer states and shorter horizons, same cases;
    ``seed``: the state sampler's (default ``pendverify.stress.framework.SEED``).
    """
    from pendverify.stress.catalogue import CASE_NAMES, run_catalogue
    from pendverify.stress.framework import FULL, QUICK, SEED

    settings = QUICK if _flag("quick", quick) else FULL
    seed = SEED if seed is None else _count("seed", seed)
    if model is not None:
        from pendverify.stress.generic import run_generic

        if urdf is None:
            raise PendverifyError(
                f"{model}: a model file needs its urdf (and params, unless the file gives PARAMS)"
            )
        params_file = None if params is None else str(params)
        return run_generic(str(model), _urdf_file_arg(urdf, "stress"), params_file, settings, cases, seed)
    if urdf is not None or params is not None:
        raise PendverifyError("urdf and params go with a model file")
    for name in cases or ():
        if name not in CASE_NAMES:
            raise UnknownNameError("stress case", name, CASE_NAMES)
    return run_catalogue(settings, names=cases, seed=seed)


def bench_accuracy(
    quick: bool = False, scene: str | Path | None = None, *, log=print, blas: str = "not limited"
) -> Results:
    """The work–precision benchmark: ``pendverify bench accuracy``.

    Error against wall time for each integrator and engine, on the two reference systems'
    problems, or with ``scene`` on a user's scene (``pendverify.bench.problems.scene_problems``
    says which problems, and refuses what the benchmark cannot run).  ``quick``: fewer
    tolerances and shorter runs.  ``log`` takes each progress line; ``blas`` says how BLAS
    was limited, for the report.  Returns ``pendverify.bench.run.Results``.
    """
    from pendverify.bench.problems import scene_problems
    from pendverify.bench.run import run_benchmark
    from pendverify.bench.workprecision import FULL, QUICK

    config, specs = QUICK if _flag("quick", quick) else FULL, None
    if scene is not None:
        config, specs = scene_problems(str(scene), config)
    return run_benchmark(config, log=log, blas=blas, specs=specs)


def bench_certify(
    params: list[str] | None = None,
    quick: bool = False,
    repeats: int | None = None,
) -> tuple[list[SetCost], BatterySettings, int]:
    """The certification battery's cost per parameter set on one core: ``pendverify bench certify``.

    ``params``: parameter files (default: each built-in model's own set).  ``quick``: 100
    states and short simulations; ``repeats`` runs per figure, least kept (default 7, 1 with
    ``quick``).  Returns (the costs, the battery settings measured, the repeats).
    """
    from pendverify.bench.certify import measure, quick_settings
    from pendverify.certify.battery import BatterySettings

    settings = quick_settings() if _flag("quick", quick) else BatterySettings()
    repeats = repeats or (1 if quick else 7)
    return measure(params, settings, repeats), settings, repeats


def bench_explain(quick: bool = False):
    """The diagnosis on the corpus of planted errors in every shipped model: ``pendverify bench explain``.

    ``quick``: a seeded sample of up to 2 planted errors per operator and model instead of all.
    Returns ``pendverify.bench.explain.ExplainBench`` (its scores per model file).
    """
    from pendverify.bench.explain import run_explain_bench

    return run_explain_bench(_flag("quick", quick))


# --- certificates ----------------------------------------------------------------------------------
def certify_set(
    output: str | Path,
    params: str | Path | None = None,
    *,
    urdf: UrdfLike | None = None,
    model: str | None = None,
    urdf_params: str | Path | None = None,
    analytic: str | Path | None = None,
    key: str | Path | None = None,
    samples: int | None = None,
    seed: int | None = None,
    force: bool = False,
    export: str | None = None,
) -> Issued:
    """Run the full battery and, if every item passes, write a certificate bundle into ``output``.

    As ``pendverify certify``: a parameter file ``params``; or a ``urdf`` (a path or
    ``erd:NAME``) with ``urdf_params`` (the set it must match) or a built-in ``model``
    whose parameters are read off the URDF; or a model file ``analytic`` with its
    ``urdf`` and ``urdf_params`` (the certificate then embeds the file's text).
    A ``urdf`` given as a Pinocchio object is certified with the URDF text it came with
    (``PinocchioRobot(model, urdf_text=...)``), which must build that very model; without
    one it is refused (a certificate embeds its URDF).
    ``key``: an Ed25519 private key file (``pendverify keygen``) that signs it.
    ``export``: a language of ``export`` (``"c"``, ``"matlab"``, ``"numpy"``): the model's code,
    verified against the set's URDF, is added to the bundle, its banner naming the certificate's
    digest; it needs ``key``, whose signature covers those files (``recheck`` refuses an edited one).
    Returns the issued result (``items``, ``certified``, ``certificate``, ``path``).
    (Not ``certify``: that name is the ``pendverify.certify`` sub-package.)
    """
    from pendverify.certify.battery import BatterySettings
    from pendverify.certify.issue import certification_input, issue
    from pendverify.certify.signing import load_private_key

    settings = BatterySettings()
    if samples is not None:
        settings = dataclasses.replace(settings, samples=_count("samples", samples))
    if seed is not None:
        settings = dataclasses.replace(settings, seed=_count("seed", seed))
    target = certification_input(
        None if params is None else str(params),
        None if urdf is None else _urdf_arg(urdf),
        model,
        None if urdf_params is None else str(urdf_params),
        None if analytic is None else str(analytic),
    )
    signer = None if key is None else load_private_key(key)  # a bad key fails before any work
    exporter = None if export is None else _certificate_exporter(target, export, signer)
    return issue(target, settings, str(output), force, key=signer, exporter=exporter)


def _certificate_exporter(target, lang: str, signer):
    """``certify --export LANG``: the certificate → the model's code, verified (else refused)."""
    # deferred on purpose: SymPy's code printers load only when code is exported
    from pendverify.export.files import LANGUAGES, exported_files
    from pendverify.export.verification import VERIFIED

    if lang not in LANGUAGES:
        raise InputError(OPTIONS_SOURCE, "export", lang, f"one of {', '.join(LANGUAGES)}")
    if signer is None:
        raise PendverifyError(
            "certify --export: give --key as well: the exported code is covered by the bundle's "
            "signature, which is how recheck tells an edited file"
        )

    def exporter(cert: dict) -> dict[str, str]:
        files, verification = exported_files(
            target.model.load(),
            lang,
            check,
            urdf=target.urdf,
            params=target.params.as_dict(),
            certificate=cert["digest"]["value"],
        )
        if verification.status != VERIFIED:
            raise PendverifyError(
                f"certify --export {lang}: the exported code is not verified: {verification.line}"
            )
        return files

    return exporter


class SweepCertificates(NamedTuple):
    """What ``sweep`` did: the run (``pendverify.certify.sweep_run.SweepRun``: its summary, the
    bundles written and kept, whether it stopped or was interrupted) and how many of the sweep's
    certificates are in the output folder after a run that finished (None after one that did not)."""

    run: SweepRun
    present: int | None


def sweep(
    sweep_file: str | Path,
    output: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    worker_timeout: float = WORKER_TIMEOUT_S,
    resume: bool = False,
    max_sets: int = DEFAULT_MAX_SETS,
    key: str | Path | None = None,
    force: bool = False,
    log=print,
) -> SweepCertificates:
    """Certify every parameter set of a sweep file in parallel: ``pendverify certify --sweep``.

    The sets run on ``workers`` local processes (default one per core) or on the Dask cluster
    at ``scheduler`` (``tcp://HOST:PORT``; the sweep stops when it has had no worker for
    ``worker_timeout`` seconds); each passing set's bundle is written into ``output`` as its
    result arrives (signed by ``key``, an Ed25519 private key file).  A sweep of more than
    ``max_sets`` sets is refused before any runs; existing files are refused unless ``force``,
    or with ``resume`` the sets certified there already (digests checked) are kept and the rest
    computed.  ``log`` takes the line saying which certified sets are recomputed to be signed.
    """
    from pendverify.certify.issue import check_sweep_names, write_sweep_certificates
    from pendverify.certify.signing import load_private_key
    from pendverify.certify.sweep import load_sweep
    from pendverify.certify.sweep_output import SameFolder, certificates_in, prepare_output
    from pendverify.certify.sweep_run import Workers, run_sweep

    resume, force = _flag("resume", resume), _flag("force", force)
    workers = None if workers is None else _at_least_one("workers", workers)
    max_sets = _at_least_one("max_sets", max_sets)
    if isinstance(worker_timeout, bool) or not isinstance(worker_timeout, (int, float)):
        raise InputError(OPTIONS_SOURCE, "worker_timeout", worker_timeout, "must be a finite number > 0")
    if not 0 < worker_timeout < math.inf:
        raise InputError(OPTIONS_SOURCE, "worker_timeout", worker_timeout, "must be a finite number > 0")
    loaded = load_sweep(sweep_file, max_sets)
    check_sweep_names(loaded, str(sweep_file))
    signer = None if key is None else load_private_key(key)  # a bad key fails before any work
    state = prepare_output(loaded, output, force, resume, signer)
    if state.resigned:
        log(
            f"{len(state.resigned)} set(s) certified in {output} but not signed by --key "
            "(unsigned, or signed by another key): recomputed and signed"
        )
    folder = SameFolder(output)

    def write(result, replace: bool) -> int:
        folder.check()
        try:
            written = write_sweep_certificates(loaded, [result], output, force or replace, signer)
        except PendverifyError:  # a write that failed because the folder went away says so
            folder.check()
            raise
        folder.wrote()
        return written

    run = run_sweep(loaded, Workers(scheduler, workers, worker_timeout), write, state.done, state.partial)
    finished = not (run.lost or run.interrupted)
    return SweepCertificates(run, certificates_in(loaded, output) if finished else None)


def recheck(
    certificate: str | Path, trust: str | Path | None = None, run_embedded_code: bool = False
) -> Rechecked:
    """Verify a certificate's digest (and signature, against ``trust``: a public key file) and
    re-run its battery: ``pendverify recheck``.  A certificate's embedded Python model runs
    only when ``trust`` vouches for it or ``run_embedded_code``.  Returns the
    ``pendverify.certify.issue.Rechecked`` (``items``, ``differences``, ``signature``, ``passed``)."""
    from pendverify.certify.issue import recheck as recheck_certificate

    trust = None if trust is None else str(trust)
    return recheck_certificate(str(certificate), trust, _flag("run_embedded_code", run_embedded_code))


def generate_keys(folder: str | Path, force: bool = False) -> tuple[Path, Path, str]:
    """Write an Ed25519 key pair for signing certificates into ``folder``: ``pendverify keygen``.
    Returns (the private key's path, the public key's path, the fingerprint)."""
    from pendverify.certify.signing import generate_keys as write_key_pair

    return write_key_pair(folder, _flag("force", force))


# --- worked examples -------------------------------------------------------------------------------
def export(
    model: ModelLike,
    lang: str | None,
    output: str | Path,
    urdf: UrdfLike | None = None,
    params: ParamsLike | None = None,
    *,
    casadi: bool = False,
    force: bool = False,
):
    """Write a model's closed forms as code, verified: ``pendverify export`` (docs/commands/export.md).

    ``lang`` is ``"c"`` (``NAME.h``, ``NAME.c``), ``"matlab"`` (one ``.m`` function per quantity
    and their declaration), ``"numpy"`` (a NumPy-functions model file) or None; ``casadi`` adds
    ``NAME_casadi.py``, the quantities as CasADi ``Function`` objects (the ``casadi`` package must be
    installed).  The files go into the folder ``output`` (existing ones are replaced only with
    ``force``: otherwise nothing is written).  Before they are written each language's code is read
    back as a model and checked against ``urdf`` with ``params``
    (``pendverify.export.verification``); each result's ``verification`` says how, and its line is
    in every file's banner.  Returns one ``ExportResult`` per language, ``lang``'s first.
    """
    # deferred on purpose: SymPy's code printers load only when code is exported
    from pendverify.export.files import export_model

    langs = (*([] if lang is None else [lang]), *(["casadi"] if _flag("casadi", casadi) else []))
    if not langs:
        raise InputError(OPTIONS_SOURCE, "lang", lang, "a language (c, matlab, numpy), or casadi=True")
    model_cls = load_model(model)
    if urdf is not None:
        urdf = _urdf_arg(urdf)
    return export_model(
        model_cls, langs, Path(output), check, urdf=urdf, params=params, force=_flag("force", force)
    )


def worked_examples() -> tuple[WorkedExample, ...]:
    """The worked examples installed with pendverify (``pendverify example``)."""
    from pendverify.worked_examples import EXAMPLES

    return EXAMPLES


def worked_example(name: str) -> WorkedExample:
    """The worked example called ``name`` (an error listing the names if none is)."""
    from pendverify.worked_examples import find_example

    return find_example(name)


def copy_example(name: str, folder: str | Path, force: bool = False) -> list[Path]:
    """Copy the worked example ``name`` into ``folder`` (created if missing), each file at the path
    the manual names it by (``urdf/double_pendulum.urdf``), ready to run; a file already there with
    the same content is left as it is, one with other content refused unless ``force``.  The paths
    written, in the catalogue's order."""
    from pendverify.worked_examples import copy_example as copy_files

    return copy_files(worked_example(name), Path(folder), force=_flag("force", force))
