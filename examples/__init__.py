"""Data shipped with pendverify: the examples folder (read with importlib.resources)."""
