"""How often the form cues (a handle, an open top) are right on hand-labelled real objects, per split.

Runs "find all objects" (as `robokudo query` does) on every hand-labelled real frame of
tests/data/labels/real_objects.json (read in place from ../shared/data) and takes the FormFeatures of the hypothesis
at each labelled object. The truth is the true class's profile in the ontology (rk:hasHandle, rk:openTop); objects
labelled "unknown" or whose class says nothing are left out. Prints, for the fit split (the frames the thresholds
were chosen on) and the held-out check split: open-top accuracy, and handle recall / precision, with the goals met
or not. Run it with PYTHONPATH at another tree to compare that tree's experts (the same labels and classes):

    python bench/bench_form_cues.py
    PYTHONPATH=/other/tree python /this/tree/bench/bench_form_cues.py
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, os.environ.get("PYTHONPATH", "").split(os.pathsep)[0] or str(ROOT))

import numpy as np  # noqa: E402

from reasoning.knowledge.knowledge_base import KnowledgeBase  # noqa: E402
from robokudo.application.service import AnsweringService, PerceptionFailedError  # noqa: E402
from robokudo.core.types import FormFeatures, ObjectHypothesis  # noqa: E402

DATA = (ROOT.parent / "shared" / "data").resolve()
LABELS = ROOT / "tests" / "data" / "labels" / "real_objects.json"
GOALS = {"open-top accuracy": 0.8, "handle recall": 0.6, "handle precision": 0.6}
"""Goals on the held-out check split."""


@dataclass(frozen=True)
class Cue:
    """One labelled object's measured and true form cues."""

    split: str
    name: str
    open_seen: bool | None
    open_true: bool | None
    handle_seen: bool | None
    handle_true: bool | None


def hypothesis_at(hypotheses: list[ObjectHypothesis], x: int, y: int) -> ObjectHypothesis | None:
    """The hypothesis covering most of the 5x5 pixels around (x, y), or None."""
    counts = [int(h.mask[max(y - 2, 0) : y + 3, max(x - 2, 0) : x + 3].sum()) for h in hypotheses]
    best = int(np.argmax(counts)) if counts else -1
    return hypotheses[best] if best >= 0 and counts[best] > 0 else None


def measure(kb: KnowledgeBase, store: Path) -> list[Cue]:
    """The cues at every labelled object of every labelled real frame."""
    cues = []
    for number, entry in enumerate(json.loads(LABELS.read_text())["frames"]):
        path = DATA / entry["input"]
        with AnsweringService.open(store.with_suffix(f".{number}"), input_path=str(path), frame=entry["frame"]) as s:
            try:
                outcome = s.answer("find all objects")
            except PerceptionFailedError as error:
                print(f"  {entry['input']}#{entry['frame']}: {error}", file=sys.stderr)
                continue
        hypotheses = outcome.tree.cas.annotations(ObjectHypothesis)
        for labelled in entry["objects"]:
            if labelled["class"] == "unknown":
                continue
            profile = kb.object_profile(labelled["class"])
            hypothesis = hypothesis_at(hypotheses, *labelled["pixel"])
            form = hypothesis.first(FormFeatures) if hypothesis is not None else None
            name = f"{entry['input']}#{entry['frame']} {labelled['name']}"
            cues.append(
                Cue(
                    entry["split"],
                    name,
                    None if form is None else bool(form.open_top),
                    profile.open_top,
                    None if form is None else bool(form.has_handle),
                    profile.handle,
                )
            )
    return cues


def report(cues: list[Cue], split: str) -> None:
    """Print the figures of one split; for the check split also the goals."""
    chosen = [c for c in cues if c.split == split]
    opened = [c for c in chosen if c.open_seen is not None and c.open_true is not None]
    accuracy = sum(c.open_seen == c.open_true for c in opened) / max(len(opened), 1)
    handles = [c for c in chosen if c.handle_seen is not None and c.handle_true is not None]
    found = sum(c.handle_seen and c.handle_true for c in handles)
    recall = found / max(sum(bool(c.handle_true) for c in handles), 1)
    precision = found / max(sum(bool(c.handle_seen) for c in handles), 1)
    figures = {"open-top accuracy": accuracy, "handle recall": recall, "handle precision": precision}
    print(f"\n{split} split: {len(chosen)} labelled objects ({len(chosen) - len(opened)} without a hypothesis)")
    for name, value in figures.items():
        goal = (
            f"   goal >= {GOALS[name]:.2f}: {'met' if value >= GOALS[name] else 'NOT met'}" if split == "check" else ""
        )
        print(f"  {name:18} {value:5.2f}{goal}")
    for c in chosen:
        wrong = [
            w for w, bad in (("open", c.open_seen != c.open_true), ("handle", c.handle_seen != c.handle_true)) if bad
        ]
        if c.open_seen is not None and wrong:
            print(f"    wrong {'/'.join(wrong):11} {c.name}")


def main() -> None:
    if not LABELS.is_file() or not DATA.is_dir():
        raise SystemExit(f"needs {LABELS} and the shared data at {DATA}")
    with tempfile.TemporaryDirectory() as tmp:
        os.environ.setdefault("ROBOKUDO_USER_ONTOLOGY", str(Path(tmp) / "user.ttl"))
        kb = KnowledgeBase.load(Path(tmp) / "user.ttl")
        cues = measure(kb, Path(tmp) / "store.sqlite")
    import annotators.cloud.form as form

    print(f"form expert: {form.__file__}")
    for split in ("fit", "check"):
        report(cues, split)


if __name__ == "__main__":
    main()
