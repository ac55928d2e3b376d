"""``python -m monitor.cli``: the crisgeo command."""

from monitor.cli import main

raise SystemExit(main())
