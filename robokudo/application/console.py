"""The console entry point (``robokudo``, ``python -m robokudo``): interrupts are handled before the CLI loads.

Loading the command modules loads Open3D and OpenCV, about a second; a Ctrl-C or SIGTERM in that second must end
the way every other interrupt does (one line ``interrupted``, exit status 130), not as a broken import. So this
module imports only the interrupt handling, installs it, and then imports the CLI.
"""

from __future__ import annotations

import os
import sys

from robokudo.application.interrupts import InterruptHandling

BROKEN_PIPE_STATUS = 141
"""The exit status when the output's reader went away: 128 + SIGPIPE, as a shell reports a killed pipe writer."""


def main() -> int:
    """Load the CLI under interrupt handling and run the command given on the command line."""
    with InterruptHandling() as interrupts:
        try:
            from robokudo.application import cli  # deferred on purpose: see the module docstring
        except BaseException:
            if interrupts.received is None:
                raise
            interrupts.exit()
    try:
        status = cli.main()
        sys.stdout.flush()
    except BrokenPipeError:
        # the reader of the output went away (``robokudo beliefs | head -1``): stop quietly, as Unix tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # the final flush must not fail again
        return BROKEN_PIPE_STATUS
    return status


if __name__ == "__main__":
    sys.exit(main())
