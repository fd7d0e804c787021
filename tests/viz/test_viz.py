"""Browser animations and the review page: same model, real time, small, no server, plays in Chromium.

The browser tests open the rendered HTML from file:// in one headless Chromium
(DevTools over a pipe) and take screenshots at two moments of the animation's
clock: the model's colours (URDF materials, found by hue, so shading does not
matter) must cover a minimum area, the cart's rail must run across the view, the
model-coloured pixels must change between the two shots, and the animation's clock must run
at the page's clock's speed from frame to frame (so load on the machine does not enter it).
They skip only where no Chromium binary exists.
"""

from __future__ import annotations

import colorsys
import dataclasses
import itertools
import json
import os
import re
import time
from pathlib import Path

import numpy as np
import psutil
import pytest
import umsgpack
from PIL import Image

from pendverify.analytic import MODELS
from pendverify.analytic.reference_urdfs import COLOURS
from pendverify.checks.evidence import Evidence
from pendverify.checks.report import Report
from pendverify.cli import main
from pendverify.errors import TrajectoryError
from pendverify.robot.writer import urdf_for
from pendverify.simulation.scene import load_scene, parse_scene
from pendverify.simulation.simulate import run_scene
from pendverify.viz.animation import DEFAULT_FPS, Trajectory, build_scene, render_html
from pendverify.viz.geometry import LINK_COLOURS, VisualSystem
from pendverify.viz.plots import energy_plot_svg
from pendverify.viz.recorder import VIEWER_JS
from pendverify.viz.review import SceneReview, review_page
from tests.browser import Chromium, find_chromium

from ..conftest import default_params

REPO = Path(__file__).resolve().parents[2]
SHIPPED = sorted((REPO / "scenes").glob("*.toml"))
# scenes on a model file draw that file's URDF, which has none of the project URDFs' colours
PLUGIN_SCENES = [p for p in SHIPPED if load_scene(p).model_file is not None]
BUILT_IN_SCENES = [p for p in SHIPPED if p not in PLUGIN_SCENES]
MAX_HTML_BYTES = 2_000_000  # the goal for a 10 s animation
SHOT_SIZE = (800, 600)
CLOCK = "viewer.animator.actions[0].time"  # the animation's clock, in [s]
FIRST_SHOT_S = 0.5  # the first screenshot once the clock reads this; the second SHOT_GAP_S later
SHOT_GAP_S = 1.0
#: animation seconds per second of the page's clock, from frame to frame.  The viewer advances the
#: animation by its clock's time since the last frame (meshcat's ``Animator.update``) and
#: ``RECORD_FRAMES`` reads the page's clock in the same frame, so over the ≥ 0.5 s compared the two
#: differ by the order of one frame's script time (milliseconds): 1 within 10 % (``RATE_SLACK``) —
#: plus, where the two run in separate frame callbacks, one frame's advance (``RecordedRate.band``)
RATE_SLACK = 0.1
#: records, at every animation frame, the page's clock and the animation's [s]: the rate is measured
#: between frames, so how late the test reads them (on a loaded machine, seconds) does not enter it
RECORD_FRAMES = (
    "window.seen = []; (function record() { window.seen.push([performance.now() / 1000, "
    + CLOCK
    + "]); requestAnimationFrame(record); })(), 0"
)
HUE_TOL_DEG = 14.0
MIN_SATURATION, MIN_VALUE = 0.35, 0.2
MIN_LINK_PIXELS = 150  # each rod's colour, in an 800×600 shot (no other pixel has these hues)
MIN_CART_PIXELS = 300
MIN_RAIL_SPAN = 0.5  # the rail: one row of rail grey across at least half the width
MIN_MOVED_PIXELS = 300  # model-coloured pixels that change between the two shots

CHROMIUM = find_chromium()
# CI sets PENDVERIFY_REQUIRE_CHROMIUM=1: there a missing browser fails the tests instead of skipping them
_skip_without_chromium = pytest.mark.skipif(
    CHROMIUM is None and not os.environ.get("PENDVERIFY_REQUIRE_CHROMIUM"),
    reason="no chromium binary on PATH (Debian package `chromium`; .ci/run installs it)",
)


def needs_chromium(test):
    """A test that drives headless Chromium: marked ``browser`` (left out of the fast default run),
    skipped where no Chromium exists unless CI requires it."""
    return pytest.mark.browser(_skip_without_chromium(test))


def short_scene(model: str, duration: float = 1.0, **extra) -> dict:
    q = [0.4, 0.9] if model == "double_pendulum" else [0.0, 0.3, -0.2]
    doc = {
        "name": 'short <test> & "scene"',
        "model": model,
        "initial": {"q": q},
        "time": {"duration": duration, "sample_rate": 100.0},
        "integrator": {"method": "DOP853", "rtol": 1e-8, "atol": 1e-8},
        "effects": {"gravity": True},
    }
    doc.update(extra)
    return doc


def write_scene(path: Path, doc: dict) -> Path:
    lines = [f"name = {json.dumps(doc['name'])}", f'model = "{doc["model"]}"']
    for table, values in doc.items():
        if isinstance(values, dict):
            lines.append(f"[{table}]")
            lines += [f"{k} = {json.dumps(v)}" for k, v in values.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


def decoded(recorder) -> list[dict]:
    return [umsgpack.unpackb(c) for c in recorder.commands]


def hex_colour(rgba: str) -> int:
    r, g, b = (float(x) for x in rgba.split()[:3])
    return int(r * 255) * 256**2 + int(g * 255) * 256 + int(b * 255)


# --- same model, real time, size: no browser needed ---------------------------------------
@pytest.mark.parametrize("model", ["double_pendulum", "cart_double_pendulum"])
def test_every_urdf_visual_is_sent_once_with_its_colour(model):
    params = default_params(model)
    run = run_scene(parse_scene(short_scene(model), "<test>"))
    commands = decoded(build_scene(Trajectory.from_run(run)))
    objects = {c["path"]: c["object"] for c in commands if c["type"] == "set_object"}
    sent = [c["path"] for c in commands if c["type"] == "set_object"]
    assert len(sent) == len(set(sent)), f"an object is sent twice: {sent}"
    visual = VisualSystem.from_params(params)
    assert len(visual.objects) >= 5
    for obj in visual.objects:
        path = "/meshcat/" + visual.node(obj)
        assert path in objects, f"{model=}: {obj.name} not drawn"
        colour = objects[path]["materials"][0]["color"]
        assert colour == hex_colour(" ".join(str(x) for x in obj.meshColor)), f"{model=} {obj.name}"
    colours = {objects["/meshcat/" + visual.node(o)]["materials"][0]["color"] for o in visual.objects}
    wanted = {"link1", "link2"} | ({"cart", "rail"} if model == "cart_double_pendulum" else set())
    assert {hex_colour(COLOURS[k]) for k in wanted} <= colours, f"{model=}: a URDF material is missing"


@pytest.mark.parametrize("model", ["double_pendulum", "cart_double_pendulum"])
def test_keyframes_are_pinocchio_poses_in_real_time(model):
    run = run_scene(parse_scene(short_scene(model, duration=2.0), "<test>"))
    traj = Trajectory.from_run(run)
    commands = decoded(build_scene(traj))
    (anim,) = [c for c in commands if c["type"] == "set_animation"]
    visual = VisualSystem.from_params(traj.params)
    n_frames = round(2.0 * DEFAULT_FPS) + 1
    clips = {a["path"]: a["clip"] for a in anim["animations"]}
    assert {"/meshcat/" + visual.node(o) for o in visual.moving()} <= set(clips)
    for path, clip in clips.items():
        assert clip["fps"] == DEFAULT_FPS, f"{model=} {path}: clip rate {clip['fps']} ≠ frame rate"
        for track in clip["tracks"]:
            end = track["keys"][-1]["time"] / clip["fps"]
            assert end == pytest.approx(2.0, abs=1e-6), f"{model=} {path}: clip ends at {end} s, run at 2 s"
    # frame k, shown at k/fps, is Pinocchio's pose at t = k/fps
    for k in (0, 37, n_frames - 1):
        theta = np.array([np.interp(k / DEFAULT_FPS, traj.t, traj.q[:, i]) for i in range(traj.q.shape[1])])
        poses = visual.placements(theta)
        for i, obj in enumerate(visual.objects):
            if obj.parentJoint == 0:
                continue
            track = next(
                t for t in clips["/meshcat/" + visual.node(obj)]["tracks"] if t["name"] == ".position"
            )
            key = track["keys"][k]
            assert key["time"] == k
            np.testing.assert_allclose(key["value"], poses[i][:3, 3], atol=1e-6, err_msg=f"{model=} {k=}")


def test_ten_second_animation_is_small():
    run = run_scene(load_scene(REPO / "scenes" / "chaotic_double_pendulum.toml"))
    assert run.t[-1] == pytest.approx(10.0)
    for trace in (False, True):
        size = len(render_html(Trajectory.from_run(run), trace=trace).encode())
        assert size < MAX_HTML_BYTES, f"{trace=}: {size / 1e6:.2f} MB"


def test_page_needs_no_network_and_no_server(monkeypatch):
    import meshcat.servers.zmqserver
    import meshcat.visualizer

    def forbidden(*args, **kwargs):
        raise AssertionError("a meshcat server was started")

    monkeypatch.setattr(meshcat.servers.zmqserver, "start_zmq_server_as_subprocess", forbidden)
    monkeypatch.setattr(meshcat.visualizer, "start_zmq_server_as_subprocess", forbidden)
    me = psutil.Process()
    children, sockets = {p.pid for p in me.children(recursive=True)}, len(me.net_connections())
    run = run_scene(parse_scene(short_scene("cart_double_pendulum"), "<test>"))
    page = render_html(Trajectory.from_run(run), trace=True)
    assert {p.pid for p in me.children(recursive=True)} == children, "a process was left behind"
    assert len(me.net_connections()) == sockets, "a socket was left open"
    bundle = VIEWER_JS.read_text(encoding="utf-8")
    assert page.count(bundle) == 1, "the viewer bundle is not embedded"
    lowered = page.replace(bundle, "").lower()  # the bundle can connect, but only if told to
    for needle in ("<script src", "<link ", "fetch(", "http://", "https://", "websocket", ".connect("):
        assert needle not in lowered, f"page loads something from outside: {needle!r}"
    assert "&lt;test&gt; &amp; &quot;scene&quot;" in page  # the title is escaped
    assert '<test> & "scene"' not in page


def test_trajectory_from_npz_round_trips_and_renders(tmp_path, capsys):
    scene = write_scene(tmp_path / "s.toml", short_scene("double_pendulum"))
    npz = tmp_path / "run.npz"
    assert main(["simulate", str(scene), "-o", str(npz), "--html", str(tmp_path / "a.html")]) == 0
    traj = Trajectory.from_npz(npz)
    direct = Trajectory.from_run(run_scene(load_scene(scene)))
    np.testing.assert_array_equal(traj.q, direct.q)
    assert traj.params == direct.params
    assert main(["render", "--trajectory", str(npz), "-o", str(tmp_path / "b.html")]) == 0
    assert main(["render", str(scene), "-o", str(tmp_path / "c.html"), "--trace"]) == 0
    out = capsys.readouterr().out
    assert "animation written to" in out and "MB)" in out
    for name in ("a", "b", "c"):
        assert (tmp_path / f"{name}.html").stat().st_size < MAX_HTML_BYTES
    assert not list(tmp_path.glob(".*.tmp")), "temporary file left behind"


def test_render_errors_are_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip")
    assert main(["render", "--trajectory", str(bad), "-o", str(tmp_path / "x.html")]) == 2
    assert "bad.npz" in capsys.readouterr().err
    assert main(["render", "--trajectory", str(tmp_path / "none.npz"), "-o", str(tmp_path / "x.html")]) == 2
    assert "saved run (.npz) not found: " in capsys.readouterr().err
    assert main(["render", "-o", str(tmp_path / "x.html")]) == 2
    assert "give a scene file" in capsys.readouterr().err
    params = default_params("double_pendulum")
    with pytest.raises(TrajectoryError, match="expected 2 columns"):
        Trajectory(np.array([0.0, 1.0]), np.zeros((2, 3)), params, "x")
    with pytest.raises(TrajectoryError, match="strictly increasing"):
        Trajectory(np.array([0.0, 0.0]), np.zeros((2, 2)), params, "x")
    assert not (tmp_path / "x.html").exists()


def test_render_draws_a_plugin_scene_from_its_urdf(tmp_path, capsys):
    out = tmp_path / "cart_pole.html"
    assert main(["render", str(REPO / "scenes" / "cart_pole_lqr_push.toml"), "-o", str(out)]) == 0
    page = out.read_text()
    assert page.startswith("<!DOCTYPE html>") or "<html" in page[:500]
    assert "cart-pole LQR after a push" in page and "cart_pole" in page


def test_energy_plot_and_review_page_escape_user_strings():
    run = run_scene(
        parse_scene(short_scene("double_pendulum", effects={"gravity": True, "damping": True}), "<t>")
    )
    svg = energy_plot_svg(run)
    assert svg.lstrip().startswith("<?xml") and "t [s]" in svg and "energy [J]" in svg

    evil = '<script>alert("x")</script>'
    scene = SceneReview(
        evil, f"dir/{evil}.toml", f"scenes/{evil}.html", "plots/p q.svg", run.invariants, True
    )
    page = review_page(Report(seed=1, states={}, results=[]), [scene], title=evil)
    assert "<script>" not in page
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in page
    assert 'src="plots/p%20q.svg"' in page


def test_a_urdf_without_materials_is_drawn_in_one_visible_colour_per_link():
    params = default_params("double_pendulum")
    bare = re.sub(r"<material[^>]*/>|<material[^>]*>.*?</material>", "", urdf_for(params), flags=re.S)
    assert "<material" not in bare and "<visual" in bare
    run = run_scene(parse_scene(short_scene("double_pendulum"), "<test>"))
    traj = Trajectory(
        np.asarray(run.t), np.asarray(run.q), params, "bare", model_cls=run.scene.model_cls, urdf=bare
    )
    commands = decoded(build_scene(traj))
    objects = {c["path"]: c["object"] for c in commands if c["type"] == "set_object"}
    visual = VisualSystem.for_model(run.scene.model_cls, bare, params.g)
    link_of = {o.name: visual.system.model.frames[o.parentFrame].name for o in visual.objects}
    sent = {o.name: objects["/meshcat/" + visual.node(o)]["materials"][0]["color"] for o in visual.objects}
    palette = {hex_colour(" ".join(str(x) for x in rgba)) for rgba in LINK_COLOURS}
    for name, colour in sent.items():
        assert colour in palette, f"{name} ({link_of[name]}) is drawn {colour:06x}, not a link colour"
        channels = (colour >> 16, (colour >> 8) & 255, colour & 255)
        assert min(channels) < 200, f"{name}: near-white {colour:06x} on the light grey background"
    per_link = {}
    for name, colour in sent.items():
        per_link.setdefault(link_of[name], set()).add(colour)
    assert {"link1", "link2"} <= per_link.keys()
    assert all(len(c) == 1 for c in per_link.values()), f"one colour per link: {per_link}"
    distinct = {c for colours in per_link.values() for c in colours}
    assert len(distinct) == len(per_link), f"links share a colour: {per_link}"


def test_a_urdf_material_is_kept_beside_the_default_colours():
    params = default_params("double_pendulum")
    urdf = urdf_for(params)
    link1 = re.compile(r'(<link name="link1">.*?</link>)', re.S)
    text = link1.sub(lambda m: re.sub(r"<material[^>]*/>", "", m.group(1)), urdf)
    visual = VisualSystem.for_model(MODELS["double_pendulum"], text, params.g)
    for obj in visual.objects:
        link = visual.system.model.frames[obj.parentFrame].name
        rgba = " ".join(str(x) for x in obj.meshColor)
        if link == "link1":
            assert tuple(obj.meshColor) in LINK_COLOURS, f"{obj.name}: {rgba}"
        elif link == "link2":
            assert hex_colour(rgba) == hex_colour(COLOURS["link2"]), f"{obj.name}: {rgba}"


def eight_model_report() -> Report:
    models = [f"model_number_{k}_with_a_long_name" for k in range(8)]
    state = {"label": "random 7", "q": [0.123456, -1.2345, 2.34567]}
    results = [
        Evidence("check", c, "pass", 1.2e-13, 5.7e-11, state, detail=c, model=m, samples=60, seed=1)
        for c in ("crba", "rnea", "gravity", "aba", "energy", "M inverse")
        for m in models
    ]
    return Report(seed=1, states=dict.fromkeys(models, 60), results=results)


def test_review_tables_sit_in_boxes_that_scroll_sideways():
    page = review_page(eight_model_report(), [])
    style = re.search(r"<style>(.*)</style>", page, re.S).group(1)
    assert re.search(r"\.table-box \{[^}]*overflow-x: auto", style)
    tables = page.count("<table>")
    assert tables == 2 and page.count('<div class="table-box"><table>') == tables
    assert page.count("</table></div>") == tables
    # a long model name may wrap in its column's head, after "_" (and ":")
    assert "<th>model_<wbr>number_<wbr>0_<wbr>with_<wbr>a_<wbr>long_<wbr>name</th>" in page


# --- in a real browser -------------------------------------------------------------------
def _hsv(png: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hue in [deg], saturation and value in [0, 1] of every pixel."""
    rgb = np.asarray(Image.open(png).convert("RGB"), dtype=float) / 255.0
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    top, spread = rgb.max(axis=-1), np.ptp(rgb, axis=-1)
    d = np.where(spread > 0, spread, 1.0)
    hue = np.where(top == r, ((g - b) / d) % 6, np.where(top == g, (b - r) / d + 2, (r - g) / d + 4)) * 60.0
    saturation = np.where(top > 0, spread / np.where(top > 0, top, 1.0), 0.0)
    return hue, saturation, top


def _material_hue(name: str) -> float:
    r, g, b = (float(x) for x in COLOURS[name].split()[:3])
    return colorsys.rgb_to_hsv(r, g, b)[0] * 360.0


def colour_masks(png: Path) -> dict[str, np.ndarray]:
    """Pixels of each URDF material's colour, allowing for shading (hue kept, value varies)."""
    hue, sat, val = _hsv(png)
    masks = {}
    for name in ("link1", "link2", "cart"):
        distance = np.abs((hue - _material_hue(name) + 180.0) % 360.0 - 180.0)
        masks[name] = (distance < HUE_TOL_DEG) & (sat > MIN_SATURATION) & (val > MIN_VALUE)
    rail = float(COLOURS["rail"].split()[0])
    masks["rail"] = (sat < 0.06) & (np.abs(val - rail) < 0.12)
    return masks


def assert_model_visible(png: Path, cart: bool, context: str) -> dict[str, np.ndarray]:
    masks = colour_masks(png)
    counts = {k: int(m.sum()) for k, m in masks.items()}
    assert counts["link1"] >= MIN_LINK_PIXELS, f"{context}: rod 1 (blue) hardly visible: {counts}"
    assert counts["link2"] >= MIN_LINK_PIXELS, f"{context}: rod 2 (orange) hardly visible: {counts}"
    if cart:
        assert counts["cart"] >= MIN_CART_PIXELS, f"{context}: cart (green) hardly visible: {counts}"
        span = float(masks["rail"].mean(axis=1).max())
        assert span >= MIN_RAIL_SPAN, f"{context}: no rail across the view (widest grey row {span:.0%})"
    return masks


@pytest.fixture(scope="module")
def browser():
    with Chromium() as chromium:
        yield chromium


def wait_for_clock(tab, at_least: float, timeout: float = 20.0) -> float:
    deadline = time.monotonic() + timeout
    while (t := tab.evaluate(CLOCK)) < at_least:
        assert time.monotonic() < deadline, f"the animation clock stays at {t} s"
        time.sleep(0.05)
    return t


def wait_for_recorded_span(tab, seconds: float, timeout: float = 20.0) -> None:
    """Wait until the frames ``RECORD_FRAMES`` records span ``seconds`` of the page's clock (a
    fixed sleep spans less on a loaded machine, where frames come late)."""
    span = "window.seen.length ? window.seen[window.seen.length - 1][0] - window.seen[0][0] : 0"
    deadline = time.monotonic() + timeout
    while (spanned := tab.evaluate(span)) < seconds:
        assert time.monotonic() < deadline, f"the recorded frames span only {spanned:.2f} s"
        time.sleep(0.05)


@dataclasses.dataclass(frozen=True)
class RecordedRate:
    """Animation seconds per second of the page's clock between the first and the last frame
    recorded, the page's seconds spanned, and the longest interval between two recorded frames."""

    rate: float
    spanned: float
    longest_frame: float

    def band(self, scale: float) -> tuple[float, float]:
        """The rates an animation at time scale ``scale`` may be recorded at.  The animator's frame
        callback and ``RECORD_FRAMES``'s run in the same frames in either order, so an animation time
        recorded may lag the page time recorded with it by one frame's advance, scale × the frame's
        interval; the two ends' lags differ by at most scale × the longest interval, a share
        longest / spanned of the rate (milliseconds over a second on an idle machine, a tenth of a
        second per frame on a loaded one); ``RATE_SLACK`` covers the script time within a frame."""
        slack = RATE_SLACK + self.longest_frame / self.spanned
        return scale * (1 - slack), scale * (1 + slack)


def recorded_rate(tab, until: float) -> RecordedRate:
    """The rate over the frames ``RECORD_FRAMES`` recorded up to animation time ``until``."""
    frames = [f for f in tab.evaluate("window.seen") if f[1] <= until]
    (page_a, anim_a), (page_b, anim_b) = frames[0], frames[-1]
    longest = max(b[0] - a[0] for a, b in itertools.pairwise(frames))
    return RecordedRate((anim_b - anim_a) / (page_b - page_a), page_b - page_a, longest)


@needs_chromium
def test_an_animation_at_twice_real_time_is_measured_so(tmp_path, browser):
    """The rate check catches an animation that does not play at real time: at time scale 2, the
    recorded rate is outside real time's band and inside twice real time's (``RecordedRate.band``)."""
    path = BUILT_IN_SCENES[0]
    page = tmp_path / f"{path.stem}.html"
    assert main(["render", str(path), "-o", str(page)]) == 0
    tab = browser.open(page, SHOT_SIZE)
    try:
        tab.evaluate("viewer.animator.mixer.timeScale = 2, viewer.animator.reset(), 0")
        tab.evaluate("viewer.animator.play(), 0")
        wait_for_clock(tab, FIRST_SHOT_S)
        tab.evaluate(RECORD_FRAMES)
        wait_for_recorded_span(tab, SHOT_GAP_S / 2)
        recorded = recorded_rate(tab, tab.evaluate(CLOCK))
    finally:
        tab.close()
    assert recorded.spanned >= SHOT_GAP_S / 2, f"frames over only {recorded.spanned:.2f} s"
    real_time, twice = recorded.band(1.0), recorded.band(2.0)
    assert real_time[1] < twice[0], f"frames {recorded.longest_frame:.2f} s apart: the bands overlap"
    assert not real_time[0] <= recorded.rate <= real_time[1], recorded
    assert twice[0] <= recorded.rate <= twice[1], recorded


@needs_chromium
def test_browser_leaves_no_process_behind():
    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}
    with Chromium() as chromium:
        tab = chromium.open("about:blank", (200, 100))
        assert tab.evaluate("1 + 1") == 2
        helpers = {p.pid for p in me.children(recursive=True)} - before
        assert helpers, "no browser process was started"
    left = [p for p in psutil.Process().children(recursive=True) if p.pid not in before]
    assert not left, f"processes left behind: {[(p.pid, p.name()) for p in left]}"
    assert not any(psutil.pid_exists(pid) and psutil.Process(pid).status() != "zombie" for pid in helpers)


@needs_chromium
@pytest.mark.parametrize("path", PLUGIN_SCENES, ids=[p.stem for p in PLUGIN_SCENES])
def test_rendered_plugin_scene_plays_in_chromium(path, tmp_path, browser):
    """A model file's URDF (its own visuals, no project colours): drawn, and it moves."""
    page = tmp_path / f"{path.stem}.html"
    assert main(["render", str(path), "-o", str(page)]) == 0
    tab = browser.open(page, SHOT_SIZE)
    try:
        tab.evaluate("viewer.animator.reset(), viewer.animator.play(), 0")
        wait_for_clock(tab, FIRST_SHOT_S)
        first = tab.screenshot(tmp_path / "first.png")
        t1 = tab.evaluate(CLOCK)
        time.sleep(SHOT_GAP_S)
        second = tab.screenshot(tmp_path / "second.png")
        t2 = tab.evaluate(CLOCK)
    finally:
        tab.close()
    a, b = (np.asarray(Image.open(x).convert("RGB"), dtype=int) for x in (first, second))
    drawn = np.abs(a - a[0, 0]).sum(axis=-1) > 30  # pixels unlike the plain background
    assert drawn.sum() >= MIN_LINK_PIXELS, f"{path.stem}: the model is hardly visible"
    moved = int((np.abs(a - b).sum(axis=-1) > 30).sum())
    assert moved >= MIN_MOVED_PIXELS, f"{path.stem}: the model did not move from t = {t1:.2f} to {t2:.2f} s"


@needs_chromium
@pytest.mark.parametrize("path", BUILT_IN_SCENES, ids=[p.stem for p in BUILT_IN_SCENES])
def test_rendered_scene_plays_in_chromium(path, tmp_path, browser):
    page = tmp_path / f"{path.stem}.html"
    assert main(["render", str(path), "-o", str(page)]) == 0
    cart = load_scene(path).model == "cart_double_pendulum"
    tab = browser.open(page, SHOT_SIZE)
    try:
        # it plays by itself ...
        started = tab.evaluate(CLOCK)
        wait_for_clock(tab, started + 0.2)
        # ... and, restarted as with the viewer's reset button, shows t ≈ 0.5 s and t ≈ 1.5 s
        tab.evaluate("viewer.animator.reset(), viewer.animator.play(), 0")
        wait_for_clock(tab, FIRST_SHOT_S)
        tab.evaluate(RECORD_FRAMES)
        first = tab.screenshot(tmp_path / "first.png")
        t1 = tab.evaluate(CLOCK)
        time.sleep(SHOT_GAP_S)
        second = tab.screenshot(tmp_path / "second.png")
        t2 = tab.evaluate(CLOCK)
        recorded = recorded_rate(tab, t2)
    finally:
        tab.close()
    a = assert_model_visible(first, cart, f"{path.stem} at t = {t1:.2f} s")
    b = assert_model_visible(second, cart, f"{path.stem} at t = {t2:.2f} s")
    moved = int(sum((a[k] ^ b[k]).sum() for k in ("link1", "link2", "cart")))
    assert moved >= MIN_MOVED_PIXELS, f"{path.stem}: the model did not move from t = {t1:.2f} to {t2:.2f} s"
    assert recorded.spanned >= SHOT_GAP_S / 2, f"{path.stem}: frames over only {recorded.spanned:.2f} s"
    low, high = recorded.band(1.0)
    assert low <= recorded.rate <= high, f"{path.stem}: plays at {recorded.rate:.2f}× real time ({recorded})"


@needs_chromium
def test_review_page_shows_table_plots_and_a_playing_animation(tmp_path, browser):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    write_scene(scenes / "swing.toml", short_scene("double_pendulum", duration=3.0))
    out = tmp_path / "review"
    assert main(["report", "-o", str(out), "--scenes", str(scenes), "--samples", "5", "--no-erd"]) == 0
    index = (out / "index.html").read_text()
    for needle in ("crba", "energy drift", 'src="scenes/swing.html"', 'src="plots/swing.svg"'):
        assert needle in index, needle
    assert "&lt;test&gt; &amp; &quot;scene&quot;" in index and "<test>" not in index
    tab = browser.open(out / "index.html", (1200, 1000))
    try:
        time.sleep(2.0)  # the embedded animation loads and plays
        shot = tab.screenshot(tmp_path / "review.png")
    finally:
        tab.close()
    masks = colour_masks(shot)
    assert masks["link1"].sum() >= MIN_LINK_PIXELS // 2, "the embedded animation shows no rod"


@needs_chromium
def test_review_page_with_eight_models_fits_1280_px_and_its_table_scrolls_in_its_box(tmp_path, browser):
    page = tmp_path / "index.html"
    page.write_text(review_page(eight_model_report(), []))
    tab = browser.open(page, (1280, 900))
    try:
        page_width = tab.evaluate("document.documentElement.scrollWidth")
        box = tab.evaluate(
            "(function () { var b = document.querySelector('.table-box');"
            " return [b.scrollWidth, b.clientWidth, b.getBoundingClientRect().right]; })()"
        )
    finally:
        tab.close()
    assert page_width <= 1280, f"the page is {page_width} px wide at 1280 px"
    scroll, client, right = box
    assert right <= 1280, f"the table's box ends at {right} px"
    assert scroll > client, "eight long model names should need the box's scroll bar at 1280 px"
