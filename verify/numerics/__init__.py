"""Compiled and high-precision back ends: the fast path, fixed-step methods, Taylor references."""
