"""``python -m partlab``: the same command line as the installed ``partlab``."""

import sys

from partlab.cli import main

sys.exit(main())
