"""The ``dnnevo`` command: one module per command, :mod:`.main` builds the parser and dispatches."""

from dnnevo.cli.command import build_parser, main

__all__ = ["build_parser", "main"]
