"""Benchmark of serving (issue 14): latency, feedback rate, tick jitter and memory of ``robokudo serve``.

Parts (each selectable; no part flag runs them all), each printing its goal and whether it is met:

* ``--latency``: warm served answer (a WebSocket goal to one ``robokudo serve``) vs a cold ``robokudo query``, side
  by side: median and p95 seconds, for "find milk in fridge" on the built-in kitchen and for a detect query on a
  shared real frame (the uoc RealSense recording, served as a live stream, cold on its frame 0). Goals: served <=
  1/10 cold, and served latency <= 2 ticks + the tree's own run time (the result's ``timing.run_ms``).
* ``--feedback``: a running continuous task (``track`` queries, "track the milk" by default): answers sent as
  feedback per second vs the engine's tick rate (both measured over the same window, the tick rate from the
  ``/robokudo/tree_status`` tick numbers), and whether the server forwarded every answer (the AnswerStep's run
  count in the tree status vs the answers received). Goal: feedback rate within 10% of the engine rate.
* ``--jitter``: tick period error ``|period - 1/rate|`` at 30 Hz with 8 clients connected and subscribed to
  ``/robokudo/tree_status``: p50 and p99 ms, with no goal (the engine perceives and the slot idles) and with a
  running track task; also each tick's own run time and how many ticks ran longer than the period. Goal: p99
  <= 5 ms.
* ``--memory``: the server's resident memory after 100 and after 10,000 goals sent one after the other. The goals
  are cheap ones (``detect {obj: {color: red, location: anywhere}, timeout: 0s}``: parsed, planned, the tree built
  and swapped into the slot, where it runs one tick before the passed deadline cancels it and the answer comes
  from memory) with a real detect run every ``--real-every`` goals. Goal: growth <= 10%. Then, on the same
  server, ``--ocr-goals`` goals whose tree reads text ("find milk in fridge"): MiB added per goal (each TextReader
  builds its own OCR engine). A workload stops early when the server's RSS passes ``--memory-cap-mib``.

The server is always a separate process and the clients speak the rosbridge protocol (``websockets``), so the parts
depend only on the protocol. Only ``--jitter`` starts the server through this script's ``--serve-ticks`` mode, the
one place that uses the service's Python API (:func:`serve_recording_ticks`, built like ``robokudo serve``'s own
``run``): it records each tick's start and end (``time.monotonic``, comparable across processes) and writes them when
the server stops.

Run: ``.venv/bin/python bench/bench_serve.py [--latency] [--feedback] [--jitter] [--memory] [options]``
"""

from __future__ import annotations

import argparse
import asyncio
import itertools
import json
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from websockets.sync.client import ClientConnection, connect

ROOT = Path(__file__).resolve().parents[1]
QUERY = "find milk in fridge"
ACTION = "/robokudo/query"
TREE_STATUS = "/robokudo/tree_status"
START_LIMIT = 180.0
RECEIVE_LIMIT = 120.0
TRACK_QUERIES = ("track the milk", "track red objects anywhere")
CHEAP_GOAL = "detect {obj: {color: red, location: anywhere}, timeout: 0s}"
REAL_GOAL = "detect {obj: {location: anywhere}}"
OCR_GOAL = "find milk in fridge"
"""A goal whose tree reads text (TextReader): measured on its own, as each such goal adds memory (see the part)."""
ANSWER_STEP = "AnswerStep"


def percentile(values: list[float], share: float) -> float:
    """The ``share`` quantile of ``values`` (nearest rank)."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(share * (len(ordered) - 1)))]


def verdict(met: bool) -> str:
    return "met" if met else "NOT met"


# ------------------------------------------------------------------------------------------- server process


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@dataclass
class Server:
    """A server process and where it listens."""

    process: subprocess.Popen[str]
    port: int

    @property
    def url(self) -> str:
        return f"ws://127.0.0.1:{self.port}"

    def rss_mib(self) -> float:
        """Resident memory of the server process (MiB), from /proc."""
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
        raise RuntimeError("no VmRSS in /proc (Linux only)")


@contextmanager
def running(command: list[str], environment: dict[str, str]) -> Iterator[Server]:
    """Start ``command`` (given ``--port``), wait for its ``serving on`` line; SIGTERM it afterwards."""
    port = free_port()
    process = subprocess.Popen(
        [*command, "--port", str(port)], cwd=ROOT, env=environment, stdout=subprocess.PIPE, text=True
    )
    try:
        assert process.stdout is not None
        deadline = time.monotonic() + START_LIMIT
        while not (line := process.stdout.readline()).startswith("serving on"):
            if (not line and process.poll() is not None) or time.monotonic() > deadline:
                raise RuntimeError(f"the server did not start: {' '.join(command)}")
        yield Server(process, port)
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
        process.wait(60)


def serve_command(rate: float | None = None) -> list[str]:
    command = [sys.executable, "-m", "robokudo", "serve"]
    return command if rate is None else [*command, "--rate", f"{rate:g}"]


def environment_in(folder: str) -> dict[str, str]:
    return {
        **os.environ,
        "PYTHONPATH": str(ROOT),
        "ROBOKUDO_USER_ONTOLOGY": str(Path(folder) / "user.ttl"),
        "ROBOKUDO_BELIEF_STORE": str(Path(folder) / "beliefs.sqlite"),
    }


# ------------------------------------------------------------------------------------------- protocol


def send_goal(connection: ClientConnection, goal_id: str, query: str) -> None:
    message = {"op": "send_action_goal", "id": goal_id, "action": ACTION, "args": {"query": query}}
    connection.send(json.dumps(message))


def subscribe(connection: ClientConnection, subscription_id: str) -> None:
    connection.send(json.dumps({"op": "subscribe", "id": subscription_id, "topic": TREE_STATUS}))


def result_of(connection: ClientConnection, goal_id: str) -> dict[str, Any]:
    """Wait for the goal's result (skipping everything else)."""
    while True:
        reply = json.loads(connection.recv(timeout=RECEIVE_LIMIT))
        if reply["op"] == "action_result" and reply["id"] == goal_id:
            return reply


def node_runs(tree: dict[str, Any], name: str) -> int | None:
    """The run count of the node ``name`` in a tree status (None when absent or without timing)."""
    pending = [tree]
    while pending:
        node = pending.pop()
        if node["name"] == name and "timing" in node:
            return int(node["timing"]["runs"])
        pending.extend(node.get("children", []))
    return None


# ------------------------------------------------------------------------------------------- latency


REAL_FRAMES = ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense"
REAL_QUERY = "detect { obj: { type: Cup } }"


@dataclass(frozen=True)
class Scenario:
    """What the latency part asks: a query on an input (None: the kitchen), served and cold."""

    name: str
    query: str
    input_path: Path | None = None

    def serve_options(self) -> list[str]:
        return [] if self.input_path is None else ["--input", str(self.input_path)]

    def query_options(self) -> list[str]:
        return [] if self.input_path is None else ["--input", str(self.input_path), "--frame", "0"]


def served(scenario: Scenario, goals: int, environment: dict[str, str], rate: float) -> tuple[list[float], list[float]]:
    """Goal -> result latencies of ``goals`` goals sent one after the other to one server, and each goal's
    latency beyond its tree's own run (``timing.run_ms`` of the result)."""
    latencies, overheads = [], []
    command = [*serve_command(rate), *scenario.serve_options()]
    with running(command, environment) as server, connect(server.url) as connection:
        for number in range(goals + 1):
            goal_id = f"g{number}"
            started = time.perf_counter()
            send_goal(connection, goal_id, scenario.query)
            reply = result_of(connection, goal_id)
            elapsed = time.perf_counter() - started
            if reply["status"] != 4:
                raise RuntimeError(f"goal {goal_id} ended {reply}")
            if number:  # the first goal warms the process up
                latencies.append(elapsed)
                overheads.append(elapsed - reply["values"]["timing"]["run_ms"] / 1e3)
    return latencies, overheads


def cold(scenario: Scenario, runs: int, environment: dict[str, str]) -> list[float]:
    """Wall times of ``runs`` ``robokudo query`` processes."""
    latencies = []
    for _ in range(runs):
        started = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "robokudo", "query", scenario.query, *scenario.query_options()],
            cwd=ROOT,
            env=environment,
            check=True,
            stdout=subprocess.DEVNULL,
        )
        latencies.append(time.perf_counter() - started)
    return latencies


def latency_part(args: argparse.Namespace, environment: dict[str, str]) -> None:
    scenarios = [Scenario("kitchen", QUERY)]
    if REAL_FRAMES.is_dir():
        scenarios.append(Scenario("real frame", REAL_QUERY, REAL_FRAMES))
    else:
        print(f"latency: {REAL_FRAMES} is missing: the real-frame scenario is left out")
    period = 1.0 / args.rate
    for scenario in scenarios:
        warm, overheads = served(scenario, args.goals, environment, args.rate)
        cli = cold(scenario, args.cold, environment)
        where = "the built-in kitchen" if scenario.input_path is None else scenario.input_path.name
        print(f"latency: warm served goal vs cold CLI, {scenario.query!r} on {where}")
        for name, values in (("served", warm), ("cold CLI", cli)):
            median, p95 = statistics.median(values), percentile(values, 0.95)
            print(f"  {name:>9}: median {median:.3f} s  p95 {p95:.3f} s  (n={len(values)})")
        ratio = statistics.median(warm) / statistics.median(cli)
        print(f"  served / cold (median): {ratio:.3f}  (goal <= 0.1: {verdict(ratio <= 0.1)})")
        ticks = [overhead / period for overhead in overheads]
        worst = percentile(ticks, 0.95)
        print(
            f"  served beyond the tree's own run: median {statistics.median(ticks):.2f} ticks, p95 {worst:.2f} ticks "
            f"of {1e3 * period:.1f} ms (goal <= 2 ticks: {verdict(worst <= 2.0)})"
        )


# ------------------------------------------------------------------------------------------- feedback rate


@dataclass
class FeedbackFigures:
    query: str
    answers_per_second: float
    ticks_per_second: float
    answers: int
    answer_step_runs: int | None
    feedback_per_second: float
    """The goal's progress feedback (phase ``running``): one per tick that ran its tree."""


def feedback_rate(
    query: str, rate: float, warmup: float, window: float, environment: dict[str, str]
) -> FeedbackFigures:
    """Answers (feedback) per second of a running track goal and engine ticks per second over one window."""
    with running(serve_command(rate), environment) as server, connect(server.url) as connection:
        subscribe(connection, "ticks")
        send_goal(connection, "track", query)
        answers: list[float] = []
        feedback: list[float] = []
        ticks: list[tuple[float, int, int | None]] = []  # (arrival, tick number, AnswerStep runs)
        started = None
        while started is None or time.monotonic() < started + warmup + window:
            message = json.loads(connection.recv(timeout=RECEIVE_LIMIT))
            now = time.monotonic()
            if message["op"] == "publish" and message["topic"] == TREE_STATUS:
                status = message["msg"]
                ticks.append((now, int(status["tick"]), node_runs(status["tree"], ANSWER_STEP)))
            elif message["op"] == "action_feedback":
                if message["values"].get("phase") == "running":
                    feedback.append(now)
                elif message["values"].get("phase") == "answer":
                    answers.append(now)
                    started = started if started is not None else now  # the window opens after the first answer
            elif message["op"] == "action_result":
                raise RuntimeError(f"the track goal ended: {message}")
    assert started is not None
    low, high = started + warmup, started + warmup + window
    in_window = [t for t in ticks if low <= t[0] <= high]
    first, last = in_window[0], in_window[-1]
    span = last[0] - first[0]
    received = sum(first[0] < t <= last[0] for t in answers)
    messages = sum(first[0] < t <= last[0] for t in feedback)
    ticks_per_second = (last[1] - first[1]) / span
    runs = None if first[2] is None or last[2] is None else last[2] - first[2]
    return FeedbackFigures(query, received / span, ticks_per_second, received, runs, messages / span)


def feedback_part(args: argparse.Namespace, environment: dict[str, str]) -> None:
    print(
        "feedback: a running track goal's progress feedback (one per tick that ran its tree) and answers (one per "
        f"run) per second vs the engine's ticks per second (--rate {args.rate:g})"
    )
    for query in args.track_query:
        figures = feedback_rate(query, args.rate, args.warmup, args.feedback_seconds, environment)
        share = figures.feedback_per_second / figures.ticks_per_second
        answered = figures.answers_per_second / figures.ticks_per_second
        lost = (
            "answer step runs unknown"
            if figures.answer_step_runs is None
            else f"{figures.answers} answers received for {figures.answer_step_runs} answer-step runs"
        )
        print(
            f"  {query!r}: {figures.feedback_per_second:.2f} feedback/s, {figures.answers_per_second:.2f} answers/s, "
            f"engine {figures.ticks_per_second:.2f} of {args.rate:g} ticks/s (feedback {share:.0%}, answers "
            f"{answered:.0%} of the engine rate); {lost}"
        )
        print(f"    goal: feedback within 10% of the engine rate: {verdict(abs(share - 1) <= 0.1)}")


# ------------------------------------------------------------------------------------------- tick jitter


def serve_recording_ticks(log: Path, options: list[str]) -> int:
    """``--serve-ticks``: serve as ``robokudo serve OPTIONS`` does, recording each tick's start and end; writes
    ``{starts, ends}`` to ``log`` when the server stops. The only part of this script that uses the service's API."""
    from robokudo.application.commands import serve as serve_command
    from robokudo.application.server.runner import ServerConfig, serve
    from robokudo.application.service import AnsweringService

    parser = argparse.ArgumentParser()
    serve_command.add_arguments(parser)
    args = parser.parse_args(options)
    stream = serve_command.source_stream(args)
    service = AnsweringService.open(args.db, input_path=args.input, hz=args.rate, stream=stream)
    starts: list[float] = []
    ends: list[float] = []
    service.engine.tree.add_pre_tick_handler(lambda _: starts.append(time.monotonic()))
    service.engine.tree.add_post_tick_handler(lambda _: ends.append(time.monotonic()))
    config = ServerConfig(host=args.host, port=args.port)
    asyncio.run(serve(service, config, on_ready=lambda address: print(f"serving on {address}", flush=True)))
    log.write_text(json.dumps({"starts": starts, "ends": ends[: len(starts)]}))
    return 0


@dataclass
class JitterFigures:
    errors_ms: list[float]
    fitting_errors_ms: list[float]
    durations_ms: list[float]
    publications: list[int]


def tick_jitter(
    clients: int, rate: float, warmup: float, window: float, track: str | None, environment: dict[str, str]
) -> JitterFigures:
    """Period errors of the ticks in one window with ``clients`` subscribed clients (one also running ``track``)."""
    with tempfile.TemporaryDirectory() as folder:
        log = Path(folder) / "ticks.json"
        command = [sys.executable, str(Path(__file__).resolve()), "--serve-ticks", str(log), "--rate", f"{rate:g}"]
        stop = threading.Event()
        counts = [0] * clients
        subscribed = threading.Barrier(clients + 1)
        with running(command, environment) as server:

            def client(number: int) -> None:
                with connect(server.url) as connection:
                    subscribe(connection, f"c{number}")
                    if number == 0 and track is not None:
                        send_goal(connection, "track", track)
                    subscribed.wait(START_LIMIT)
                    while not stop.is_set():
                        try:
                            message = json.loads(connection.recv(timeout=0.5))
                        except TimeoutError:
                            continue
                        counts[number] += message["op"] == "publish"

            threads = [threading.Thread(target=client, args=(n,)) for n in range(clients)]
            for thread in threads:
                thread.start()
            subscribed.wait(START_LIMIT)
            time.sleep(warmup)
            low = time.monotonic()
            time.sleep(window)
            high = time.monotonic()
            stop.set()
            for thread in threads:
                thread.join()
        ticks = json.loads(log.read_text())
    timed = [(start, end) for start, end in zip(ticks["starts"], ticks["ends"], strict=False) if low <= start <= high]
    period = 1.0 / rate
    errors, fitting = [], []
    for (start, end), (following, _) in itertools.pairwise(timed):
        error = abs((following - start) - period) * 1e3
        errors.append(error)
        if end - start <= period:  # this tick fit its period: the error is the scheduling's, not the tree's
            fitting.append(error)
    return JitterFigures(errors, fitting, [(end - start) * 1e3 for start, end in timed], counts)


def jitter_part(args: argparse.Namespace, environment: dict[str, str]) -> None:
    print(f"jitter: |tick period - 1/{args.rate:g} s| with {args.clients} clients subscribed to {TREE_STATUS}")
    for label, track in (("no goal", None), (f"running {args.track_query[-1]!r}", args.track_query[-1])):
        figures = tick_jitter(args.clients, args.rate, args.warmup, args.jitter_seconds, track, environment)
        if len(figures.errors_ms) < 2:
            print(f"  {label}: the engine did not tick ({len(figures.errors_ms) + 1} ticks in the window)")
            continue
        p50, p99 = percentile(figures.errors_ms, 0.5), percentile(figures.errors_ms, 0.99)
        overran = sum(d > 1e3 / args.rate for d in figures.durations_ms)
        print(
            f"  {label}: p50 {p50:.2f} ms  p99 {p99:.2f} ms over {len(figures.errors_ms)} periods; tick run time "
            f"median {statistics.median(figures.durations_ms):.2f} ms, {overran} ticks longer than the period; "
            f"publications per client {min(figures.publications)}..{max(figures.publications)}"
        )
        if overran and figures.fitting_errors_ms:
            fitting = percentile(figures.fitting_errors_ms, 0.99)
            print(f"    after the {len(figures.fitting_errors_ms)} ticks that fit their period: p99 {fitting:.2f} ms")
        print(f"    goal: p99 <= 5 ms: {verdict(p99 <= 5.0)}")


# ------------------------------------------------------------------------------------------- memory


def goals_rss(
    server: Server, connection: ClientConnection, queries: list[str], checkpoints: set[int], cap_mib: float
) -> tuple[dict[int, float], dict[int, int]]:
    """Send ``queries`` one after the other; the server's RSS (MiB) at each checkpoint (goal number) and the count of
    each terminal status. Stops early once the RSS passes ``cap_mib`` (the last goal is then a checkpoint)."""
    rss: dict[int, float] = {0: server.rss_mib()}
    statuses: dict[int, int] = {}
    started = time.perf_counter()
    for number, query in enumerate(queries, start=1):
        send_goal(connection, f"m{number}", query)
        status = int(result_of(connection, f"m{number}")["status"])
        statuses[status] = statuses.get(status, 0) + 1
        over = number % 50 == 0 and server.rss_mib() > cap_mib
        if number in checkpoints or over or number == len(queries):
            rss[number] = server.rss_mib()
            print(f"  after {number:>6} goals: RSS {rss[number]:.1f} MiB  ({time.perf_counter() - started:.0f} s)")
        if over:
            print(f"  stopped: the RSS passed --memory-cap-mib {cap_mib:g}")
            break
    return rss, statuses


def memory_part(args: argparse.Namespace, environment: dict[str, str]) -> None:
    goals = args.memory_goals
    checkpoints = {100, *(c for c in (1000, goals // 2) if c < goals), goals}
    print(f"memory: server RSS over {goals} goals ({CHEAP_GOAL!r}, every {args.real_every}th {REAL_GOAL!r})")
    queries = [REAL_GOAL if n % args.real_every == 0 else CHEAP_GOAL for n in range(1, goals + 1)]
    with running(serve_command(), environment) as server, connect(server.url) as connection:
        rss, statuses = goals_rss(server, connection, queries, checkpoints, args.memory_cap_mib)
        last = max(rss)
        print(f"  goal statuses: {dict(sorted(statuses.items()))}")
        if 100 in rss and last > 100:
            growth = rss[last] / rss[100] - 1
            met = verdict(growth <= 0.10 and last == goals)
            print(f"  growth from 100 to {last} goals: {growth:+.1%}  (goal <= 10%: {met})")
        half = goals // 2
        if half in rss and half > 100 and last == goals:  # a leak keeps growing; warming up levels off
            print(f"  growth over the second half ({half} to {goals} goals): {rss[goals] / rss[half] - 1:+.1%}")
        if args.ocr_goals:
            print(f"  then {args.ocr_goals} goals {OCR_GOAL!r} (their trees read text) on the same server:")
            ocr, _ = goals_rss(server, connection, [OCR_GOAL] * args.ocr_goals, set(), args.memory_cap_mib)
            added = (ocr[max(ocr)] - ocr[0]) / max(ocr)
            print(f"  {added:+.1f} MiB per goal reading text")


# ------------------------------------------------------------------------------------------- main


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parts = parser.add_argument_group("parts (none given: all)")
    for part in ("latency", "feedback", "jitter", "memory"):
        parts.add_argument(f"--{part}", action="store_true", help=f"run the {part} part")
    parser.add_argument("--goals", type=int, default=20, help="latency: served goals (default 20)")
    parser.add_argument("--cold", type=int, default=5, help="latency: cold CLI runs (default 5)")
    parser.add_argument("--rate", type=float, default=30.0, help="feedback, jitter: engine ticks per second (30)")
    parser.add_argument(
        "--track-query", action="append", help=f"feedback: track queries (default {', '.join(TRACK_QUERIES)})"
    )
    parser.add_argument("--warmup", type=float, default=3.0, help="feedback, jitter: seconds before measuring (3)")
    parser.add_argument("--feedback-seconds", type=float, default=15.0, help="feedback: measured seconds (15)")
    parser.add_argument("--jitter-seconds", type=float, default=20.0, help="jitter: measured seconds (20)")
    parser.add_argument("--clients", type=int, default=8, help="jitter: subscribed clients (8)")
    parser.add_argument("--memory-goals", type=int, default=10_000, help="memory: goals (10000)")
    parser.add_argument("--real-every", type=int, default=50, help="memory: every Nth goal is a real detect (50)")
    parser.add_argument("--ocr-goals", type=int, default=50, help="memory: then goals reading text (50; 0: none)")
    parser.add_argument("--memory-cap-mib", type=float, default=8000, help="memory: stop above this RSS (8000)")
    parser.add_argument("--serve-ticks", type=Path, help=argparse.SUPPRESS)
    args, serve_options = parser.parse_known_args()
    if args.serve_ticks is not None:
        return serve_recording_ticks(args.serve_ticks, ["--rate", f"{args.rate:g}", *serve_options])
    if serve_options:
        parser.error(f"unrecognized arguments: {' '.join(serve_options)}")
    args.track_query = args.track_query or list(TRACK_QUERIES)
    chosen = [p for p in ("latency", "feedback", "jitter", "memory") if getattr(args, p)] or [
        "latency",
        "feedback",
        "jitter",
        "memory",
    ]
    runners = {"latency": latency_part, "feedback": feedback_part, "jitter": jitter_part, "memory": memory_part}
    for part in chosen:
        with tempfile.TemporaryDirectory() as folder:
            runners[part](args, environment_in(folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
