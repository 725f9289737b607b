"""``python -m cosim`` runs the command line."""

from cosim.cli.main import main

raise SystemExit(main())
