"""What "find all objects" answers with and without reading text, and what the text costs, side by side.

On the real uoc frames 000000-000004 (../shared/data/uoc_tabletop_realsense) each frame is asked, in one run and
in alternating order, "find all objects" (which now reads text, because the ontology knows classes only their
printed text or brand tells apart) and ``detect { obj: { type: object, text: false } }`` (the same query without
the TextReader: the plan "find all objects" had before). Each side gets its own belief store per frame, so one
side's evidence never reaches the other. The answer of the first query on a fresh store is shown (class label,
class confidence, text read, image box); the time is the median of ``ROUNDS`` more answers on the same service.

Goals: with text, the Cheez-It box is named on the frames that show it (0-3), and no object named without text is
unknown (or unseen) with text; the time per query with text is printed as a ratio (the OCR cost; no goal: it is
the price of the better answer, which a query opts out of with ``text: false``).
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from robokudo.application.service import AnsweringService  # noqa: E402

UOC = ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense"
WITH_TEXT = "find all objects"
WITHOUT_TEXT = "detect { obj: { type: object, text: false } }"
CHEEZ_IT = {0: (500, 250), 1: (480, 320), 2: (260, 70), 3: (260, 70)}
"""A pixel inside the Cheez-It box, per frame that shows it (as in bench_text.py)."""
ROUNDS = 3
UNKNOWN = "unknown object"


def described(objects: list[dict]) -> list[tuple[str, float, str, tuple[int, ...]]]:
    """(class label, class confidence, text read, roi) of each answered object, left to right."""
    rows = []
    for o in objects:
        attributes = o.get("attributes", {})
        confidence = attributes.get("class", {}).get("confidence", 0.0)
        text = attributes.get("text", {}).get("value", "")
        rows.append((o["class"]["label"], confidence, text, tuple(o["roi"] or ())))
    return sorted(rows, key=lambda r: r[3][:1] or (0,))


def run(query: str, frame: int, folder: Path) -> tuple[list[dict], list[float]]:
    """The first answer on a fresh store, and the seconds of ``ROUNDS`` more answers."""
    with tempfile.TemporaryDirectory() as scratch:
        os.environ["ROBOKUDO_USER_ONTOLOGY"] = str(Path(scratch) / "user.ttl")
        with AnsweringService.open(Path(scratch) / "beliefs.sqlite", input_path=str(folder), frame=frame) as service:
            first = service.answer(query).answer.to_dict()["objects"]
            seconds = []
            for _ in range(ROUNDS):
                start = time.perf_counter()
                service.answer(query)
                seconds.append(time.perf_counter() - start)
    return first, seconds


def at(rows: list[tuple[str, float, str, tuple[int, ...]]], pixel: tuple[int, int]) -> list[str]:
    x, y = pixel
    return [r[0] for r in rows if r[3] and r[3][0] <= x < r[3][2] and r[3][1] <= y < r[3][3]]


def main() -> None:
    if not UOC.is_dir():
        sys.exit(f"needs {UOC}")
    named_by_text: dict[int, bool] = {}
    lost: list[str] = []
    times: dict[str, list[float]] = {WITH_TEXT: [], WITHOUT_TEXT: []}
    for frame in range(5):
        order = (WITHOUT_TEXT, WITH_TEXT) if frame % 2 == 0 else (WITH_TEXT, WITHOUT_TEXT)
        answers = {}
        for query in order:
            objects, seconds = run(query, frame, UOC)
            answers[query] = described(objects)
            times[query].append(statistics.median(seconds))
        before, after = answers[WITHOUT_TEXT], answers[WITH_TEXT]
        print(f"frame {frame}: {len(before)} objects without text, {len(after)} with text")
        print(f"  {'without text':44s} | with text")
        for index in range(max(len(before), len(after))):
            left = before[index] if index < len(before) else None
            right = after[index] if index < len(after) else None
            show = lambda r: "" if r is None else f"{r[0]} {r[1]:.2f} {r[2][:14]!r} {r[3]}"  # noqa: E731
            print(f"  {show(left):44s} | {show(right)}")
        print(f"  seconds per query: without {times[WITHOUT_TEXT][-1]:.3f}, with {times[WITH_TEXT][-1]:.3f}")
        if frame in CHEEZ_IT:
            named_by_text[frame] = "Cheez-It crackers" in at(after, CHEEZ_IT[frame])
        named_after = {r[3]: r[0] for r in after}
        lost += [
            f"frame {frame}: {r[0]} at {r[3]}"
            for r in before
            if r[0] != UNKNOWN and named_after.get(r[3], UNKNOWN) == UNKNOWN
        ]
    without, with_text = (statistics.mean(times[q]) for q in (WITHOUT_TEXT, WITH_TEXT))
    ratio = with_text / without
    print(f"mean seconds per query: without text {without:.3f}, with text {with_text:.3f}, ratio {ratio:.2f}")
    named = all(named_by_text.values())
    print(
        f"goal: the Cheez-It box named with text on frames {sorted(named_by_text)}: {'met' if named else 'NOT met'}"
        f" ({named_by_text})"
    )
    kept = "met" if not lost else "NOT met"
    print(f"goal: no object named without text is unknown (or unseen) with text: {kept} {lost}")


if __name__ == "__main__":
    main()
