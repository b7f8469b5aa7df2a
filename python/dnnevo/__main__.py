"""``python -m dnnevo``: the same as the ``dnnevo`` command."""

from dnnevo.cli.command import main

raise SystemExit(main())
