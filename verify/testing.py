"""pendverify in a user's own test suite.

::

    from pendverify.testing import assert_verified

    def test_my_pendulum_matches_its_urdf():
        assert_verified("models/my_pendulum.py", "models/my_pendulum.urdf", "models/my_pendulum.toml")

A failing verification fails the test with the table ``pendverify check`` prints as the
message, so the pytest output shows which check failed, by how much, at which state, and any
diagnosis.  Bad input (a missing file, an invalid parameter) is not an assertion: it raises
``pendverify.errors.PendverifyError`` with its one-line message.
"""

from __future__ import annotations

from typing import Any

from pendverify.api import ModelLike, ParamsLike, UrdfLike, check
from pendverify.checks.report import CheckReport

__all__ = ["assert_verified"]


def assert_verified(
    model: ModelLike,
    urdf: UrdfLike | None = None,
    params: ParamsLike | None = None,
    **check_options: Any,
) -> CheckReport:
    """Run ``pendverify.check(model, urdf, params, **check_options)``; fail unless the report passes.

    Passing means ``report.passed`` with the model compared with a robot (a model given without
    ``urdf`` gets its units checked alone, which verifies nothing against a robot, and fails
    here): every check passes, or passes with warnings (a warning
    fails with ``strict=True``); a failure or a refusal (a state beyond the trust limit) raises
    ``AssertionError`` whose message is the full check table, the same text as the CLI's.
    ``check_options`` are ``check``'s keywords: ``erd``, ``samples``, ``seed``, ``strict``,
    ``model_form_rtol``.  Returns the report when it passes.
    """
    __tracebackhide__ = True  # pytest: show the caller's line, not this helper's
    report = check(model, urdf, params, **check_options)
    if not report.passed or not report.robot_compared:  # a model alone's units verify no robot
        raise AssertionError(report.table())
    return report
