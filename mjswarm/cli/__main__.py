"""``python -m mjswarm.cli`` runs the CLI."""

import sys

from mjswarm.cli import main

sys.exit(main())
