"""``pendverify keygen -o DIR``: an Ed25519 key pair to sign certificates with."""

from __future__ import annotations

import argparse

from pendverify.commands import add_command


def register(sub) -> None:
    p = add_command(
        sub,
        "keygen",
        "write an Ed25519 key pair for signing certificates",
        ["pendverify keygen -o keys", "pendverify keygen -o keys --force --quiet"],
    )
    p.add_argument(
        "-o", "--output", required=True, help="directory for the private and public key (PEM) (required)"
    )
    p.add_argument("--force", action="store_true", help="replace an existing key pair")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pendverify import api
    from pendverify.atomic import check_output

    check_output(args.output, folder=True)
    private, public, keyid = api.generate_keys(args.output, args.force)
    if not args.quiet:
        print(f"private key: {private} (mode 0600: keep it secret; certify --key {private})")
        print(f"public key:  {public} (give it to whoever rechecks: recheck --trust {public})")
    print(f"fingerprint: {keyid}")
    return 0
