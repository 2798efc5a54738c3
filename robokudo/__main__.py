"""``python -m robokudo``."""

import sys

from robokudo.application.cli import main

sys.exit(main())
