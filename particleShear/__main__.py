"""``python -m particleShear``: run one simulation from the command line (see ``--help``)."""
import sys

from .run.cli import console_main

if __name__ == "__main__":
    sys.exit(console_main())
