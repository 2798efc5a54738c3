"""Benchmark of the knowledge base: load time (cold, with and without HermiT), question latency and edit latency.

Runs on the shipped ontology with the catalog's annotator classes and on a generated one (the shipped files plus
1,000 object classes, and 200 generated annotator classes). Cold load = a fresh Python process importing the
package, finding the annotator classes and loading; warm load = another load in the same process. Question
latency = median and p99 over 10,000 mixed questions (word resolution, subsumption, profiles, default locations,
regions, providers, query keys, annotator inputs).

Edit latency (shipped ontology, ``OntologyEditor.add_object`` in one process, p50/p95 over ``--edits`` edits),
side by side: without the reasoner; with HermiT as edits run it now (a stored classification, new classes checked
incrementally); with HermiT when no classification is stored (a full run per edit); and, with ``--before REV``, the
editor of git revision REV (e.g. ``main``) loaded from git, without and with HermiT. Then the first question after
an edit (same knowledge base, and a second one that notices the change) against the median question, and the wall
time of ``robokudo ontology add-object`` processes.

    python bench/bench_ontology.py [--questions N] [--no-reasoner] [--edits N] [--before REV] [--edits-only]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypedDict

from annotators.catalog import AnnotatorCatalog
from ontology import ontology_dir, shipped_files
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import Conditions
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import type_by_name

GENERATED_CLASSES = 1000
GENERATED_ANNOTATORS = 200
GENERATED_REGIONS = 40
SEED = 7

_COLD_LOAD = """
import json, sys, time
start = time.perf_counter()
from pathlib import Path
sys.path.insert(0, sys.argv[5])
from bench_ontology import annotator_classes
from reasoning.knowledge.knowledge_base import KnowledgeBase
imported = time.perf_counter()
classes = annotator_classes(json.loads(Path(sys.argv[4]).read_text()) if sys.argv[4] else None)
found = time.perf_counter()
files = [Path(p) for p in json.loads(sys.argv[1])] or None
KnowledgeBase.load(Path(sys.argv[2]), files=files, reason=sys.argv[3] == "1", annotators=classes)
done = time.perf_counter()
print(json.dumps({"import": imported - start, "annotators": found - imported, "load": done - found}))
"""


class Declaration(TypedDict):
    """A generated annotator as plain data (JSON for the cold load): its name, ports and Capability fields."""

    name: str
    inputs: list[str]
    outputs: list[str]
    capability: dict[str, Any]


def annotator_classes(declarations: list[Declaration] | None) -> list[type[Annotator]]:
    """The catalog's annotator classes plus one generated Annotator class per declaration (if any)."""
    classes = list(AnnotatorCatalog.discover().values())
    for declared in declarations or ():
        fields = {k: tuple(v) if isinstance(v, list) else v for k, v in declared["capability"].items()}
        members = {
            "__module__": __name__,
            "__doc__": f"Generated annotator {declared['name']}.",
            "inputs": tuple(map(type_by_name, declared["inputs"])),
            "outputs": tuple(map(type_by_name, declared["outputs"])),
            "capability": Capability(**fields),
        }
        classes.append(type(declared["name"], (Annotator,), members))
    return classes


def generate(
    folder: Path,
    rng: random.Random,
    classes_count: int = GENERATED_CLASSES,
    annotators_count: int = GENERATED_ANNOTATORS,
) -> tuple[list[Path], list[Declaration]]:
    """Write the generated object classes and regions; return the full file list and the annotator declarations.

    ``classes_count`` object classes and ``annotators_count`` annotators are generated on top of the shipped ones.
    """
    base = KnowledgeBase.load(folder / "none.ttl")
    colors = base.names_of_kind("color")
    shapes = base.names_of_kind("shape")
    sizes = base.names_of_kind("size")
    materials = base.names_of_kind("material")
    region_classes = [c for c in base.names_of_kind("region_class") if c != "Region"]
    classes = [c for c in base.names_of_kind("class") if c not in ("RefrigeratedItem", "TransparentObject")]
    lines = ["@prefix rk: <http://robokudo.org/ontology#> .", "@prefix owl: <http://www.w3.org/2002/07/owl#> .",
             "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .", ""]  # fmt: skip

    def restriction(prop: str, value: str, literal: bool = False) -> str:
        kind = "owl:hasValue" if literal else "owl:someValuesFrom"
        return f"[ a owl:Restriction ; owl:onProperty rk:{prop} ; {kind} {value} ]"

    generated: list[str] = []
    for i in range(classes_count):
        name = f"GenObject{i:04d}"
        drawn = rng.randrange(len(classes) + len(generated))  # as rng.choice(classes + generated), without the copy
        parent = classes[drawn] if drawn < len(classes) else generated[drawn - len(classes)]
        supers = [f"rk:{parent}"]
        if rng.random() < 0.5:
            supers.append(restriction("typicalColor", "rk:" + rng.choice(colors)))
        if rng.random() < 0.3:
            supers.append(restriction("typicalShape", "rk:" + rng.choice(shapes)))
        if rng.random() < 0.3:
            supers.append(restriction("sizeClass", "rk:" + rng.choice(sizes)))
        if rng.random() < 0.2:
            supers.append(restriction("madeOf", "rk:" + rng.choice(materials)))
        if rng.random() < 0.2:
            supers.append(restriction("storedIn", "rk:" + rng.choice(region_classes)))
        if rng.random() < 0.2:
            supers.append(restriction("printedText", f'"text {i}"', literal=True))
        lines.append(f'rk:{name} a owl:Class ; rdfs:label "generated object {i}" ;')
        lines.append("    rdfs:subClassOf " + " ,\n        ".join(supers) + " .")
        generated.append(name)
    for i in range(GENERATED_REGIONS):
        lines.append(f'rk:gen_region_{i} a owl:NamedIndividual , rk:{rng.choice(region_classes)} ; rk:frame "map" ;')
        lines.append(f"    rk:positionX {i * 0.5} ; rk:positionY 1.0 ; rk:positionZ 0.8 ;")
        lines.append("    rk:orientationX 0.0 ; rk:orientationY 0.0 ; rk:orientationZ 0.0 ; rk:orientationW 1.0 ;")
        lines.append("    rk:sizeX 0.4 ; rk:sizeY 0.4 ; rk:sizeZ 0.4 .")
    types = base.cas_types()
    preconditions = ["NeedsDepth", "NeedsRegion", "NotForTransparentObjects"]
    all_classes = classes + generated
    declarations: list[Declaration] = []
    for i in range(annotators_count):
        inputs = rng.sample(types, rng.randint(1, 3))
        outputs = rng.sample(types, rng.randint(1, 2))
        capability: dict[str, Any] = {
            "cost_ms": round(rng.uniform(1, 100), 1),
            "reliability": round(rng.uniform(0.3, 1.0), 2),
        }
        if rng.random() < 0.4:
            capability["colors"] = tuple(rng.sample(colors, 4))
        if rng.random() < 0.4:
            capability["classes"] = tuple(rng.sample(all_classes, 5))
        if rng.random() < 0.3:
            capability["preconditions"] = (rng.choice(preconditions),)
        declarations.append(
            {"name": f"GenAnnotator{i:03d}", "inputs": inputs, "outputs": outputs, "capability": capability}
        )
    extra = folder / "generated.ttl"
    extra.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return [*shipped_files(), extra], declarations


def cold_load(
    files: list[Path], user_file: Path, reason: bool, declarations: list[Declaration] | None
) -> dict[str, float]:
    """Import + annotator classes + load in a fresh interpreter (``declarations`` None: the catalog's classes)."""
    declared = ""
    if declarations is not None:
        declared = str(user_file.with_name("annotators.json"))
        Path(declared).write_text(json.dumps(declarations), encoding="utf-8")
    argv = [json.dumps([str(f) for f in files]), str(user_file), "1" if reason else "0", declared]
    argv.append(str(Path(__file__).resolve().parent))
    output = subprocess.run(
        [sys.executable, "-c", _COLD_LOAD, *argv], check=True, capture_output=True, text=True, cwd=ontology_dir().parent
    )
    return json.loads(output.stdout.strip().splitlines()[-1])


def plural(word: str) -> str:
    """A regular English plural of the last word."""
    if word.endswith(("s", "x", "ch", "sh")):
        return word + "es"
    if word.endswith("y") and word[-2:-1] not in "aeiou":
        return word[:-1] + "ies"
    return word + "s"


def questions(kb: KnowledgeBase, count: int, rng: random.Random) -> list[tuple[str, Callable[[], object]]]:
    """A reproducible mix of ``count`` typed questions a planner asks."""
    classes = kb.names_of_kind("class")
    words = [w for c in classes for w in (kb.label(c), *kb.synonyms(c))]
    variants = [str.lower, str.upper, lambda w: w.replace(" ", "_"), plural, str.title]
    region_classes = kb.names_of_kind("region_class")
    colors = [kb.label(c) for c in kb.names_of_kind("color")]
    annotators = [a.name for a in kb.annotators()]
    keys = ["color", "colour", "type", "shape", "size", "text", "pose", "location"]
    no_depth = Conditions(depth=False)
    made: list[tuple[str, Callable[[], object]]] = []
    for _ in range(count):
        kind = rng.randrange(10)
        if kind == 0:
            word = rng.choice(variants)(rng.choice(words))
            made.append(("resolve", lambda w=word: kb.resolve(w)))
        elif kind == 1:
            a, b = rng.choice(classes), rng.choice(classes)
            made.append(("is_subclass", lambda a=a, b=b: kb.is_subclass(a, b)))
        elif kind == 2:
            name = rng.choice(classes)
            made.append(("object_profile", lambda n=name: kb.object_profile(n)))
        elif kind == 3:
            name = rng.choice(classes)
            made.append(("default_location", lambda n=name: kb.default_location(n)))
        elif kind == 4:
            name = rng.choice(region_classes)
            made.append(("regions_of_class", lambda n=name: kb.regions_of_class(n)))
        elif kind == 5:
            color = rng.choice(colors)
            made.append(("providers(color)", lambda c=color: kb.providers("SemanticColor", value=c)))
        elif kind == 6:
            name = rng.choice(classes)
            made.append(
                (
                    "providers(class)",
                    lambda n=name: kb.providers("ObjectHypothesis", object_class=n, conditions=no_depth),
                )
            )
        elif kind == 7:
            key = rng.choice(keys)
            made.append(("annotation_type_for_key", lambda k=key: kb.annotation_type_for_key(k)))
        elif kind == 8:
            name = rng.choice(annotators)
            made.append(("inputs_of", lambda n=name: kb.inputs_of(n)))
        else:
            name = rng.choice(classes)
            made.append(("subclasses(direct)", lambda n=name: kb.subclasses(n, direct=True)))
    return made


def latency(kb: KnowledgeBase, count: int, rng: random.Random) -> dict[str, list[float]]:
    """Seconds per question, grouped by question kind (plus "all")."""
    asked = questions(kb, count, rng)
    for _, question in asked[:500]:  # warm-up
        question()
    timings: dict[str, list[float]] = defaultdict(list)
    clock = time.perf_counter_ns
    for name, question in asked:
        start = clock()
        question()
        elapsed = (clock() - start) / 1e9
        timings[name].append(elapsed)
        timings["all"].append(elapsed)
    return timings


def p99(values: list[float]) -> float:
    """The 99th percentile."""
    return statistics.quantiles(values, n=100)[98] if len(values) > 1 else values[0]


def bench(
    label: str,
    files: list[Path],
    declarations: list[Declaration] | None,
    user_file: Path,
    count: int,
    reason: bool,
    rng: random.Random,
) -> None:
    """Print load times and question latencies for one ontology and its annotator classes."""
    print(f"\n== {label}")
    runs = [("no reasoning ", False), ("with HermiT  ", True)] if reason else [("no reasoning ", False)]
    for name, with_hermit in runs:
        cold = cold_load(files, user_file, with_hermit, declarations)
        print(
            f"cold load, {name}: import {cold['import'] * 1e3:7.0f} ms + annotator classes "
            f"{cold['annotators'] * 1e3:7.0f} ms + load {cold['load'] * 1e3:7.0f} ms"
        )
    classes = annotator_classes(declarations)
    warm = []
    for _ in range(3):
        start = time.perf_counter()
        kb = KnowledgeBase.load(user_file, files=files, annotators=classes)
        warm.append(time.perf_counter() - start)
    print(f"warm load, no reasoning : {min(warm) * 1e3:7.0f} ms (best of 3)")
    start = time.perf_counter()
    kb.reload()
    print(f"reload (files unchanged): {(time.perf_counter() - start) * 1e3:7.0f} ms")
    print(
        f"size: {len(kb.names_of_kind('class'))} object classes, {len(kb.annotators())} annotators, "
        f"{len(kb.regions())} regions, {len(kb.index.words)} word keys"
    )
    timings = latency(kb, count, rng)
    print(f"{'question':26s} {'n':>6s} {'median µs':>10s} {'p99 µs':>10s}")
    for name in sorted(timings, key=lambda n: (n == "all", n)):
        values = timings[name]
        print(f"{name:26s} {len(values):6d} {statistics.median(values) * 1e6:10.1f} {p99(values) * 1e6:10.1f}")


def previous_editor_class(revision: str) -> type | None:
    """The OntologyEditor of the editing module at a git revision (None when git or the revision is missing)."""
    root = Path(__file__).resolve().parents[1]
    try:
        source = subprocess.run(
            ["git", "show", f"{revision}:reasoning/knowledge/editing.py"], cwd=root, capture_output=True, check=True
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    spec = importlib.util.spec_from_loader(f"editing_at_{revision}", loader=None)
    assert spec is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    exec(compile(source, f"{revision}:reasoning/knowledge/editing.py", "exec"), module.__dict__)
    return module.OntologyEditor


def percentiles(values: list[float]) -> tuple[float, float]:
    """p50 and p95."""
    ordered = sorted(values)
    return statistics.median(ordered), ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]


def time_edits(editor_class: type, folder: Path, label: str, count: int, **options: Any) -> list[float]:
    """Seconds per ``add_object`` of ``count`` new classes into a fresh user file (one knowledge base, one editor).

    With ``options["forget"]`` the stored classification is deleted before each edit (a full HermiT run each)."""
    forget = options.pop("forget", False)
    user_file = folder / label.replace(" ", "-") / "user.ttl"
    kb = KnowledgeBase.load(user_file, annotators=annotator_classes(None))
    editor = editor_class(kb, **options)
    if options.get("use_reasoner") and hasattr(editor, "check"):
        editor.check(code=False)  # a stored classification, as after `robokudo ontology check` or the first edit
    times = []
    colors = ["white", "red", "blue", "green"]
    for i in range(count):
        if forget:
            for stored in user_file.parent.glob("*.reasoner.json"):
                stored.unlink()
        start = time.perf_counter()
        editor.add_object(f"BenchThing{i}", ["Milk" if i % 2 else "Cup"], colors=[colors[i % 4]], texts=[f"t{i}"])
        times.append(time.perf_counter() - start)
    return times


def bench_edits(count: int, before: str | None) -> None:
    """Print edit latencies side by side, the first question after an edit and CLI edit wall times."""
    from reasoning.knowledge.editing import OntologyEditor

    print(f"\n== edit latency: add-object on the shipped ontology, {count} edits per row (in one process)")
    rows: list[tuple[str, type, int, dict[str, Any]]] = [
        ("now, no reasoner", OntologyEditor, count, {"use_reasoner": False}),
        ("now, HermiT (stored classification)", OntologyEditor, count, {"use_reasoner": True}),
        (
            "now, HermiT (nothing stored: full run)",
            OntologyEditor,
            max(3, count // 4),
            {"use_reasoner": True, "forget": True},
        ),
    ]
    previous = previous_editor_class(before) if before else None
    if before and previous is None:
        print(f"(git revision {before} not found: no 'before' rows)")
    if previous is not None:
        rows += [
            (f"{before}, no reasoner", previous, count, {"use_reasoner": False}),
            (f"{before}, HermiT", previous, max(3, count // 4), {"use_reasoner": True}),
        ]
    print(f"{'editor':42s} {'n':>4s} {'p50 ms':>9s} {'p95 ms':>9s}")
    with tempfile.TemporaryDirectory() as folder:
        for label, editor_class, n, options in rows:
            p50, p95 = percentiles(time_edits(editor_class, Path(folder), label, n, **options))
            print(f"{label:42s} {n:4d} {p50 * 1e3:9.0f} {p95 * 1e3:9.0f}")
        first_question_after_edit(Path(folder) / "questions" / "user.ttl")
        cli_edits(Path(folder) / "cli" / "user.ttl")


def first_question_after_edit(user_file: Path, rounds: int = 20) -> None:
    """The first question after an edit, asked of the editing knowledge base and of a second one (another holder
    of the ontology, which notices the change with ``reload_if_changed``), against the median question."""
    from reasoning.knowledge.editing import OntologyEditor

    classes = annotator_classes(None)
    kb = KnowledgeBase.load(user_file, annotators=classes)
    other = KnowledgeBase.load(user_file, annotators=classes)
    editor = OntologyEditor(kb, use_reasoner=False)
    same, noticing, usual = [], [], []
    clock = time.perf_counter
    for i in range(rounds):
        editor.add_object(f"AskedThing{i}", ["Milk"])
        start = clock()
        kb.object_profile(f"AskedThing{i}")
        same.append(clock() - start)
        start = clock()
        other.reload_if_changed()
        other.object_profile(f"AskedThing{i}")
        noticing.append(clock() - start)
        for _ in range(5):
            start = clock()
            kb.object_profile(f"AskedThing{i}")  # the same question again
            usual.append(clock() - start)
    print("\n== the first question after an edit (object_profile of the new class), median of", rounds)
    print(f"same knowledge base as the editor : {statistics.median(same) * 1e6:9.1f} µs")
    print(f"the same question asked again     : {statistics.median(usual) * 1e6:9.1f} µs")
    print(f"second knowledge base (reloads)   : {statistics.median(noticing) * 1e3:9.1f} ms")


def cli_edits(user_file: Path, runs: int = 3) -> None:
    """Wall time of ``robokudo ontology add-object`` processes (start-up and loading included)."""
    root = Path(__file__).resolve().parents[1]
    environment = {**os.environ, "ROBOKUDO_USER_ONTOLOGY": str(user_file), "PYTHONPATH": str(root)}
    print(f"\n== robokudo ontology add-object as a process, median of {runs}")
    for label, extra in (("no reasoner", ["--no-reasoner"]), ("HermiT", [])):
        times = []
        for i in range(runs):
            name = f"Cli{label.replace(' ', '')}{i}"
            command = [sys.executable, "-m", "robokudo", "ontology", *extra, "add-object", name, "--is-a", "Milk"]
            start = time.perf_counter()
            subprocess.run(command, env=environment, cwd=root, check=True, capture_output=True)
            times.append(time.perf_counter() - start)
        print(f"{label:12s}: {statistics.median(times):6.2f} s   (runs: {', '.join(f'{t:.2f}' for t in times)})")


def main() -> int:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--questions", type=int, default=10_000)
    parser.add_argument("--no-reasoner", action="store_true", help="skip the HermiT cold loads")
    parser.add_argument("--edits", type=int, default=20, help="edits per row of the edit latency table")
    parser.add_argument("--before", metavar="REV", help="also time the editor of this git revision (e.g. main)")
    parser.add_argument("--edits-only", action="store_true", help="only the edit latency part")
    args = parser.parse_args()
    bench_edits(args.edits, args.before)
    if args.edits_only:
        return 0
    rng = random.Random(SEED)
    with tempfile.TemporaryDirectory() as folder:
        user_file = Path(folder) / "user.ttl"
        shipped = list(shipped_files())
        bench("shipped ontology", shipped, None, user_file, args.questions, not args.no_reasoner, rng)
        files, declarations = generate(Path(folder), rng)
        label = f"generated: shipped + {GENERATED_CLASSES} classes, {GENERATED_ANNOTATORS} annotators"
        bench(label, files, declarations, user_file, args.questions, not args.no_reasoner, rng)
    return 0


if __name__ == "__main__":
    sys.exit(main())
