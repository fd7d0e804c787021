"""The conformance matrix's session summary: the product's size and the sample's (``matrix.summary``)."""

from __future__ import annotations


def pytest_terminal_summary(terminalreporter):
    from tests.conformance.matrix import summary

    terminalreporter.write_line(summary())
