"""Ask the real-trial questions (bench/profiles/realtrial-table.txt) of the shared real frames, as a robot's program
would: for each frame one answering service with a fresh belief store, every question in turn; prints each answer
(or the error a user sees) and writes the frame with the answer drawn to OUT/<tag>_q<N>.png, to be looked at.

    PYTHONPATH=. python bench/ask_real_frames.py [OUT]        (default OUT: /tmp/realtrial)
    PYTHONPATH=. python bench/ask_real_frames.py [OUT] --new  (only NEW_QUESTIONS: the TUM desk, unused frames)

The unorganized cloud is made here from mOSD learn35 (finite points shuffled, HEIGHT 1) and read with the
PrimeSense intrinsics. Judging the answers is a person's job: the table holds the verdicts.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import open3d as o3d

from robokudo.application.annotated_image import write_annotated_image
from robokudo.application.service import AnsweringService
from robokudo.core.types import CameraIntrinsics, ColorImage

DATA = (Path(__file__).resolve().parents[2] / "shared" / "data").resolve()
UNORGANIZED = "UNORGANIZED:"
PRIMESENSE = CameraIntrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480)

QUESTIONS: list[dict] = [
    {
        "tag": "u0",
        "input": "uoc_tabletop_realsense",
        "frame": 0,
        "queries": [
            "find all objects",
            "find the red can",
            "find the can",
            "what is on the table",
            "find the drill",
            "find the box",
            "find something blue",
            "find the bowl",
            "find the white bowl",
            "find the yellow bottle",
            "find the mustard",
            "how many cans are there",
            "find the cheez-it box",
            'find "CHEEZ"',
            "inspect object 3",
        ],
    },
    {
        "tag": "u1",
        "input": "uoc_tabletop_realsense",
        "frame": 1,
        "queries": [
            "find all objects",
            "find the mug",
            "find the blue mug",
            "find the white mug",
            "find a cup",
            "find the mustard bottle",
            "find the soup can",
            "find the red can",
            "find the box",
            "find the cheez-it box",
            "find something yellow",
            "find two bowls",
            "what color is the bowl?",
            "find the spam",
        ],
    },
    {
        "tag": "u2",
        "input": "uoc_tabletop_realsense",
        "frame": 2,
        "queries": [
            "find all objects",
            "find the cans",
            "find the teal bowl",
            "find the white bowl",
            "find the can in the bowl",
            "find the mug",
            "find the largest box",
            "find the big box",
            "find the blue mug",
            "what is on the table",
            "find the mug on the table",
            "find objects anywhere",
        ],
    },
    {
        "tag": "u3",
        "input": "uoc_tabletop_realsense",
        "frame": 3,
        "queries": [
            "find all objects",
            "find the bottle",
            "find the soup can",
            "find something green",
            "find the red box",
        ],
    },
    {
        "tag": "u4",
        "input": "uoc_tabletop_realsense",
        "frame": 4,
        "queries": [
            "find all objects",
            "find the purple cup",
            "find a cup",
            "find the yellow block",
            "find the clorox wipes",
            "find the can",
            "find something purple",
            "what color is the cup?",
        ],
    },
    {
        "tag": "tum",
        "input": "tum_rgbd_sample_open3d",
        "frame": 0,
        "queries": [
            "find all objects",
            "find the blue mug",
            "find a bottle",
            "find the globe",
            "find a cup",
            "find something red",
        ],
    },
    {
        "tag": "grab",
        "input": "pcl_grabber_sequences/tiff",
        "frame": 0,
        "queries": ["find all objects", "find the box", "find the laptop", "find something blue"],
    },
    {
        "tag": "milk",
        "input": "pcl_tabletop_pcd/milk_cartoon_all_small_clorox.pcd",
        "frame": 0,
        "queries": [
            "find all objects",
            "find the milk",
            "find the milk carton",
            "find a bottle",
            "find the blue bottle",
            'find "milk"',
            "find a white bottle",
        ],
    },
    {
        "tag": "mugst",
        "input": "pcl_tabletop_pcd/table_scene_mug_stereo_textured.pcd",
        "frame": 0,
        "queries": ["find all objects", "find the mug", "find a cup"],
    },
    {
        "tag": "l0",
        "input": "pcl_mosd_tabletop/learn/learn0.pcd",
        "frame": 0,
        "queries": ["find all objects", "find the boxes", "find two cereal boxes", "find the top box"],
    },
    {
        "tag": "l35",
        "input": "pcl_mosd_tabletop/learn/learn35.pcd",
        "frame": 0,
        "queries": ["find all objects", "find the bowl", "find the white bowl", "find the yellow tub", "find the tin"],
    },
    {
        "tag": "l35u",
        "input": "UNORGANIZED:pcl_mosd_tabletop/learn/learn35.pcd",
        "frame": 0,
        "intrinsics": "525,525,319.5,239.5",
        "queries": ["find all objects", "find the bowl", "find something yellow"],
    },
    {
        "tag": "people",
        "input": "pcl_people/five_people.pcd",
        "frame": 0,
        "queries": ["find all objects", "detect { human: {} }", "find the person"],
    },
    {
        "tag": "redwood",
        "input": "redwood_synthetic_open3d",
        "frame": 0,
        "queries": ["find all objects", "find the chair"],
    },
]

NEW_QUESTIONS: list[dict] = [
    {
        "tag": "ntum",
        "input": "tum_rgbd_sample_open3d",
        "frame": 0,
        "queries": [
            "what is on the table",
            "how many bottles are there",
            "find the green bottle",
            "find something yellow",
            "find the magazine",
            "find the scissors",
            "find the plastic bag",
            "find the white cup",
            "find the mug on the table",
            "find the chair",
        ],
    },
    {"tag": "n10", "input": "pcl_mosd_tabletop/learn/learn10.pcd", "frame": 0, "queries": ["find the red box"]},
    {"tag": "n22", "input": "pcl_mosd_tabletop/learn/learn22.pcd", "frame": 0, "queries": ["how many boxes are there"]},
    {"tag": "n28", "input": "pcl_mosd_tabletop/learn/learn28.pcd", "frame": 0, "queries": ["find the yellow box"]},
    {"tag": "n40", "input": "pcl_mosd_tabletop/learn/learn40.pcd", "frame": 0, "queries": ["find something yellow"]},
    {"tag": "n43", "input": "pcl_mosd_tabletop/learn/learn43.pcd", "frame": 0, "queries": ["how many cans are there"]},
]
"""Questions asked later (realtrial-table.txt, second section): ten on the TUM desk, one each on five mOSD frames
no earlier question used."""


def unorganized_copy(organized: Path, folder: Path) -> Path:
    """``organized`` as an unorganized cloud (its finite points shuffled, HEIGHT 1) in ``folder``."""
    cloud = o3d.t.io.read_point_cloud(str(organized))
    points = cloud.point.positions.numpy()
    colours = cloud.point.colors.numpy().astype(np.float64) / 255.0
    order = np.flatnonzero(np.isfinite(points).all(axis=1))
    np.random.default_rng(0).shuffle(order)
    flat = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points[order].astype(np.float64)))
    flat.colors = o3d.utility.Vector3dVector(colours[order])
    path = folder / f"{organized.stem}_unorganized.pcd"
    o3d.io.write_point_cloud(str(path), flat)
    return path


def ask(out: Path, jobs: list[dict]) -> None:
    """Ask every question of ``jobs`` and write the pictures into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    for job in jobs:
        source, intrinsics = job["input"], None
        if source.startswith(UNORGANIZED):
            path, intrinsics = unorganized_copy(DATA / source.removeprefix(UNORGANIZED), out), PRIMESENSE
        else:
            path = DATA / source
        with (
            tempfile.TemporaryDirectory() as store,
            AnsweringService.open(
                Path(store) / "beliefs.sqlite", input_path=str(path), frame=job["frame"], intrinsics=intrinsics
            ) as service,
        ):
            for number, text in enumerate(job["queries"]):
                print(f"--- [{job['tag']}] {source} frame {job['frame']}: {text}", flush=True)
                started = time.perf_counter()
                try:
                    outcome = service.answer(text)
                except Exception as error:  # the error a user of the CLI sees, whatever its type
                    print(f"ERROR {type(error).__name__}: {error}")
                    continue
                print(outcome.answer.summary())
                if outcome.tree.cas.view(ColorImage) is not None:
                    picture = out / f"{job['tag']}_q{number}.png"
                    write_annotated_image(outcome.tree.cas, str(picture), regions=service.kb.regions())
                print(f"    ({time.perf_counter() - started:.1f} s)", flush=True)


if __name__ == "__main__":
    arguments = [argument for argument in sys.argv[1:] if argument != "--new"]
    ask(
        Path(arguments[0]) if arguments else Path("/tmp/realtrial"),
        NEW_QUESTIONS if "--new" in sys.argv[1:] else QUESTIONS,
    )
