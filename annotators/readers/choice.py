"""One entry point for every recorded input: pick the reader annotator from a path (``--input PATH --frame N``).

The rules, tried in this order (the first that matches wins):

=====================================================================  ==========================================
path                                                                   reader
=====================================================================  ==========================================
None                                                                   KitchenSceneReader (the built-in scene)
ROS 1 ``.bag`` file, ROS 2 bag folder (``metadata.yaml``) or its       BagReader(path, frame) (BagCloudReader
``.mcap`` / ``.db3`` file                                               when it holds only PointCloud2 topics)
folder with ``rgb.txt`` and ``depth.txt``                              TumSequenceReader(folder, frame)
folder with ``depth/`` and ``color/`` (or ``image/``) image folders    Open3dFolderReader(folder, frame)
folder with ``camera_params.json`` and ``NNNNNN-color.png`` files       ColorDepthPairReader(folder, frame)
folder with ``tiff/`` (and ``pclzf/*.xml``), or that ``tiff/`` folder  TiffSequenceReader(folder, frame)
folder of ``.pcd`` files                                               PcdReader(the frame-th file, natural order)
folder of TUM-style colour/depth pairs (``TUM_color.png`` +           TumPairReader(the frame-th pair's colour
``TUM_depth.png``, ...)                                                 file, natural order)
``.pcd`` file                                                          PcdReader(file) (frame must be 0)
``NNNNNN-color.png`` with ``camera_params.json`` beside it             ColorDepthPairReader(folder, NNNNNN)
image file named ``*color*`` / ``*rgb*`` / ``*depth*`` with its other  TumPairReader(file) (frame must be 0)
half beside it (``TUM_color.png`` + ``TUM_depth.png``)
=====================================================================  ==========================================

Anything else raises ValueError listing these layouts. :func:`reader_name_for` gives the ontology name of the
reader without constructing it; :func:`reader_choice` also gives the constructor arguments (plain data). Choosing
looks at the file system only (for a bag, at its index of topics) and decodes no frame.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from annotators.readers.bag_io import IMAGE, bag_message_types, is_bag
from annotators.readers.frame_io import CAMERA_PARAMS_FILE, IMAGE_SUFFIXES, FrameError, natural_order_key
from annotators.readers.frame_readers import (
    BagCloudReader,
    BagReader,
    ColorDepthPairReader,
    KitchenSceneReader,
    Open3dFolderReader,
    PcdReader,
    TiffSequenceReader,
    TumPairReader,
    TumSequenceReader,
)
from annotators.readers.open3d_io import frame_pairs, is_open3d_folder
from annotators.readers.tiff_io import frame_stamps, is_tiff_sequence, tiff_folder
from annotators.readers.tum_io import is_tum_pair, is_tum_sequence, pair_color_files
from robokudo.core.annotator import Annotator
from robokudo.core.types import CameraIntrinsics

SUPPORTED_LAYOUTS = (
    "no path: the built-in kitchen scene",
    "a ROS 1 .bag file, or a ROS 2 bag (folder with metadata.yaml, .mcap or .db3 file)",
    "a TUM RGB-D sequence folder (rgb.txt, depth.txt)",
    "an Open3D RGB-D folder (color/ or image/ and depth/ image folders, a camera JSON, optional trajectory.log)",
    "a uoc folder (NNNNNN-color.png, NNNNNN-depth.png, camera_params.json) or one of its NNNNNN-color.png",
    "a PCL ImageGrabber folder (tiff/ with pclzf/*.xml) or its tiff/ folder",
    "a .pcd file, organized or unorganized (HEIGHT 1; --intrinsics gives its camera), or a folder of them",
    "a TUM-style colour/depth pair: a colour file named *color* or *rgb* with the *depth* file beside it, "
    "or a folder of such pairs",
)

READER_NAMES: tuple[str, ...] = (
    "KitchenSceneReader",
    "TumSequenceReader",
    "Open3dFolderReader",
    "ColorDepthPairReader",
    "TiffSequenceReader",
    "PcdReader",
    "TumPairReader",
    "BagReader",
    "BagCloudReader",
)
"""Every reader the entry point can choose, by ontology name (classes of :mod:`annotators.readers.frame_readers`)."""

_UOC_COLOR = re.compile(r"^(\d{6})-color\.png$")


@dataclass(frozen=True)
class ReaderChoice:
    """The reader for a path: its class and its constructor's keyword arguments."""

    reader: type[Annotator]
    parameters: Mapping[str, object] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The reader's name (its class name, which is also its ontology individual)."""
        return self.reader.__name__

    def create(self) -> Annotator:
        """A new reader annotator."""
        return self.reader(**self.parameters)


def _unsupported(path: Path, why: str) -> ValueError:
    layouts = "\n  - ".join(SUPPORTED_LAYOUTS)
    return ValueError(f"cannot read {path}: {why}; supported inputs:\n  - {layouts}")


def _single_frame(path: Path, frame: int) -> None:
    if frame != 0:
        raise ValueError(f"{path} holds a single frame; --frame must be 0, got {frame}")


def _bag_choice(path: Path, frame: int) -> ReaderChoice:
    try:
        types = bag_message_types(path)
    except FrameError as error:
        raise _unsupported(path, str(error)) from None
    reader = BagReader if IMAGE in types else BagCloudReader
    return ReaderChoice(reader, {"path": str(path), "frame": frame})


def _describe_numbers(numbers: list[int]) -> str:
    """``frames 0 to 4`` for a run without gaps, else ``frames 0, 2, 7`` (sorted, non-empty ``numbers``)."""
    if numbers == list(range(numbers[0], numbers[-1] + 1)) and len(numbers) > 1:
        return f"frames {numbers[0]} to {numbers[-1]}"
    return ("frame " if len(numbers) == 1 else "frames ") + ", ".join(map(str, numbers))


def _folder_choice(folder: Path, frame: int, intrinsics: CameraIntrinsics | None = None) -> ReaderChoice:
    if is_tum_sequence(folder):
        return ReaderChoice(TumSequenceReader, {"folder": str(folder), "frame": frame})
    if is_open3d_folder(folder):
        try:
            count = len(frame_pairs(folder))
        except FrameError as error:
            raise _unsupported(folder, str(error)) from None
        if not 0 <= frame < count:
            raise ValueError(f"{folder} holds {count} colour/depth frames, no frame {frame}")
        return ReaderChoice(Open3dFolderReader, {"folder": str(folder), "frame": frame})
    numbers = sorted(int(m.group(1)) for p in folder.iterdir() if (m := _UOC_COLOR.match(p.name)))
    if (folder / CAMERA_PARAMS_FILE).is_file() and numbers:
        if frame not in numbers:
            raise ValueError(f"{folder} holds {_describe_numbers(numbers)}, no frame {frame}")
        return ReaderChoice(ColorDepthPairReader, {"folder": str(folder), "frame": frame})
    if is_tiff_sequence(folder):
        return ReaderChoice(TiffSequenceReader, {"folder": str(folder), "frame": frame})
    clouds = sorted((p for p in folder.iterdir() if p.suffix.lower() == ".pcd"), key=natural_order_key)
    if clouds:
        if not 0 <= frame < len(clouds):
            raise ValueError(f"{folder} holds {len(clouds)} .pcd files, no frame {frame}")
        return ReaderChoice(PcdReader, _with_intrinsics({"path": str(clouds[frame])}, intrinsics))
    # uoc-named files without camera_params.json are not pairs: their intrinsics would be guessed
    pairs = sorted(
        (p for p in pair_color_files(folder, IMAGE_SUFFIXES) if not _UOC_COLOR.match(p.name)), key=natural_order_key
    )
    if pairs:
        if not 0 <= frame < len(pairs):
            raise ValueError(f"{folder} holds {len(pairs)} colour/depth pair(s), no frame {frame}")
        return ReaderChoice(TumPairReader, {"path": str(pairs[frame])})
    raise _unsupported(folder, "the folder matches no known layout")


def _with_intrinsics(parameters: dict[str, object], intrinsics: CameraIntrinsics | None) -> dict[str, object]:
    return {**parameters, "intrinsics": intrinsics} if intrinsics is not None else parameters


def _file_choice(path: Path, frame: int, intrinsics: CameraIntrinsics | None = None) -> ReaderChoice:
    suffix = path.suffix.lower()
    if suffix == ".pcd":
        _single_frame(path, frame)
        return ReaderChoice(PcdReader, _with_intrinsics({"path": str(path)}, intrinsics))
    uoc = _UOC_COLOR.match(path.name)
    if uoc and (path.parent / CAMERA_PARAMS_FILE).is_file():
        _single_frame(path, frame)
        return ReaderChoice(ColorDepthPairReader, {"folder": str(path.parent), "frame": int(uoc.group(1))})
    if suffix in IMAGE_SUFFIXES and is_tum_pair(path):
        _single_frame(path, frame)
        return ReaderChoice(TumPairReader, {"path": str(path)})
    raise _unsupported(path, "the file matches no known layout")


def reader_choice(path: str | None, frame: int = 0, intrinsics: CameraIntrinsics | None = None) -> ReaderChoice:
    """The reader for ``path`` and frame ``frame`` (see the module docstring); ValueError when none fits.

    ``intrinsics`` are given to a PCD reader (the camera of the cloud; other layouts carry their own).
    """
    if frame < 0:
        raise ValueError(f"frame number must be >= 0, got {frame}")
    if path is None:
        return ReaderChoice(KitchenSceneReader)
    resolved = Path(path).expanduser()
    if is_bag(resolved):
        return _bag_choice(resolved, frame)
    if resolved.is_dir():
        return _folder_choice(resolved, frame, intrinsics)
    if resolved.is_file():
        return _file_choice(resolved, frame, intrinsics)
    raise _unsupported(resolved, "no such file or folder")


def reader_for(path: str | None, frame: int = 0, intrinsics: CameraIntrinsics | None = None) -> Annotator:
    """A new reader annotator for ``path`` and frame ``frame``; ValueError listing the layouts when none fits."""
    return reader_choice(path, frame, intrinsics).create()


def reader_name_for(path: str | None, frame: int = 0) -> str:
    """The ontology name of the reader for ``path`` (``KitchenSceneReader`` for None), without constructing it."""
    return reader_choice(path, frame).name


def _folder_frame_count(folder: Path) -> int:
    """The frames of a folder of a layout read frame by frame (TIFF sequence, clouds, colour/depth pairs)."""
    if is_tiff_sequence(folder):
        return len(frame_stamps(tiff_folder(folder)))
    clouds = [p for p in folder.iterdir() if p.suffix.lower() == ".pcd"]
    if clouds:
        return len(clouds)
    return len([p for p in pair_color_files(folder, IMAGE_SUFFIXES) if not _UOC_COLOR.match(p.name)])


def recorded_frames(path: str) -> tuple[ReaderChoice, ...]:
    """The reader of every frame of the recorded input at ``path`` (not a bag), in recording order.

    A uoc folder gives its NNNNNN frames in number order, a sequence or a folder of files each of its frames, a
    single file its one frame. ValueError as :func:`reader_choice` for a path of no known layout or a bag (bags are
    read in order by :func:`annotators.readers.bag_io.bag_frames`); FrameError for an unreadable frame list.
    """
    resolved = Path(path).expanduser()
    if is_bag(resolved):
        raise ValueError(f"{resolved} is a bag: read its frames with bag_frames")
    first = reader_choice(path, 0)
    if not resolved.is_dir():
        return (first,)
    if first.reader is ColorDepthPairReader:
        numbers = sorted(int(m.group(1)) for p in resolved.iterdir() if (m := _UOC_COLOR.match(p.name)))
        return tuple(ReaderChoice(ColorDepthPairReader, {"folder": str(resolved), "frame": n}) for n in numbers)
    if first.reader is TumSequenceReader or first.reader is Open3dFolderReader:
        # the recording's lists (a long ground truth or trajectory among them) read once for all its frames
        opened = first.reader.open(resolved)
        return tuple(
            ReaderChoice(first.reader, {"folder": str(resolved), "frame": frame, "opened": opened})
            for frame in range(len(opened.pairs))
        )
    return tuple(_folder_choice(resolved, frame) for frame in range(_folder_frame_count(resolved)))
