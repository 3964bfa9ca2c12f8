"""``python -m hexapod_workspace`` runs the CLI."""

import sys

from .cli import main

sys.exit(main())
