"""The ``dnnevo`` command line."""

from __future__ import annotations

import argparse
import sys

import dnnevo

EXAMPLES = """examples:
  dnnevo --version
"""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``dnnevo`` command."""
    parser = argparse.ArgumentParser(
        prog="dnnevo",
        description="Evolve continuous-time recurrent neural networks (Yamauchi & Beer).",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"dnnevo {dnnevo.__version__}")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit status."""
    parser = build_parser()
    parser.parse_args(argv)
    parser.print_help(sys.stdout)
    return 0
