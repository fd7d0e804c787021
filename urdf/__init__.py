"""URDFs of the default parameter sets, written by ``pendverify.robot.writer``.

Nothing here is public API (``__all__`` is empty).
"""

__all__: list[str] = []
