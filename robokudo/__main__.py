"""``python -m robokudo``."""

import sys

from robokudo.cli import main

sys.exit(main())
