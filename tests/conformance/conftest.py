"""The conformance matrix's session summary (the product's size and the sample's: ``matrix.summary``)
and the signing keys its certify commands use."""

from __future__ import annotations

import pytest


def pytest_terminal_summary(terminalreporter):
    from tests.conformance.matrix import summary

    terminalreporter.write_line(summary())


@pytest.fixture(scope="session")
def signing_keys(tmp_path_factory):
    """A key pair from ``pendverify keygen`` for ``certify --key`` and ``recheck --trust``."""
    from pendverify.cli import main

    folder = tmp_path_factory.mktemp("conformance-keys")
    assert main(["keygen", "-o", str(folder / "keys")]) == 0
    return folder / "keys"
