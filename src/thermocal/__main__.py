"""``python -m thermocal``: the command line, as the ``thermocal`` script runs it."""

import sys

from thermocal.cli import main

if __name__ == "__main__":
    sys.exit(main())
