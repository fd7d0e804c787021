"""Benchmarks: work-precision diagrams and timing, figures as ratios measured in the same run."""
