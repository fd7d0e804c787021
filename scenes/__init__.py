"""Data shipped with pendverify: the scenes folder (read with importlib.resources)."""
