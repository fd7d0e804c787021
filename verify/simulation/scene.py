"""Scene files: what to simulate, and which effects are switched on.

A scene is a TOML file::

    name = "Damped double pendulum"
    model = "double_pendulum"   # a built-in model, or a model file relative to the scene
                                # ("../examples/cart_pole.py", see pendverify.analytic.plugin)
    params = "default"          # "default" (built-in models only), a parameter file relative
                                # to the scene, or an inline [parameters] table instead
    # urdf = "cart_pole.urdf"   # relative to the scene: the URDF ABA integrates; required for
                                # aba/both with a model file, else the project writes the URDF
    engine = "aba"              # aba (Pinocchio, default) | closed_form | both

    [initial]
    q = [1.2, -0.4]             # model coordinates (rad, m), as in the model's docstring
    v = [0.0, 0.0]              # rates (rad/s, m/s); zeros when omitted

    [time]
    duration = 10.0             # s, > 0
    sample_rate = 100.0         # Hz of the output samples, > 0

    [integrator]
    method = "DOP853"           # RK45 | RK23 | DOP853 | Radau | BDF | LSODA (adaptive) | rk4 (fixed step)
    rtol = 1e-10                # adaptive methods
    atol = 1e-10
    # max_steps = 100000        # adaptive methods: the most steps the run may take (the default)
    # step = 1e-3               # rk4 only, s

    [effects]                   # every effect is off unless turned on here
    gravity = true              # true (the parameter set's g), false, or a value in m/s²
    damping = true              # true (the model's damping_matrix()), false, or a list: diag(D)
    [effects.actuation]         # u: see pendverify.simulation.effects for every type and its keys
    type = "sine"
    amplitude = [0.5, 0.0]
    frequency = 0.5
    [effects.disturbance]       # w, models with disturbances (W): impulse | step | noise
    type = "impulse"
    time = 1.0
    impulse = [2.0, 0.0, 0.0]

Every error names the file, the key, the value and the expected type or range.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pendverify.analytic import MODELS, ClosedFormModel, ParameterSet
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import check_model_outputs, load_model_class, plugin_parameters
from pendverify.documents import read_toml
from pendverify.errors import InputError, PendverifyError, SceneError
from pendverify.file_kinds import expect_kind
from pendverify.simulation.effects import parse_actuation, parse_disturbance
from pendverify.simulation.engine_names import SCENE_ENGINE_CHOICES
from pendverify.simulation.laws import Law
from pendverify.simulation.limits import DEFAULT_MAX_STEPS, check_scene_work
from pendverify.simulation.scene_reader import TableReader

#: the smallest rtol scipy's solve_ivp honours (it raises a smaller one to this, with a warning)
MIN_RTOL = 100 * 2.220446049250313e-16

ADAPTIVE_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
FIXED_STEP_METHODS = ("rk4",)
TOP_KEYS = (
    "name",
    "model",
    "params",
    "parameters",
    "urdf",
    "engine",
    "initial",
    "time",
    "integrator",
    "effects",
)


@dataclass(frozen=True)
class Integrator:
    method: str
    rtol: float = 1e-9
    atol: float = 1e-9
    step: float | None = None
    max_steps: int = DEFAULT_MAX_STEPS  # adaptive methods: their accepted steps over the whole run

    @property
    def adaptive(self) -> bool:
        return self.method in ADAPTIVE_METHODS

    def describe(self) -> str:
        if self.adaptive:
            return f"{self.method} (rtol {self.rtol:g}, atol {self.atol:g})"
        return f"{self.method} (step {self.step:g} s)"


@dataclass(frozen=True)
class Scene:
    """A simulation scene as read from its TOML: the model and its parameters, the initial state,
    the time span, the integrator and the effects it calls for (each None when off)."""

    name: str
    source: str
    model: str  # the model's name (a built-in name, or the plug-in class's ``name``)
    params: ParameterSet
    params_source: str
    engine: str
    q0: np.ndarray
    v0: np.ndarray
    duration: float
    sample_rate: float
    integrator: Integrator
    gravity: float | None  # m/s², None when off
    damping: np.ndarray | None  # D's diagonal, None when off (the full D: ``damping_matrix``)
    actuation: Law | None  # u(t, q, q̇), None when off
    disturbance: Law | None  # w(t), None when off
    model_cls: type[ClosedFormModel] | None = None  # None: MODELS[model]
    model_file: str | None = None  # the model file of a plug-in, None when built in
    urdf: str | None = None  # the scene's URDF (path), None: the project writes it (built-in)
    #: D as a matrix: the model's damping_matrix() (damping = true; a triple pendulum's joint
    #: friction couples its absolute angles), or diag(damping); None when off
    damping_matrix: np.ndarray | None = None

    def __post_init__(self):
        if self.model_cls is None:
            object.__setattr__(self, "model_cls", MODELS[self.model])
        if self.damping_matrix is None and self.damping is not None:
            object.__setattr__(self, "damping_matrix", np.diag(self.damping))

    @property
    def conservative(self) -> bool:
        return self.damping is None and self.actuation is None and self.disturbance is None

    def __repr__(self) -> str:
        effects = [
            name
            for name, value in (
                ("gravity", self.gravity),
                ("damping", self.damping),
                ("actuation", self.actuation),
                ("disturbance", self.disturbance),
            )
            if value is not None
        ]
        return (
            f"<Scene {self.name!r} ({self.model}): engine {self.engine}, {self.duration:g} s at "
            f"{self.sample_rate:g} Hz, {self.integrator.method}, effects: {', '.join(effects) or 'none'}>"
        )


def _parameters(
    top: TableReader, model_cls, scene_path: Path, model_file: str | None
) -> tuple[ParameterSet, str]:
    model = model_cls.name
    if top.has("parameters"):
        if top.has("params"):
            top.fail("params", top.get("params"), "give either params or [parameters], not both")
        table = top.sub("parameters")
        return model_cls.params_type.from_mapping(table.table, top.source, "parameters."), "inline"
    if model_file is not None:
        ref = top.string("params", default=None) if top.has("params") else None
        if (ref is None or ref == "default") and model_cls.default_params is not None:
            return model_cls.default_params, f"{model_file} (PARAMS)"
        if ref is None or ref == "default":
            top.fail(
                "params", ref, "a model file has no default parameter set: give params = FILE or [parameters]"
            )
        path = scene_path.parent / ref
        if not path.is_file():
            top.fail("params", ref, f"parameter file not found (looked for {path})")
        return plugin_parameters(model_cls, model_file, str(path)), str(path)
    ref = top.string("params", default="default")
    path = default_parameter_file(model) if ref == "default" else (scene_path.parent / ref)
    if ref != "default" and not path.is_file():
        top.fail("params", ref, f"parameter file not found (looked for {path})")
    file_model, _, params = load_parameter_file(path)
    if file_model != model:
        top.fail("params", ref, f"that parameter file is for model {file_model!r}, the scene is {model!r}")
    return params, str(path)


def _model(top: TableReader, scene_path: Path) -> tuple[type[ClosedFormModel], str | None]:
    """(model class, model file or None): a built-in name, or a ``.py`` file relative to the scene.

    A document built in code (the certification battery's) may give the class itself.
    """
    value = top.get("model")
    if isinstance(value, type) and issubclass(value, ClosedFormModel):
        return value, None
    if isinstance(value, str) and value.endswith((".py", ".toml")):
        path = scene_path.parent / value
        if not path.is_file():
            top.fail("model", value, f"model file not found (looked for {path})")
        try:
            return load_model_class(path), str(path)
        except PendverifyError as exc:
            top.fail("model", value, f"not a usable model file: {exc}")
    return MODELS[top.string("model", tuple(MODELS))], None


def _urdf(top: TableReader, scene_path: Path) -> str | None:
    """The scene's URDF (relative to the scene), or None; whether one is needed is decided when
    the engine is known (``pendverify.simulation.dynamics``: ``simulate --engine`` may override it)."""
    if not top.has("urdf"):
        return None
    ref = top.string("urdf")
    path = scene_path.parent / ref
    if not path.is_file():
        top.fail("urdf", ref, f"URDF file not found (looked for {path})")
    return str(path)


def parse_scene(data: dict, source: str, base: Path | None = None) -> Scene:
    """Validate a scene document (already parsed TOML) into a Scene."""
    top = TableReader(data, source)
    top.only(TOP_KEYS)
    scene_path = base or Path(source)
    model_cls, model_file = _model(top, scene_path)
    if not model_cls.has_mass_matrix:
        top.fail(
            "model",
            top.get("model"),
            f"{model_cls.__name__} gives q̈ alone (no M, H, V): a scene's invariants (energy, momentum) "
            "need them; check q̈ with pendverify check instead",
        )
    model = model_cls.name
    n = len(model_cls.coordinates)
    params, params_source = _parameters(top, model_cls, scene_path, model_file)
    if not hasattr(params, "g"):
        top.fail(
            "model", top.get("model"), f"the {model} parameter set has no g; a scene sets gravity through g"
        )
    name = top.string("name", default=Path(source).stem)
    engine = top.string("engine", SCENE_ENGINE_CHOICES, default="aba")
    urdf = _urdf(top, scene_path)

    initial = top.sub("initial")
    initial.only(("q", "v"))
    q0 = initial.vector("q", n)
    v0 = initial.vector("v", n, default=[0.0] * n)

    time = top.sub("time")
    time.only(("duration", "sample_rate"))
    duration = time.number("duration", positive=True)
    sample_rate = time.number("sample_rate", default=100.0, positive=True)

    integ = top.sub("integrator")
    integ.only(("method", "rtol", "atol", "step", "max_steps"))
    method = integ.string("method", ADAPTIVE_METHODS + FIXED_STEP_METHODS)
    if method in ADAPTIVE_METHODS:
        if integ.has("step"):
            integ.fail("step", integ.get("step"), f"{method} is adaptive: give rtol and atol, not step")
        rtol = integ.number("rtol", default=1e-9, positive=True)
        if rtol < MIN_RTOL:
            integ.fail("rtol", integ.get("rtol"), f"expected rtol >= {MIN_RTOL:.3g} (100 × double's epsilon: "
                       "scipy's adaptive methods go no lower)")  # fmt: skip
        atol = integ.number("atol", default=rtol, positive=True)
        max_steps = integ.number("max_steps", default=DEFAULT_MAX_STEPS, minimum=1)
        if max_steps != int(max_steps):
            integ.fail("max_steps", integ.get("max_steps"), "expected a whole number of steps >= 1")
        integrator = Integrator(method, rtol, atol, max_steps=int(max_steps))
    else:
        for key in ("rtol", "atol", "max_steps"):
            if integ.has(key):
                integ.fail(key, integ.get(key), f"{method} has a fixed step: give step, not {key}")
        step = integ.number("step", positive=True)
        if step > duration:
            integ.fail("step", step, f"expected a step <= the duration ({duration:g} s)")
        integrator = Integrator(method, step=step)
    check_scene_work(source, duration, sample_rate, integrator.step, 2 * n)

    effects = top.sub("effects", required=False) or TableReader({}, source, "effects.")
    effects.only(("gravity", "damping", "actuation", "disturbance"))
    g = effects.boolean_or_number("gravity")
    gravity = params.g if g is True else (None if g is False else g)
    damping_value = effects.get("damping", False)
    damping_matrix = None
    if isinstance(damping_value, bool):
        if damping_value:
            damping_matrix = np.array(model_cls(params).damping_matrix(), dtype=float).reshape(n, n)
        damping = np.diag(damping_matrix).copy() if damping_value else None
    else:
        damping = effects.vector("damping", n, minimum=0.0)
    actuation = parse_actuation(
        effects.sub("actuation", required=False), model_cls, params.replace(g=gravity or 0.0)
    )
    disturbance = parse_disturbance(effects.sub("disturbance", required=False), model_cls)
    if model_file is not None:
        check_model_outputs(model_cls(params))
    return Scene(
        name=name,
        source=source,
        model=model,
        params=params,
        params_source=params_source,
        engine=engine,
        q0=q0,
        v0=v0,
        duration=duration,
        sample_rate=sample_rate,
        integrator=integrator,
        gravity=gravity,
        damping=damping,
        actuation=actuation,
        disturbance=disturbance,
        model_cls=model_cls,
        model_file=model_file,
        urdf=urdf,
        damping_matrix=damping_matrix,
    )


def load_scene(path: str | Path) -> Scene:
    path = Path(path)
    try:
        data = read_toml(path, "scene file")
    except InputError as exc:
        raise SceneError(exc.source, exc.key, exc.value, exc.rule) from None
    expect_kind(data, path, "scene")
    return parse_scene(data, str(path), path)
