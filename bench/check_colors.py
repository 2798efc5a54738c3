"""Whether this checkout's SemanticColorAnnotator gives exactly the colour annotations of another git revision's.

``python bench/check_colors.py REV`` prepares the annotator's inputs once with this checkout (the colour image and
the object hypotheses the tabletop tree makes on frames 0-4 of ../shared/data/uoc_tabletop_realsense and on every
mOSD learn scene, and the hand-labelled objects of tests/data/colors/real_colors.json, one input per frame); then
this checkout and REV (exported with ``git archive``) each run their SemanticColorAnnotator on them in a worker
process of their own, and every hypothesis' SemanticColor annotations (name, ratio and confidence, compared to the
last bit, in order) are compared input by input. Prints one line per differing hypothesis (and whether only the
last bits of the numbers differ or also the names) and ``identical on N/N inputs``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from revision_workers import compare_with_revision

ROOT = Path(__file__).resolve().parents[1]
DATA = (ROOT.parent / "shared" / "data").resolve()
UOC_FRAMES = range(5)


def _save(folder: Path, name: str, image: np.ndarray, masks: list[np.ndarray], rois: list[tuple]) -> None:
    np.savez(
        folder / f"{name}.npz",
        image=image,
        masks=np.array([np.packbits(mask) for mask in masks]).reshape(len(masks), -1),
        rois=np.array(rois, dtype=np.int64).reshape(-1, 4),
    )


def prepare(folder: Path) -> list[str]:
    """Write each input's ``image``, packed hypothesis ``masks`` and ``rois`` to ``folder``; their names."""
    sys.path.insert(0, str(ROOT))
    from annotators.readers.frame_readers import PcdReader
    from robokudo.core.engine import Engine
    from robokudo.core.types import ColorImage, ObjectHypothesis
    from tests.annotators.color_set import load_frame, load_samples, sample_mask
    from trees.tabletop import create_pipeline, create_tree

    names = []
    trees = [(f"uoc{i}", create_tree(str(DATA / "uoc_tabletop_realsense"), i)) for i in UOC_FRAMES]
    trees += [
        (path.stem, create_pipeline(PcdReader(path)))
        for path in sorted((DATA / "pcl_mosd_tabletop" / "learn").glob("*.pcd"))
    ]
    for name, root in trees:
        Engine(root, hz=1000.0).tick()
        hypotheses = root.cas.annotations(ObjectHypothesis)
        image = root.cas.view(ColorImage).image
        _save(folder, name, image, [h.mask for h in hypotheses], [h.roi for h in hypotheses])
        names.append(name)
    by_frame: dict[tuple[str, int], list] = {}
    for sample in load_samples():
        by_frame.setdefault((sample.input, sample.frame), []).append(sample)
    for (input_path, index), samples in by_frame.items():
        frame = load_frame(input_path, index)
        masks = [sample_mask(sample, frame) for sample in samples]
        rois = []
        for mask in masks:
            rows, cols = np.nonzero(mask)
            rois.append((int(cols.min()), int(rows.min()), int(cols.max()) + 1, int(rows.max()) + 1))
        name = f"set_{Path(input_path).stem}_{index}"
        _save(folder, name, frame.color, masks, rois)
        names.append(name)
    return names


def worker(checkout: str, folder: Path, names: list[str], tag: str) -> None:
    """Run the checkout's SemanticColorAnnotator on every prepared input; write ``{tag}.json``: per input, per
    hypothesis, its annotations as [name, ratio as hex, confidence as hex]."""
    sys.path.insert(0, checkout)
    from annotators.image.color import SemanticColorAnnotator
    from robokudo.core.annotator import Annotator
    from robokudo.core.pipeline import Pipeline
    from robokudo.core.types import ColorImage, ObjectHypothesis, SemanticColor

    class Scene(Annotator):
        outputs = (ColorImage, ObjectHypothesis)

        def __init__(self, data: dict) -> None:
            super().__init__(name="Scene")
            self.data = data

        def analyse(self) -> None:
            image = self.data["image"]
            self.write(ColorImage(image))
            for packed, roi in zip(self.data["masks"], self.data["rois"], strict=True):
                mask = np.unpackbits(packed)[: image.shape[0] * image.shape[1]].reshape(image.shape[:2]).view(bool)
                roi = tuple(int(v) for v in roi)
                self.write(ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=roi))

    results = {}
    for name in names:
        data = dict(np.load(folder / f"{name}.npz"))
        colors = SemanticColorAnnotator()
        pipeline = Pipeline("check", [Scene(data), colors])
        pipeline.tick_once()
        results[name] = {
            "status": str(colors.status),
            "hypotheses": [
                [[c.color, float(c.ratio).hex(), float(c.confidence).hex()] for c in h.find(SemanticColor)]
                for h in pipeline.cas.annotations(ObjectHypothesis)
            ],
        }
    (folder / f"{tag}.json").write_text(json.dumps(results))


def report(inputs: Path, names: list[str]) -> None:
    """Compare the two sides' results input by input and print the differences and the count."""
    ours = json.loads((inputs / "ours.json").read_text())
    theirs = json.loads((inputs / "theirs.json").read_text())
    same = hypotheses = annotations = 0
    for name in names:
        mine, other = ours[name], theirs[name]
        hypotheses += len(other["hypotheses"])
        annotations += sum(len(h) for h in other["hypotheses"])
        if mine == other:
            same += 1
            continue
        if mine["status"] != other["status"] or len(mine["hypotheses"]) != len(other["hypotheses"]):
            print(f"DIFFERENT: {name}: {mine['status']} vs {other['status']}")
            continue
        for index, (a, b) in enumerate(zip(mine["hypotheses"], other["hypotheses"], strict=True)):
            if a != b:
                names_same = [c[0] for c in a] == [c[0] for c in b]
                kind = "numbers only (names and order the same)" if names_same else "NAMES"
                print(f"DIFFERENT: {name} hypothesis {index}, {kind}: {a} vs {b}")
    print(f"{hypotheses} hypotheses, {annotations} colour annotations in {len(names)} inputs")
    print(f"identical on {same}/{len(names)} inputs")


def main() -> None:
    compare_with_revision(__file__, __doc__.split("\n")[0], prepare, worker, report)


if __name__ == "__main__":
    main()
