"""``python -m cosim`` runs the command line."""

from cosim.cli import main

raise SystemExit(main())
