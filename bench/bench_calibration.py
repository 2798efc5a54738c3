"""Is the knowledge classifier's confidence a probability of being right? Reliability tables on labelled objects.

Runs the synthesized tree of every query in QUERIES (as `robokudo query` does) on every labelled frame: the
hand-labelled real frames of tests/data/labels/real_objects.json (read in place from ../shared/data) and the
built-in kitchen rendered from its orbit and named views (ground truth from the renderer, written to a temporary
folder). At each labelled object it takes the hypothesis there and compares the class the classifier attached
with the true one (a superclass or subclass of the true class counts as right; "unknown" objects have no class
profile in the ontology). For the fit split and the held-out check split, kitchen and real frames apart, it prints
confidence bin -> answers naming a class, fraction right; and how the unknown objects were reported.

    python bench/bench_calibration.py          # tables for the calibration in use (calibration.FITTED)
    python bench/bench_calibration.py --fit    # also fit the calibration on the fit split and print it
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from annotators.classification import calibration  # noqa: E402
from annotators.classification.knowledge_classifier import UNKNOWN_CLASS, KnowledgeClassifier, best_match, lead, score  # noqa: E402
from annotators.simulation import kitchen_scene  # noqa: E402
from reasoning.knowledge.knowledge_base import KnowledgeBase  # noqa: E402
from robokudo.application.service import AnsweringService, PerceptionFailedError  # noqa: E402
from robokudo.core.types import Classification, ObjectHypothesis  # noqa: E402

DATA = (ROOT.parent / "shared" / "data").resolve()
LABELS = ROOT / "tests" / "data" / "labels" / "real_objects.json"
QUERIES = ("find all objects", "find all mugs", "find the cracker box")
BINS = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0 + 1e-9)
UNKNOWN = "unknown"
KITCHEN_FIT_VIEWS = ("table", "orbit0", "orbit2", "orbit4")
"""Kitchen views in the fit split; the others (orbit1, orbit3, fridge, overview) are held out."""


@dataclass(frozen=True)
class LabelledFrame:
    """One frame to run, with the true class of each labelled object at a pixel."""

    source: str  # "kitchen" or "real"
    split: str  # "fit" or "check"
    name: str
    input_path: str
    frame: int
    objects: tuple[tuple[str, tuple[int, int], str], ...]  # (name, (x, y), true class or "unknown")


@dataclass(frozen=True)
class Sample:
    """The classifier's answer for one labelled object under one query, with its evidence."""

    frame: LabelledFrame
    query: str
    name: str
    truth: str
    said: str | None  # the attached class (None: the object got no hypothesis or no classification)
    confidence: float
    best: str
    score: float
    lead: float
    unread: bool


def real_frames() -> list[LabelledFrame]:
    """The hand-labelled real frames."""
    data = json.loads(LABELS.read_text())
    frames = []
    for entry in data["frames"]:
        objects = tuple((o["name"], (int(o["pixel"][0]), int(o["pixel"][1])), o["class"]) for o in entry["objects"])
        name = f"{entry['input']}#{entry['frame']}"
        frames.append(LabelledFrame("real", entry["split"], name, str(DATA / entry["input"]), entry["frame"], objects))
    return frames


def kitchen_frames(folder: Path) -> list[LabelledFrame]:
    """Render the kitchen's views into ``folder`` (uoc layout) and label each visible object at its most interior
    pixel (the ground-truth object ids)."""
    views = {f"orbit{i}": pose for i, pose in enumerate(kitchen_scene.orbit_views(5))}
    views |= {name: kitchen_scene.camera_views()[name] for name in ("table", "fridge", "overview")}
    frames = []
    for index, (name, pose) in enumerate(views.items()):
        scene = kitchen_scene.render_kitchen(pose)
        cv2.imwrite(str(folder / f"{index:06d}-color.png"), cv2.cvtColor(scene.color, cv2.COLOR_RGB2BGR))
        cv2.imwrite(str(folder / f"{index:06d}-depth.png"), np.round(scene.depth * 1000).astype(np.uint16))
        objects = []
        for obj in scene.visible_objects(min_pixels=400):
            mask = (scene.object_ids == obj.object_id).astype(np.uint8)
            inside = cv2.distanceTransform(mask, cv2.DIST_L2, 5)
            y, x = np.unravel_index(int(inside.argmax()), inside.shape)
            objects.append((obj.name, (int(x), int(y)), obj.object_class))
        split = "fit" if name in KITCHEN_FIT_VIEWS else "check"
        frames.append(LabelledFrame("kitchen", split, f"kitchen/{name}", str(folder), index, tuple(objects)))
    k = kitchen_scene.DEFAULT_INTRINSICS
    params = {"img_width": k.width, "img_height": k.height, "fx": k.fx, "fy": k.fy, "x_offset": k.cx}
    (folder / "camera_params.json").write_text(json.dumps(params | {"y_offset": k.cy, "depth_scale": 1000}))
    return frames


def hypothesis_at(hypotheses: list[ObjectHypothesis], x: int, y: int) -> ObjectHypothesis | None:
    """The hypothesis covering most of the 5x5 pixels around (x, y), or None."""
    counts = [int(h.mask[max(y - 2, 0) : y + 3, max(x - 2, 0) : x + 3].sum()) for h in hypotheses]
    best = int(np.argmax(counts)) if counts else -1
    return hypotheses[best] if best >= 0 and counts[best] > 0 else None


def run_frame(frame: LabelledFrame, store: Path) -> Iterator[Sample]:
    """Every query on one frame: the classifier's answer and evidence at each labelled object."""
    with AnsweringService.open(store, input_path=frame.input_path, frame=frame.frame) as service:
        for query in QUERIES:
            try:
                outcome = service.answer(query)
            except PerceptionFailedError as error:
                print(f"  {frame.name} {query!r}: {error}", file=sys.stderr)
                continue
            classifier = next(n for n in outcome.tree.iterate() if isinstance(n, KnowledgeClassifier))
            hypotheses = outcome.tree.cas.annotations(ObjectHypothesis)
            for name, (x, y), truth in frame.objects:
                hypothesis = hypothesis_at(hypotheses, x, y)
                cues = classifier.cues(hypothesis) if hypothesis is not None else None
                if hypothesis is None or cues is None or hypothesis.first(Classification) is None:
                    yield Sample(frame, query, name, truth, None, 0.0, "", 0.0, 0.0, False)
                    continue
                said = hypothesis.first(Classification)
                matches = [score(p, cues) for p in classifier.profiles]
                best = best_match(matches)
                yield Sample(
                    frame,
                    query,
                    name,
                    truth,
                    said.class_name,
                    said.confidence,
                    best.profile.class_name,
                    best.score,
                    lead(best, matches, cues),
                    best.unread,
                )


def right(kb: KnowledgeBase, said: str, truth: str) -> bool:
    """A class is right when it is the true class, a superclass or a subclass of it (not the root)."""
    if truth == UNKNOWN or said == UNKNOWN_CLASS:
        return False
    return said == truth or kb.is_subclass(said, truth) or kb.is_subclass(truth, said)


def table(kb: KnowledgeBase, samples: list[Sample], title: str) -> None:
    """Print the reliability table of ``samples`` and how unknown objects were reported."""
    seen = [s for s in samples if s.said is not None]
    named = [s for s in seen if s.said != UNKNOWN_CLASS]
    print(f"\n{title}: {len(samples)} object answers ({len(samples) - len(seen)} without a hypothesis)")
    print("  class confidence   answers   right")
    for low, high in itertools.pairwise(BINS):
        inside = [s for s in named if low <= s.confidence < high]
        share = f"{sum(right(kb, s.said, s.truth) for s in inside) / len(inside):5.2f}" if inside else "    -"
        print(f"  {low:.1f}-{min(high, 1.0):.1f}          {len(inside):7d}   {share}")
    unknown = [s for s in seen if s.truth == UNKNOWN]
    reported = [s for s in seen if s.said == UNKNOWN_CLASS]
    known = [s for s in samples if s.truth != UNKNOWN]
    named_known = [s for s in known if s.said is not None and s.said != UNKNOWN_CLASS]
    named_right = sum(right(kb, s.said, s.truth) for s in named_known)
    print(
        f"  coverage: known objects named {len(named_known)}/{len(known)}"
        f" ({len(named_known) / max(len(known), 1):.2f}), of them right {named_right}"
    )
    print(
        f"  unknown objects reported unknown: {sum(s.said == UNKNOWN_CLASS for s in unknown)}/{len(unknown)}; "
        f"known objects reported unknown: {sum(s.truth != UNKNOWN for s in reported)}/"
        f"{sum(s.truth != UNKNOWN for s in seen)}"
    )


def fit(kb: KnowledgeBase, samples: list[Sample]) -> calibration.Calibration:
    """Fit the calibration on samples: was the best candidate right, given its score and lead?"""
    usable = [s for s in samples if s.said is not None]
    return calibration.fit(
        [s.score for s in usable],
        [s.lead for s in usable],
        [s.unread for s in usable],
        [right(kb, s.best, s.truth) for s in usable],
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fit", action="store_true", help="also fit the calibration on the fit split")
    parser.add_argument("--details", action="store_true", help="print every object answer")
    args = parser.parse_args()
    if not LABELS.is_file() or not DATA.is_dir():
        raise SystemExit(f"needs {LABELS} and the shared data at {DATA}")
    os.environ.setdefault("ROBOKUDO_USER_ONTOLOGY", str(Path(tempfile.mkdtemp()) / "user.ttl"))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "kitchen"
        folder.mkdir()
        frames = kitchen_frames(folder) + real_frames()
        samples: list[Sample] = []
        for number, frame in enumerate(frames):
            print(f"running {frame.name} ({frame.split})", file=sys.stderr)
            samples.extend(run_frame(frame, Path(tmp) / f"store{number}.sqlite"))
        kb = KnowledgeBase.load(Path(tmp) / "user.ttl")
    if args.details:
        for s in samples:
            print(
                f"{s.frame.split:5} {s.frame.name:40} {s.query:22} {s.name:16} {s.truth:14} said {s.said} "
                f"{s.confidence:.2f} (best {s.best}, score {s.score:.2f}, lead {s.lead:.2f}, unread {s.unread})"
            )
    print(f"calibration in use: {calibration.FITTED}")
    if args.fit:
        fitted = fit(kb, [s for s in samples if s.frame.split == "fit"])
        print(f"fitted on the fit split (paste into calibration.FITTED): {fitted}")
    for split in ("fit", "check"):
        for source in ("kitchen", "real"):
            chosen = [s for s in samples if s.frame.split == split and s.frame.source == source]
            table(kb, chosen, f"{split} split, {source} frames")


if __name__ == "__main__":
    main()
