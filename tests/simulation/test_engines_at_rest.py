"""``simulate`` with engine both on a scene that never moves (``simulation.simulate``).

Gravity off, starting at rest, no effects: every state's scale of the engine comparison is 0,
and the comparison was 0/0 = NaN, a FAIL.  Two engines that agree exactly agree; two that
disagree (a stray constant torque in H, or any difference where no term is summed) fail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pendverify.checks.trust import EPS
from pendverify.simulation.scene import load_scene
from pendverify.simulation.simulate import relative_differences, run_scene

from ..robot.one_joint import write_one_joint

H = "return np.array([p.m * p.g * p.r * self.math.sin(q[0])])"


def _still_scene(tmp_path, q0: float, h: str = H):
    r = write_one_joint("pendulum", tmp_path)
    text = r.model.read_text()
    assert text.count(H) == 1
    r.model.write_text(text.replace(H, h))
    scene = tmp_path / "still.toml"
    scene.write_text(
        f'name = "still"\nmodel = "{r.model}"\nparams = "{r.params}"\nurdf = "{r.robot}"\nengine = "both"\n'
        f"[initial]\nq = [{q0}]\nv = [0.0]\n[time]\nduration = 0.5\nsample_rate = 10.0\n"
        '[integrator]\nmethod = "RK45"\nrtol = 1e-10\natol = 1e-10\n'
    )
    return run_scene(load_scene(scene))


@pytest.mark.parametrize("q0", [1.0, 0.0])
def test_two_engines_on_a_scene_that_never_moves_agree(tmp_path, q0):
    comparison = _still_scene(tmp_path, q0).engine_comparison
    assert comparison.passed and comparison.error == 0.0, f"{q0=} {comparison}"


def test_a_stray_constant_torque_is_reported_on_a_scene_that_never_moves(tmp_path):
    """H + 1e-9 N·m: the closed form accelerates where ABA does not."""
    planted = "return np.array([p.m * p.g * p.r * self.math.sin(q[0]) + 1e-9])"
    comparison = _still_scene(tmp_path, 1.0, planted).engine_comparison
    assert not comparison.passed and comparison.error > 1e-3, comparison


def test_where_no_term_is_summed_any_difference_is_a_disagreement():
    ratios = relative_differences([0.0, 1e-300], [0.0, 0.0])
    assert ratios[0] == 0.0 and math.isinf(ratios[1])


def test_a_state_at_rest_in_a_moving_scene_is_judged_at_the_scene_s_resolution():
    """Scale floored at ε × the largest: a difference of 1e-20 at a state of scale 0 in a scene
    of scale 1 is 1e-20/ε ≈ 4.5e-5 of it, above any rounding tolerance; at scale 1 it is 1e-20."""
    ratios = relative_differences([1e-20, 1e-20], [0.0, 1.0])
    assert ratios == pytest.approx([1e-20 / EPS, 1e-20], rel=1e-15)
    assert np.all(np.isfinite(ratios))
