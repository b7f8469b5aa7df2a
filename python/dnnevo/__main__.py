"""``python -m dnnevo``: the same as the ``dnnevo`` command."""

from dnnevo.cli import main

raise SystemExit(main())
