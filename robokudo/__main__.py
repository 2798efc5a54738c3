"""``python -m robokudo``."""

import sys

from robokudo.application.console import main

sys.exit(main())
