"""Command line: ``spherecontact <stage> <command> …``.

A thin layer: each stage module ``spherecontact.<stage>.cli`` provides
``register(subparsers)`` that adds its commands and binds them to functions
the tests call directly.
"""

from __future__ import annotations

import argparse
import importlib
import sys

STAGES = ("model", "fem")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="spherecontact",
        description="Contact between two elastic-plastic spheres: FE reference and closed-form model.",
    )
    sub = parser.add_subparsers(dest="stage", required=True, metavar="STAGE")
    for stage in STAGES:
        module = importlib.import_module(f"spherecontact.{stage}.cli")
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as err:  # bad input: one clear line, exit code 2
        print(f"spherecontact: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
