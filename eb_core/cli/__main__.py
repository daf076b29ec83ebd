"""``python -m eb_core.cli``: the ``eb`` command."""

from eb_core.cli import main

raise SystemExit(main())
