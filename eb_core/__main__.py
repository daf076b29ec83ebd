"""``python -m eb_core`` is the ``eb`` command."""

from eb_core.cli import main

raise SystemExit(main())
