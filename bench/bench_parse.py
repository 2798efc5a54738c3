"""Parse time per query for the nested, natural and JSON forms (not a test).

Each form parses 10,000 queries, cycling through that form's inputs in
``queries/corpus.jsonl``; every parse is timed on its own and the median,
90th percentile and mean are printed in microseconds.  Building the lark
parsers (once per process) is timed separately.  Goal: well under 1 ms.
"""

from __future__ import annotations

import itertools
import json
import statistics
import time
from collections.abc import Callable
from importlib import resources

from queries import Query, parse_json, parse_natural, parse_nested
from queries.json_form import json_parser
from queries.nested import nested_parser

QUERIES_PER_FORM = 10_000
GOAL_US = 1000.0


def corpus_inputs(form: str) -> list[str]:
    """Return the corpus inputs written in ``form``."""
    text = resources.files("queries").joinpath("corpus.jsonl").read_text(encoding="utf-8")
    entries = [json.loads(line) for line in text.splitlines() if line.strip()]
    return [entry["input"] for entry in entries if entry["form"] == form]


def time_parses(parse: Callable[[str], Query], inputs: list[str], count: int) -> list[float]:
    """Parse ``count`` queries cycling through ``inputs``; return each time in µs."""
    timings: list[float] = []
    clock = time.perf_counter_ns
    for text in itertools.islice(itertools.cycle(inputs), count):
        start = clock()
        parse(text)
        timings.append((clock() - start) / 1000.0)
    return timings


def main() -> int:
    """Run the benchmark and print one line per form."""
    start = time.perf_counter()
    nested_parser()
    json_parser()
    build_ms = (time.perf_counter() - start) * 1000.0
    print(f"parser construction (once per process): {build_ms:.1f} ms")
    print(f"{'form':<8} {'inputs':>6} {'queries':>8} {'median µs':>10} {'p90 µs':>8} {'mean µs':>8}")
    forms: list[tuple[str, Callable[[str], Query]]] = [
        ("nested", parse_nested),
        ("natural", parse_natural),
        ("json", parse_json),
    ]
    worst = 0.0
    for form, parse in forms:
        inputs = corpus_inputs(form)
        time_parses(parse, inputs, len(inputs))  # warm up
        timings = time_parses(parse, inputs, QUERIES_PER_FORM)
        median = statistics.median(timings)
        p90 = statistics.quantiles(timings, n=10)[-1]
        mean = statistics.fmean(timings)
        worst = max(worst, median)
        print(f"{form:<8} {len(inputs):>6} {len(timings):>8} {median:>10.1f} {p90:>8.1f} {mean:>8.1f}")
    verdict = "met" if worst < GOAL_US else "MISSED"
    print(f"goal: median under {GOAL_US:.0f} µs per query: {verdict}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
