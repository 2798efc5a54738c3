"""The server: a websockets (asyncio) server on the main thread's event loop in front of one answering service.

Goals and service calls run on the goal manager's worker thread (:mod:`.goals`), never on the event loop. After
every engine tick the tree's statuses are handed to the loop (``call_soon_threadsafe``) and published to the
``/robokudo/tree_status`` subscribers, and every frame's belief changes to the ``/robokudo/beliefs`` subscribers.
SIGINT or SIGTERM stops the server: open goals are aborted with the
reason, their results are sent, the belief store is closed and :func:`serve` returns.
"""

from __future__ import annotations

import asyncio
import contextlib
import gc
import ipaddress
import signal
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import py_trees
from websockets.asyncio.server import ServerConnection
from websockets.asyncio.server import serve as websocket_server

from reasoning.fusion.tracking import TrackStep
from robokudo.application.server.belief_changes import belief_changes
from robokudo.application.server.camera_topics import FramePicker, ShownFrame, image_messages
from robokudo.application.server.goals import GoalManager
from robokudo.application.server.protocol import (
    BELIEFS_TOPIC,
    DEPTH_TOPIC,
    IMAGE_TOPIC,
    MAX_MESSAGE_BYTES,
    TREE_STATUS_TOPIC,
    publish,
)
from robokudo.application.server.services import SERVICES
from robokudo.application.server.session import Session, Subscribers
from robokudo.application.server.tree_status import tree_status
from robokudo.application.server.web_page import page_handler
from robokudo.application.service import AnsweringService
from robokudo.core.pipeline import finished_run_cas

if TYPE_CHECKING:
    from robokudo.application.rerun_log import TickRecorder

FRAME_LIMIT = 8 * MAX_MESSAGE_BYTES
"""Frames above this are refused by the WebSocket layer (connection closed); up to it, a message over
:data:`MAX_MESSAGE_BYTES` gets a status error and the connection stays open."""

FLUSH_SECONDS = 2.0
"""How long the shutdown waits for the last results to be written to each client."""


@dataclass(frozen=True)
class ServerConfig:
    """Where the server listens and the token clients must send (None: no authentication)."""

    host: str = "127.0.0.1"
    port: int = 9090
    token: str | None = None


def is_loopback(host: str) -> bool:
    """True for ``localhost`` and loopback addresses (127.0.0.0/8, ::1)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def keep_startup_objects_out_of_collections() -> None:
    """Move everything loaded so far (knowledge base, rendered views, imported modules: it lives as long as the
    server) out of the garbage collector's reach, so that a full collection only looks at what goals made.

    Each goal's tree is a reference cycle (parents and children) holding its CAS, frames and clouds, and it lives
    long enough to reach the oldest generation, which CPython collects only when the objects promoted since the
    last full collection reach a quarter of those that survived it. With ~150,000 startup objects counted, that
    took hundreds of goals and the server's memory grew by ~0.2 MiB per goal meanwhile. With them frozen, a full
    collection costs well under a millisecond, and the goal manager runs one after every goal (the second
    collection here resets the count to the few objects left outside the frozen ones). Called once the socket is
    bound; :func:`serve` unfreezes when it returns.
    """
    gc.collect()
    gc.freeze()
    gc.collect()


async def serve(
    service: AnsweringService,
    config: ServerConfig,
    *,
    on_ready: Callable[[str], None] | None = None,
    recorder: TickRecorder | None = None,
) -> str:
    """Serve until SIGINT or SIGTERM; returns the reason it stopped. Closes ``service`` (not ``recorder``, which
    records the engine's ticks and belief changes while it serves)."""
    loop = asyncio.get_running_loop()
    stopping: asyncio.Future[str] = loop.create_future()
    for signum in (signal.SIGINT, signal.SIGTERM):
        reason = f"the server is shutting down ({signal.Signals(signum).name})"
        loop.add_signal_handler(signum, lambda r=reason: stopping.done() or stopping.set_result(r))
    goals = GoalManager(service, collect_after_goals=True)
    sessions: set[Session] = set()
    subscribers = Subscribers()

    def broadcast(topic: str, message: dict[str, Any]) -> None:
        for session in subscribers.of(topic):
            session.send(publish(topic, message))

    def subscribed(topic: str) -> bool:  # engine thread: a stale read only delays or skips one message
        return bool(subscribers.of(topic))

    frames = FramePicker()
    encoding = threading.Event()  # set while a picked frame is being encoded: later picks are dropped meanwhile

    def encode_and_publish(shown: ShownFrame) -> None:  # a worker thread of the loop's executor
        try:
            color, depth = image_messages(shown)
            loop.call_soon_threadsafe(broadcast, IMAGE_TOPIC, color)
            if depth is not None:
                loop.call_soon_threadsafe(broadcast, DEPTH_TOPIC, depth)
        finally:
            encoding.clear()

    def publish_frame() -> None:  # engine thread
        finished = finished_run_cas(service.task_tree)
        perception = service.perception
        shown = frames.pick(finished, perception.cas if perception is not None else None)
        if shown is not None and not encoding.is_set():
            encoding.set()
            loop.call_soon_threadsafe(loop.run_in_executor, None, encode_and_publish, shown)

    def after_tick(tree: py_trees.trees.BehaviourTree) -> None:
        if subscribed(TREE_STATUS_TOPIC):
            status = tree_status(tree.root, service.engine.tick_count)
            loop.call_soon_threadsafe(broadcast, TREE_STATUS_TOPIC, status)
        if subscribed(IMAGE_TOPIC) or subscribed(DEPTH_TOPIC):
            publish_frame()

    def beliefs_changed(step: TrackStep) -> None:
        if subscribed(BELIEFS_TOPIC):
            changes = belief_changes(step, service.engine.tick_count, service.kb.label)
            loop.call_soon_threadsafe(broadcast, BELIEFS_TOPIC, changes)

    service.engine.tree.add_post_tick_handler(after_tick)
    service.add_belief_listener(beliefs_changed)
    if recorder is not None:
        service.engine.tree.add_post_tick_handler(recorder.after_tick)
        service.add_belief_listener(recorder.beliefs_changed)
    service.run_in_background()

    async def connect(connection: ServerConnection) -> None:
        session = Session(connection, goals, SERVICES, subscribers, config.token)
        sessions.add(session)
        try:
            await session.serve()
        finally:
            sessions.discard(session)

    closed = False
    try:
        async with websocket_server(
            connect, config.host, config.port, max_size=FRAME_LIMIT, process_request=page_handler(config.token)
        ) as server:
            keep_startup_objects_out_of_collections()
            if on_ready is not None:
                on_ready(f"ws://{config.host}:{config.port}")
            reason = await stopping
            closed = True
            await loop.run_in_executor(None, goals.close, reason)
            for session in list(sessions):
                with contextlib.suppress(TimeoutError):
                    await asyncio.wait_for(session.flush(), FLUSH_SECONDS)
            server.close()
    finally:
        gc.unfreeze()  # a caller in the same process (tests, an embedding program) gets its collector back
        if not closed:  # the server could not start (address in use, ...): still close the store
            await loop.run_in_executor(None, goals.close, "the server stopped")
        for signum in (signal.SIGINT, signal.SIGTERM):
            loop.remove_signal_handler(signum)
    return reason
