"""Scenes: declared effects, right-hand sides, integrators and invariants."""
