"""Visualisation: Meshcat scenes and review pages (see the render issue)."""
