"""``python -m samvg``: the command line."""

import sys

from samvg.cli import main

sys.exit(main())
