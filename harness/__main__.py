"""``python -m harness ...``: the vibroblock command line (see harness.cli)."""
import sys

from .cli import main

sys.exit(main())
