"""``python -m asymslide``: the same as the ``asymslide`` console script."""

import sys

from asymslide.cli import main

sys.exit(main())
