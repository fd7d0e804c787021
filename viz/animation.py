"""A trajectory as a meshcat animation in one self-contained HTML file.

Pipeline: the trajectory's samples (t, θ) are resampled to ``fps`` frames per
second on the trajectory's own time base (linear interpolation; the shipped
scenes sample at 100 Hz, so 50 fps keeps every other sample exactly), every
frame is posed by Pinocchio (``VisualSystem.placements``), and the poses become
keyframes of a meshcat ``Animation`` whose clip rate is the same ``fps``:
frame k is shown at t = k/fps, i.e. in real time.  Every clip spans the whole
duration, so the looping clips stay in step.

Camera: a perspective camera (``FOV_DEG``) looks at the plane of motion face on
(``VisualSystem.view_normal``: along the hinge axis for the double pendulum,
across the rail for the cart, rail to the right).  It is aimed at the centre of
the box swept by the moving parts over the whole run (the model is shifted so
that this centre sits at the viewer's origin, where meshcat's orbit controls
aim) and backed off until that box, with ``MARGIN``, fits a viewport at least
``MIN_ASPECT`` wide.  The world's
static parts (the cart's rail) are drawn but not framed.  Grid and axes are
hidden and the background is plain light grey, so the model's colours stand out.

Tip trace (optional): the path of the far end of the last rod, cut into short
lines that appear as the tip passes them, so the trace grows with the motion.

Size: the three.js viewer bundle (0.85 MB) dominates.  Only the visuals on a
moving joint get keys (position + quaternion, float32), about 18 kB per second
of animation for the double pendulum: a 10 s run is 1.04 MB (1.24 MB with the
trace).  Each mesh is sent once, whatever the number of frames.

Bounded work: an animation has at most ``PENDVERIFY_MAX_FRAMES`` frames (default
``DEFAULT_MAX_FRAMES``, 30 min at 50 fps); a longer one is refused, naming the times and the
limit, before any frame is computed.  A saved run's arrays are bounded before they are loaded
(``pendverify.viz.saved_run``), and a saved run never imports the Python model file its
metadata names (``Trajectory.from_npz``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import meshcat.geometry as mg
import meshcat.transformations as tf
import numpy as np
from meshcat.animation import Animation

from pendverify.analytic import MODELS, PARAMETER_TYPES, ParameterSet
from pendverify.analytic.plugin import load_model_class
from pendverify.display import html_fields, shortened
from pendverify.errors import TrajectoryError, folder_given, missing_file
from pendverify.simulation.limits import environment_limit
from pendverify.viz.geometry import ROOT, UP, VisualSystem
from pendverify.viz.recorder import SceneRecorder
from pendverify.viz.saved_run import read_saved_arrays

DEFAULT_FPS = 50.0
FPS_RANGE = (30.0, 60.0)
FOV_DEG = 30.0
MARGIN = 1.15
MIN_ASPECT = 4.0 / 3.0
BACKGROUND = [0.94, 0.94, 0.94]
TRACE_COLOUR = 0x5B2C83  # dark purple: unlike every URDF material
TRACE_CHUNK_S = 0.05  # s of motion per trace segment (at most MAX_TRACE_CHUNKS)
MAX_TRACE_CHUNKS = 200
REPETITIONS = 1_000_000  # loop for as long as anyone watches
MAX_FRAMES_VARIABLE = "PENDVERIFY_MAX_FRAMES"
#: 30 min at 50 fps: a page of about 35 MB, built in about 0.6 GB and 20 s (measured: 60 000 frames
#: of the double pendulum, 22 MB, 0.4 GB, 14 s)
DEFAULT_MAX_FRAMES = 90_000
TITLE_WIDTH = 80  # characters of a saved run's scene name kept as its title
FRAGMENT_WIDTH = 60  # characters of a metadata value quoted in a message


@dataclass(frozen=True)
class Trajectory:
    """What is rendered: sample times in [s], model coordinates θ, the parameter set, a title."""

    t: np.ndarray
    q: np.ndarray
    params: ParameterSet
    title: str
    source: str = "<run>"
    #: the model class (None: the built-in ``MODELS[params.model]``) and the URDF to draw
    #: (path or text; None: the one ``urdf_for(params)`` writes, built-in models only)
    model_cls: type | None = None
    urdf: str | None = None
    #: what reading a saved run noticed (printed by ``render``)
    notes: tuple[str, ...] = ()

    def __repr__(self) -> str:
        span = f"{len(self.t)} samples over {self.t[-1] - self.t[0]:g} s" if len(self.t) else "no samples"
        where = shortened(self.source, 80)
        title = shortened(self.title, 80)
        return f"<Trajectory {title}: {span}, {self.q.shape[1]} coordinates, from {where}>"

    def _repr_html_(self) -> str:
        fields = [
            ("samples", len(self.t)),
            ("duration [s]", f"{self.t[-1] - self.t[0]:g}"),
            ("coordinates", self.q.shape[1]),
            ("source", self.source),
            *(("note", n) for n in self.notes),
        ]
        return html_fields(self.title, fields)

    def __post_init__(self) -> None:
        if self.t.ndim != 1 or len(self.t) < 2:
            raise TrajectoryError(self.source, "t", self.t.shape, "expected at least two sample times")
        if self.q.ndim != 2 or self.q.shape[0] != len(self.t):
            raise TrajectoryError(
                self.source, "q", self.q.shape, f"expected {len(self.t)} rows, one per time"
            )
        if self.model_cls is None:
            object.__setattr__(self, "model_cls", MODELS[self.params.model])
        n = len(self.model_cls.coordinates)
        if self.q.shape[1] != n:
            raise TrajectoryError(
                self.source, "q", self.q.shape, f"expected {n} columns for {self.params.model}"
            )
        if not (np.all(np.isfinite(self.t)) and np.all(np.isfinite(self.q))):
            raise TrajectoryError(self.source, "q", "…", "expected finite numbers")
        if not np.all(np.diff(self.t) > 0):
            raise TrajectoryError(self.source, "t", "…", "expected strictly increasing times")

    @classmethod
    def from_run(cls, run) -> Trajectory:
        """A ``pendverify.simulation.simulate.Run``."""
        s = run.scene
        return cls(
            np.asarray(run.t), np.asarray(run.q), s.params, s.name, s.source, s.model_cls, run.dynamics.urdf
        )

    @classmethod
    def from_npz(cls, path: str | Path, analytic: str | Path | None = None) -> Trajectory:
        """A file of ``pendverify simulate -o FILE.npz``: t, q, and the metadata's model and parameters.

        The file is data: a run of a Python model file is drawn only with that file given as
        ``analytic`` (``render --analytic FILE``), never by importing what the metadata names;
        a text model (``.toml``) the metadata names is read, as it runs nothing.
        """
        path = Path(path)
        source = str(path)
        if path.is_dir():
            raise folder_given(path, "saved run (.npz)")
        if not path.is_file():
            raise missing_file(path, "saved run (.npz)", "`pendverify simulate SCENE -o FILE.npz` saves one")
        t, q, meta = read_saved_arrays(path, source)
        if not isinstance(meta, dict):
            raise TrajectoryError(source, "metadata", type(meta).__name__, "must be a JSON object")
        model_cls, param_type, notes = _saved_model(meta, source, analytic)
        urdf = meta.get("urdf")
        if urdf is not None and not isinstance(urdf, str):
            raise TrajectoryError(source, "metadata.urdf", _fragment(urdf), "must be a file name")
        if model_cls is not None and urdf is None:
            raise TrajectoryError(source, "metadata.urdf", None, "a model file's run needs its URDF")
        parameters = meta.get("parameters", {})
        if not isinstance(parameters, dict):
            raise TrajectoryError(
                source, "metadata.parameters", _fragment(parameters), "must be a JSON object"
            )
        params = param_type.from_mapping(parameters, source, "metadata.parameters.")
        t, q = _samples(source, t, q)
        title = shortened(str(meta.get("scene", path.stem)), TITLE_WIDTH)
        return cls(t, q, params, title, source, model_cls, urdf, tuple(notes))


def _saved_model(meta: dict, source: str, analytic: str | Path | None) -> tuple[type | None, type, list[str]]:
    """(model class or None for a built-in one, its parameter type, notes) of a saved run.

    A Python model file named by ``metadata.model_file`` is not imported: ``analytic`` (the
    user's ``--analytic FILE``) is loaded instead, and must define the model the run names.
    """
    model, model_file = meta.get("model"), meta.get("model_file")
    if model_file is None:
        if analytic is not None:
            raise TrajectoryError(
                source,
                "metadata.model_file",
                None,
                f"the run is of the built-in model {_fragment(model)!r}; --analytic is for a run of a model "
                "file",
            )
        if model not in PARAMETER_TYPES:
            known = ", ".join(PARAMETER_TYPES)
            raise TrajectoryError(
                source, "metadata.model", _fragment(model), f"expected one of {known} or a model_file"
            )
        return None, PARAMETER_TYPES[model], []
    if not isinstance(model_file, str) or not model_file or "\0" in model_file:
        raise TrajectoryError(source, "metadata.model_file", _fragment(model_file), "must be a file name")
    named = Path(model_file)
    notes: list[str] = []
    if analytic is None:
        if named.suffix != ".toml":
            raise TrajectoryError(
                source,
                "metadata.model_file",
                _fragment(model_file),
                "the run is of a Python model file, and a saved run never runs code: give that file "
                "with --analytic FILE if you trust it",
            )
        model_cls = load_model_class(named)  # a text model is data: read, not run
    else:
        if Path(analytic).name != named.name:
            notes.append(
                f"the run names the model file {_fragment(model_file)}; drawn with --analytic {analytic}"
            )
        model_cls = load_model_class(analytic)
    if model_cls.name != model:
        raise TrajectoryError(
            source,
            "metadata.model",
            _fragment(model),
            f"the model file {analytic or model_file} defines the model {model_cls.name!r}, not the run's",
        )
    return model_cls, model_cls.params_type, notes


def _fragment(value: object) -> object:
    """A value of the metadata as a message quotes it: itself, or its text shortened."""
    if isinstance(value, str):
        return shortened(value, FRAGMENT_WIDTH)
    text = repr(value)
    return value if len(text) <= FRAGMENT_WIDTH else shortened(text, FRAGMENT_WIDTH)


def _samples(source: str, t, q) -> tuple[np.ndarray, np.ndarray]:
    """A saved run's t (finite, increasing) and q (one finite row per time), or a TrajectoryError."""
    try:
        t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise TrajectoryError(source, "t, q", None, "must be arrays of numbers") from None
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise TrajectoryError(source, "t", t.shape, "must be a non-empty vector of finite, increasing times")
    q = q.reshape(len(t), -1) if q.ndim == 1 and q.size % t.size == 0 else q
    if q.ndim != 2 or q.shape[0] != t.size or q.shape[1] == 0 or not np.all(np.isfinite(q)):
        raise TrajectoryError(source, "q", q.shape, f"must be {t.size} rows of finite coordinates, one per t")
    return t, q


def max_frames() -> int:
    """The limit on an animation's frames: ``PENDVERIFY_MAX_FRAMES``, else ``DEFAULT_MAX_FRAMES``."""
    return environment_limit(MAX_FRAMES_VARIABLE, DEFAULT_MAX_FRAMES, minimum=2)


def check_frames(traj: Trajectory, fps: float = DEFAULT_FPS) -> None:
    """Refuse a trajectory whose animation would have more frames than ``max_frames()``."""
    shown = f"{traj.t[0]:g} … {traj.t[-1]:g} s"
    check_frame_count(traj.source, "t", shown, float(traj.t[-1] - traj.t[0]), fps)


def check_frame_count(
    source: str, key: str, shown: object, duration: float, fps: float = DEFAULT_FPS
) -> None:
    """Refuse an animation of ``duration`` seconds at ``fps`` beyond ``max_frames()``, naming ``key``."""
    limit = max_frames()
    frames = duration * fps + 1  # a float: the count of a 1e300 s run overflows nothing
    if frames > limit:
        raise TrajectoryError(
            source,
            key,
            shown,
            f"{duration:g} s at {fps:g} frames per second ≈ {frames:.3g} frames exceed the limit of "
            f"{limit:g}; raise the limit with {MAX_FRAMES_VARIABLE}",
        )


def resample(t: np.ndarray, q: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Frames at t0 + k/fps for every k within the run, θ linearly interpolated."""
    n = math.floor((t[-1] - t[0]) * fps + 1e-9) + 1
    times = t[0] + np.arange(n) / fps
    frames = np.column_stack([np.interp(times, t, q[:, i]) for i in range(q.shape[1])])
    return times, frames


@dataclass(frozen=True)
class Camera:
    target: np.ndarray  # world point the camera orbits, in [m]
    position: np.ndarray  # camera position relative to the target, world axes, in [m]
    fov_deg: float


def frame_camera(points: np.ndarray, radii: np.ndarray, normal: np.ndarray) -> Camera:
    """Aim at the box swept by spheres (points, radii) and back off until it fits the view."""
    right = np.cross(UP, normal)
    axes = np.stack([right, UP, normal])
    local = points @ axes.T
    lo = (local - radii[:, None]).min(axis=0)
    hi = (local + radii[:, None]).max(axis=0)
    centre = (lo + hi) / 2
    half_w, half_h = (hi - lo)[:2] / 2
    half_fov = math.radians(FOV_DEG) / 2
    distance = MARGIN * max(half_h, half_w / MIN_ASPECT, 0.05) / math.tan(half_fov) + (hi[2] - centre[2])
    return Camera(centre @ axes, distance * normal, FOV_DEG)


def _to_camera_frame(v: np.ndarray) -> list[float]:
    """World axes (z up) to meshcat's ``/Cameras/default/rotated`` frame (y up)."""
    return [float(v[0]), float(v[2]), float(-v[1])]


def _set_camera(vis, camera: Camera) -> None:
    """Place the camera; the model moves so that the target sits at the viewer's origin.

    meshcat's orbit controls always aim at the world origin, so the whole model
    (node ``ROOT``) is shifted by −target instead of moving the camera's target.
    """
    vis[ROOT].set_transform(tf.translation_matrix(-camera.target))
    cam = vis["/Cameras/default/rotated/<object>"]
    cam.set_property("position", _to_camera_frame(camera.position))
    cam.set_property("fov", camera.fov_deg)
    vis["/Grid"].set_property("visible", False)
    vis["/Axes"].set_property("visible", False)
    vis["/Background"].set_property("top_color", BACKGROUND)
    vis["/Background"].set_property("bottom_color", BACKGROUND)


def _trace(vis, anim: Animation, tips: np.ndarray, fps: float) -> None:
    n = len(tips)
    per = max(round(TRACE_CHUNK_S * fps), math.ceil((n - 1) / MAX_TRACE_CHUNKS), 1)
    last = float(n - 1)
    material = mg.LineBasicMaterial(color=TRACE_COLOUR)
    for k, start in enumerate(range(0, n - 1, per)):
        stop = min(start + per, n - 1)
        path = f"{ROOT}/trace/{k:03d}"
        vis[path].set_object(mg.Line(mg.PointsGeometry(tips[start : stop + 1].T.copy()), material))
        clip = anim.at_frame(vis, 0)[path].get_clip()
        for frame, shown in ((0.0, False), (float(stop), True), (last, True)):
            clip.set_property(frame, "visible", "boolean", shown)


def _visual_system(traj: Trajectory) -> VisualSystem:
    if traj.urdf is not None:
        return VisualSystem.for_model(traj.model_cls, traj.urdf, getattr(traj.params, "g", None))
    if traj.params.model not in MODELS or MODELS[traj.params.model].params_type is not type(traj.params):
        raise TrajectoryError(
            traj.source,
            "urdf",
            None,
            f"{traj.params.model} is drawn from its URDF: give urdf = FILE in the scene, or --urdf",
        )
    return VisualSystem.from_params(traj.params)


def build_scene(traj: Trajectory, trace: bool = False, fps: float = DEFAULT_FPS) -> SceneRecorder:
    """Record the model, the camera and the animation of a trajectory (no server involved)."""
    return _record(traj, trace, fps)[0]


def _record(traj: Trajectory, trace: bool, fps: float) -> tuple[SceneRecorder, tuple[str, ...]]:
    """``build_scene``'s recorder and the notes of the visual system it drew."""
    if not FPS_RANGE[0] <= fps <= FPS_RANGE[1]:
        raise TrajectoryError(traj.source, "fps", fps, f"expected {FPS_RANGE[0]:g} to {FPS_RANGE[1]:g}")
    check_frames(traj, fps)
    visual = _visual_system(traj)
    recorder = SceneRecorder()
    vis = recorder.visualizer()
    visual.load_into(vis)
    times, frames = resample(traj.t, traj.q, fps)
    poses = np.array([visual.placements(theta) for theta in frames])  # (frames, objects, 4, 4)
    objects = visual.objects
    for i, obj in enumerate(objects):
        vis[visual.node(obj)].set_transform(poses[0, i])

    anim = Animation(default_framerate=fps)
    moving = [i for i, o in enumerate(objects) if o.parentJoint != 0]
    for k in range(len(times)):
        frame = anim.at_frame(vis, k)
        for i in moving:
            frame[visual.node(objects[i])].set_transform(poses[k, i])

    tip_index, tip_local = visual.tip_point()
    tips = poses[:, tip_index, :3, :3] @ tip_local + poses[:, tip_index, :3, 3]
    if trace:
        _trace(vis, anim, tips, fps)

    radii = np.array([visual.radius(objects[i]) for i in moving])
    points = poses[:, moving, :3, 3].reshape(-1, 3)
    all_radii = np.tile(radii, len(times))
    camera = frame_camera(
        np.vstack([points, tips]), np.concatenate([all_radii, np.zeros(len(tips))]), visual.view_normal()
    )
    _set_camera(vis, camera)
    vis.set_animation(anim, play=True, repetitions=REPETITIONS)
    return recorder, visual.notes


@dataclass(frozen=True)
class AnimationPage:
    """A rendered animation: the page's HTML and what drawing it noticed (e.g. a skeleton drawn)."""

    html: str
    notes: tuple[str, ...] = ()


def animation_page(traj: Trajectory, trace: bool = False, fps: float = DEFAULT_FPS) -> AnimationPage:
    """The self-contained HTML page that plays ``traj`` in real time, with the drawing's notes."""
    recorder, notes = _record(traj, trace, fps)
    duration = traj.t[-1] - traj.t[0]
    caption = f"{traj.title} — {traj.params.model}, {duration:g} s"
    return AnimationPage(recorder.html(f"{traj.title} (pendverify)", caption), notes)


def render_html(traj: Trajectory, trace: bool = False, fps: float = DEFAULT_FPS) -> str:
    """The self-contained HTML page that plays ``traj`` in real time."""
    return animation_page(traj, trace, fps).html
