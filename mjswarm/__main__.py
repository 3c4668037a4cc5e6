"""``python -m mjswarm`` runs the CLI."""

import sys

from mjswarm.cli import main

sys.exit(main())
