"""The ``--input PATH`` and ``--frame N`` options shared by the commands that perceive (run, plan, query).

``--frame`` numbers the frames of a recorded input; the built-in kitchen scene (no ``--input``) has a single
frame, so ``--frame`` without ``--input`` is refused (exit 2) instead of being silently ignored.
"""

from __future__ import annotations

import argparse


def add_input_arguments(parser: argparse.ArgumentParser, what: str = "input to perceive") -> None:
    """Declare ``--input`` and ``--frame``."""
    parser.add_argument("--input", help=f"{what} (default: the built-in kitchen scene)")
    parser.add_argument(
        "--frame", type=int, default=None, help="frame number in a recorded input (default 0; needs --input)"
    )


def input_problem(args: argparse.Namespace) -> str | None:
    """Why ``--input`` / ``--frame`` cannot be used as given (None when they can)."""
    if args.frame is not None and args.input is None:
        return "--frame needs --input: the built-in kitchen scene has a single frame"
    return None


def frame_number(args: argparse.Namespace) -> int:
    """The frame to read (0 when ``--frame`` was not given)."""
    return 0 if args.frame is None else int(args.frame)
