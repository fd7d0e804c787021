"""The review folder: check every model a set of scenes simulates, run the scenes, write the page.

``write_review(scene_paths, out, ...)`` loads the scenes first (a bad scene is an
error before any work), then builds one check target per distinct model, URDF
and parameter set among them (``scene_targets``):

* a built-in model with the project's URDF: the URDF the project writes for the
  scene's parameter set (for the default set, exactly ``pendverify check``'s target);
* a scene that names a URDF (plug-in or built-in): that URDF, in the model's
  coordinates, with the scene's parameter set;
* a plug-in scene without a URDF can be neither checked nor drawn: an error,
  before any work.

example-robot-data's double pendulums join the table when ``erd`` is on and a
scene simulates their model (when it is not installed, the report says they were
skipped).  The folder holds ``index.html``, ``report.json``, ``scenes/<stem>.html``
and ``plots/<stem>.svg``.

The folder is built as a temporary folder beside ``out`` and renamed to ``out``
at the end, so an interruption or an error leaves neither a half-written folder
nor the temporary one.  An existing ``out`` is refused before any work unless
``force``, which swaps the new folder in (rename the old aside, rename the new
into place, remove the old).  One progress bar (checks, then each scene) shows
on a terminal.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.atomic import write_atomic
from pendverify.checks.verification import build_report
from pendverify.display import REPR_LIMIT, html_table, shortened
from pendverify.errors import InputError, SceneError
from pendverify.progress import bar
from pendverify.robot import erd as erd_data
from pendverify.simulation.scene import Scene, load_scene
from pendverify.simulation.simulate import run_scene
from pendverify.targets import (
    Selection,
    Target,
    default_target,
    erd_selection,
    select_targets,
)
from pendverify.viz.animation import Trajectory, animation_page
from pendverify.viz.plots import energy_plot_svg
from pendverify.viz.review import SceneReview, review_page


@dataclass
class ReviewFolder:
    """What ``write_review`` wrote and found."""

    report: object  # pendverify.checks.verification.CheckReport
    reviews: list[SceneReview]
    index: Path

    @property
    def passed(self) -> bool:
        return self.report.passed and all(r.passed for r in self.reviews)

    def __repr__(self) -> str:
        head = f"<ReviewFolder {'pass' if self.passed else 'FAIL'}: {len(self.reviews)} scene(s), "
        return (
            f"{head}checks {self.report.status}; {shortened(str(self.index), REPR_LIMIT - len(head) - 20)}>"
        )

    def _repr_html_(self) -> str:
        rows = [(r.name, r.source, r.model, "pass" if r.passed else "FAIL") for r in self.reviews]
        caption = f"review page {self.index}: checks {self.report.status}"
        return html_table(
            ("scene", "file", "model", "invariants"), rows, caption, [not r.passed for r in self.reviews]
        )


def _is_default(scene: Scene) -> bool:
    return scene.params == load_parameter_file(default_parameter_file(scene.model))[2]


def _target(scene: Scene) -> Target:
    """A scene's target: its default set against the committed URDF, else as ``check`` chooses it."""
    if scene.urdf is None and _is_default(scene):
        return default_target(scene.model)
    urdf, params, origin = scene.urdf, scene.params, scene.params_source
    return select_targets(scene.model_cls, urdf, params, erd_urdfs=False, origin=origin).targets[0]


def scene_targets(scenes: list[Scene], erd: bool = True) -> Selection:
    """One target per distinct (model, URDF, parameters) the scenes use, and example-robot-data's
    (``erd``) when a scene simulates their model; ``skipped`` says when it is not installed."""
    targets, seen = [], set()
    for scene in scenes:
        key = (scene.model, scene.model_file, scene.urdf, repr(scene.params))
        if key in seen:
            continue
        seen.add(key)
        if scene.model_file is not None and scene.urdf is None:
            raise SceneError(
                scene.source,
                "urdf",
                None,
                f"a review checks and draws {scene.model} against its URDF: give one",
            )
        targets.append(_target(scene))
    selection = Selection(targets)
    if erd and any(s.model == erd_data.MODEL and s.model_file is None for s in scenes):
        selection.extend(erd_selection())
    return selection


def _review(path: Path, scene: Scene, out: Path, trace: bool) -> SceneReview:
    result = run_scene(scene)
    animation, plot = f"scenes/{path.stem}.html", f"plots/{path.stem}.svg"
    page = animation_page(Trajectory.from_run(result), trace=trace)
    write_atomic(out / animation, page.html)
    write_atomic(out / plot, energy_plot_svg(result))
    return SceneReview(
        name=scene.name,
        source=path.name,  # relative to the scenes folder: the page is shared, the folder is the author's
        animation=animation,
        plot=plot,
        invariants=[*result.invariants, *([result.engine_comparison] if result.engine_comparison else [])],
        passed=result.passed,
        model=scene.model,
        duration_s=scene.duration,
        notes=[*result.notes, *page.notes],
    )


def refuse_existing_folder(out: Path, force: bool) -> None:
    """An existing ``out`` is refused unless ``force``; a file there always is."""
    if out.exists() and not out.is_dir():
        raise InputError("<command line>", "output", str(out), "exists and is not a folder")
    if out.exists() and not force:
        raise InputError("<command line>", "output", str(out), "exists; pass --force to replace it")


@contextmanager
def staged_folder(out: Path):
    """A temporary folder beside ``out``, renamed to ``out`` when the block ends without error."""
    out.parent.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent))
    try:
        yield work
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(work, 0o777 & ~mask)  # mkdtemp makes 0700
        if not out.exists():
            os.rename(work, out)
            return
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.parent))
        os.replace(out, old)
        try:
            os.replace(work, out)
        except BaseException:
            os.replace(old, out)
            raise
        shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise


def write_review(
    scene_paths: list[Path],
    out: Path,
    samples: int,
    seed: int,
    erd: bool,
    trace: bool,
    log=print,
    force: bool = False,
) -> ReviewFolder:
    """Check the scenes' models, run and draw every scene, and write ``out/index.html`` (docstring)."""
    out = Path(out)
    refuse_existing_folder(out, force)
    scenes = [load_scene(path) for path in scene_paths]
    selection = scene_targets(scenes, erd)
    for sentence in selection.skipped:
        log(f"note: {sentence}")
    with staged_folder(out) as work, bar(1 + len(scenes), "report", "step") as progress:
        start = time.perf_counter()
        report = build_report(selection.targets, samples, seed)
        report.skipped = selection.skipped
        report.elapsed_s = time.perf_counter() - start
        write_atomic(work / "report.json", report.to_json())
        progress.update(1)
        verdict = "pass" if report.passed else "FAIL"
        log(f"checks: {len(report.results)} on {len(report.states)} model(s): {verdict}")
        reviews = []
        for path, scene in zip(scene_paths, scenes, strict=True):
            reviews.append(_review(path, scene, work, trace))
            progress.update(1)
            log(f"scene {scene.name}: invariants {'pass' if reviews[-1].passed else 'FAIL'}")
        write_atomic(work / "index.html", review_page(report, reviews))
    return ReviewFolder(report, reviews, out / "index.html")
