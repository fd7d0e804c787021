"""pendverify: checks hand-derived pendulum dynamics against their URDF in Pinocchio."""

__version__ = "0.1.0"
