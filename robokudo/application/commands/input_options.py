"""The ``--input PATH``, ``--frame N`` and ``--intrinsics`` options shared by the commands that perceive.

``--frame`` numbers the frames of a recorded input; the built-in kitchen scene (no ``--input``) has a single
frame, so ``--frame`` without ``--input`` is refused (exit 2) instead of being silently ignored. ``--intrinsics
fx,fy,cx,cy[,width,height]`` gives the camera of a point-cloud input (the virtual image an unorganized PCD is
projected onto; width and height default to ``2 cx + 1`` and ``2 cy + 1``, rounded).
"""

from __future__ import annotations

import argparse

from robokudo.core.types import CameraIntrinsics


def add_input_arguments(parser: argparse.ArgumentParser, what: str = "input to perceive") -> None:
    """Declare ``--input`` and ``--frame``."""
    parser.add_argument("--input", help=f"{what} (default: the built-in kitchen scene)")
    parser.add_argument(
        "--frame", type=int, default=None, help="frame number in a recorded input (default 0; needs --input)"
    )
    parser.add_argument(
        "--intrinsics",
        metavar="FX,FY,CX,CY[,W,H]",
        help="camera of a point-cloud input, e.g. 525,525,319.5,239.5 (default: camera_params.json beside it, "
        "else the 640x480 PrimeSense model; needs --input)",
    )


def input_problem(args: argparse.Namespace) -> str | None:
    """Why ``--input`` / ``--frame`` cannot be used as given (None when they can)."""
    if args.frame is not None and args.input is None:
        return "--frame needs --input: the built-in kitchen scene has a single frame"
    if getattr(args, "intrinsics", None) is not None:
        if args.input is None:
            return "--intrinsics needs --input: the built-in kitchen scene has its own camera"
        try:
            parse_intrinsics(args.intrinsics)
        except ValueError as error:
            return str(error)
    return None


def frame_number(args: argparse.Namespace) -> int:
    """The frame to read (0 when ``--frame`` was not given)."""
    return 0 if args.frame is None else int(args.frame)


def parse_intrinsics(text: str) -> CameraIntrinsics:
    """``fx,fy,cx,cy[,width,height]`` as CameraIntrinsics; ValueError saying what is wrong."""
    try:
        values = [float(part) for part in text.split(",")]
    except ValueError:
        values = []
    if len(values) not in (4, 6) or values[0] <= 0 or values[1] <= 0 or min(values[2:4]) < 0:
        raise ValueError(f"--intrinsics must be fx,fy,cx,cy[,width,height] with positive focal lengths, got {text!r}")
    fx, fy, cx, cy = values[:4]
    width, height = (values[4], values[5]) if len(values) == 6 else (2 * cx + 1, 2 * cy + 1)
    return CameraIntrinsics(fx=fx, fy=fy, cx=cx, cy=cy, width=round(width), height=round(height))


def intrinsics_of(args: argparse.Namespace) -> CameraIntrinsics | None:
    """The ``--intrinsics`` given (None when not)."""
    text = getattr(args, "intrinsics", None)
    return parse_intrinsics(text) if text is not None else None
