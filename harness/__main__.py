"""``python -m harness ...``: the vibroblock command line (see harness.runs.cli)."""
import sys

from harness.runs.cli import main

sys.exit(main())
