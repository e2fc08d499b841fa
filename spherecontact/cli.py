"""Command line: ``spherecontact <stage> <command> …``.

A thin layer: each stage's ``cli`` module (:data:`STAGES`) provides ``register(subparsers)``
that adds its commands and binds them to functions the tests call directly:
``model curve|table``, ``fem run|render``, ``campaign run|design|increments``, ``calibrate``,
``validate``, ``peers mdr``.
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys
import warnings

#: the modules whose ``register`` adds the commands, in the order of the help text
STAGES = ("spherecontact.model.cli", "spherecontact.fem.cli", "spherecontact.campaign.cli",
          "spherecontact.calibration.cli", "spherecontact.validation.cli")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="spherecontact",
        description="Contact between two elastic-plastic spheres: FE reference and closed-form model.",
    )
    sub = parser.add_subparsers(dest="stage", required=True, metavar="STAGE")
    for stage in STAGES:
        module = importlib.import_module(stage)
        module.register(sub)
    return parser


#: a negative number as a flag's value (argparse alone takes "-193e9" for an option)
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$|^-inf(inity)?$", re.IGNORECASE)


def join_negative_values(argv: list[str]) -> list[str]:
    """``--E -193e9`` → ``--E=-193e9``: a negative number after a long option is its value."""
    out: list[str] = []
    for tok in argv:
        prev = out[-1] if out else ""
        if _NEGATIVE_NUMBER.match(tok) and prev.startswith("--") and "=" not in prev:
            out[-1] = f"{prev}={tok}"
        else:
            out.append(tok)
    return out


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line with its message only (no source line)."""
    print(f"spherecontact: warning: {message}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(join_negative_values(sys.argv[1:] if argv is None else list(argv)))
    with warnings.catch_warnings():
        warnings.showwarning = _show_warning
        try:
            return int(args.func(args) or 0)
        except ValueError as err:  # bad input: one clear line, exit code 2
            print(f"spherecontact: error: {err}", file=sys.stderr)
            return 2
        except OSError as err:  # a file that cannot be read or written
            print(f"spherecontact: error: {err.filename or ''}: {err.strerror or err}", file=sys.stderr)
            return 2


if __name__ == "__main__":
    sys.exit(main())
