"""One client connection: authentication, dispatch of the rosbridge ops, its goals and subscriptions.

Replies go through an outbox drained by one writer task, so the worker thread hands messages over with
``loop.call_soon_threadsafe`` and never touches the socket. A message that fails validation gets a ``status``
error and the connection keeps working; a client that must authenticate (the server has a token) and sends any
other op first, or a wrong token, gets a ``status`` error and is disconnected. When the connection closes, the
client's open goals are cancelled. A call of a service the server lacks, or with arguments it refuses, is answered
as rosbridge does, with a failed ``service_response`` holding the reason (a client waits for that response); a
refused goal (no such action, no query, too many open goals) gets its failed ``action_result`` and nothing else.

A client's subscriptions are told apart, as in rosbridge, by topic and the ``subscribe`` op's ``id`` (roslibpy gives
each ``Topic`` object its own): subscribing again with the same topic and id changes nothing, ``unsubscribe`` with an
id ends that subscription and without one every subscription to the topic. A client receives each publication once
however many subscriptions to its topic it has. It may hold :data:`MAX_SUBSCRIPTIONS` at a time; one more gets a
``status`` error naming the cap (the connection keeps working) until an unsubscribe frees a place.

Cancelling a goal that already ended (its result and the cancel crossed on the wire) is no error: the result was
sent, and nothing else is. A cancel of a goal id the client never sent (among its last :data:`REMEMBERED_GOALS`) gets
a ``status`` error naming it.
"""

from __future__ import annotations

import asyncio
import hmac
import json
from collections import OrderedDict
from collections.abc import Mapping
from concurrent.futures import Future
from typing import Any

from websockets.asyncio.server import ServerConnection
from websockets.exceptions import ConnectionClosed

from robokudo.application.server.designator import GoalError, MissingQueryError, goal_query
from robokudo.application.server.goals import Goal, GoalManager
from robokudo.application.server.protocol import (
    BELIEFS_TOPIC,
    DEPTH_TOPIC,
    IMAGE_TOPIC,
    QUERY_ACTION,
    TREE_STATUS_TOPIC,
    GoalStatus,
    ProtocolError,
    action_result,
    parse_message,
    service_response,
    status,
)
from robokudo.application.server.services import Service

MAX_OPEN_GOALS = 64
"""Goals one client may have open (queued or running) at a time."""

MAX_SUBSCRIPTIONS = 32
"""Subscriptions (topic and subscription id) one client may hold at a time."""

REMEMBERED_GOALS = 1024
"""How many of a client's latest goal ids a session remembers, to tell a cancel that came late from a wrong one."""

TOPICS = (TREE_STATUS_TOPIC, BELIEFS_TOPIC, IMAGE_TOPIC, DEPTH_TOPIC)

Services = Mapping[str, Service]


class Subscribers:
    """The sessions that subscribe to any topic. Changed on the event loop, read by the engine's thread: the set is
    replaced on every change, never changed in place, so a reader on another thread never sees it half-changed."""

    def __init__(self) -> None:
        self._sessions: frozenset[Session] = frozenset()

    def add(self, session: Session) -> None:
        self._sessions = self._sessions | {session}

    def discard(self, session: Session) -> None:
        self._sessions = self._sessions - {session}

    def of(self, topic: str) -> list[Session]:
        """The sessions subscribed to ``topic`` (any thread)."""
        return [session for session in self._sessions if topic in session.topics]


class Session:
    """Serves one WebSocket connection (see the module)."""

    def __init__(
        self,
        connection: ServerConnection,
        goals: GoalManager,
        services: Services,
        subscribers: Subscribers,
        token: str | None,
    ) -> None:
        self.connection = connection
        self.goals = goals
        self.services = services
        self.subscribers = subscribers
        self.token = token
        self.authenticated = token is None
        self.subscriptions: frozenset[tuple[str, str | None]] = frozenset()
        """Replaced, never changed in place: the engine thread reads it to decide what to publish."""
        """(topic, subscription id) of each subscription; the id is None when the client gave none."""
        self._loop = asyncio.get_running_loop()
        self._sent_goals: OrderedDict[str, None] = OrderedDict()
        """The ids of this client's latest goals (at most :data:`REMEMBERED_GOALS`), oldest first."""
        self._outbox: asyncio.Queue[dict[str, Any] | None] = asyncio.Queue()
        self._calls: set[asyncio.Task[None]] = set()

    def send(self, message: dict[str, Any]) -> None:
        """Queue ``message`` for this client; callable from any thread."""
        self._loop.call_soon_threadsafe(self._outbox.put_nowait, message)

    async def serve(self) -> None:
        """Read and answer messages until the connection closes; then cancel this client's goals."""
        writer = asyncio.create_task(self._write())
        try:
            async for raw in self.connection:
                if not await self._handle(raw):
                    break
        except ConnectionClosed:
            pass
        finally:
            self.subscribers.discard(self)
            self.goals.cancel_owner(self, "the client disconnected")
            self._loop.call_soon(self._outbox.put_nowait, None)  # after the replies already handed over
            await writer

    async def flush(self) -> None:
        """Wait until everything queued so far was written."""
        await self._outbox.join()

    async def _write(self) -> None:
        while (message := await self._outbox.get()) is not None:
            try:
                await self.connection.send(json.dumps(message))
            except ConnectionClosed:
                pass
            finally:
                self._outbox.task_done()
        self._outbox.task_done()

    async def _handle(self, raw: str | bytes) -> bool:
        """Act on one message; False when the connection is to be closed."""
        try:
            message = parse_message(raw)
        except ProtocolError as error:
            self.send(status("error", str(error), error.id))
            return self.authenticated
        op = message["op"]
        if op == "auth":
            return self._auth(message)
        if not self.authenticated:
            self.send(status("error", f"authenticate first (op 'auth' with the server's token) before {op!r}"))
            return False
        try:
            if op == "send_action_goal":
                self._send_goal(message)
            elif op == "cancel_action_goal":
                self._cancel_goal(message)
            elif op == "call_service":
                self._call_service(message)
            elif op == "subscribe":
                self._subscribe(message)
            elif op == "unsubscribe":
                self._unsubscribe(message)
        except ProtocolError as error:
            self.send(status("error", str(error), message.get("id")))
        return True

    def _auth(self, message: dict[str, Any]) -> bool:
        if self.token is None:
            return True
        if hmac.compare_digest(message["mac"].encode(), self.token.encode()):
            self.authenticated = True
            return True
        self.send(status("error", "authentication failed: wrong token"))
        return False

    def _send_goal(self, message: dict[str, Any]) -> None:
        goal_id = message["id"]
        self._remember(goal_id)  # every goal sent gets a result, refused and aborted ones included
        if message["action"] != QUERY_ACTION:
            error = f"no action {message['action']!r}; this server has {QUERY_ACTION!r}"
            self.send(action_result(goal_id, 0, {"error": error}, result=False))
            return
        try:
            query = goal_query(message["args"])
        except MissingQueryError as error:
            self.send(action_result(goal_id, 0, {"error": str(error)}, result=False))
            return
        except GoalError as error:  # a designator that makes no query: the goal is aborted with the reason
            self.send(action_result(goal_id, GoalStatus.ABORTED, {"reason": str(error)}))
            return
        if self.goals.open_goals(self) >= MAX_OPEN_GOALS:
            error = f"too many open goals (at most {MAX_OPEN_GOALS} per client)"
            self.send(action_result(goal_id, 0, {"error": error}, result=False))
            return
        self.goals.submit(Goal(goal_id, query, self, self.send))

    def _remember(self, goal_id: str) -> None:
        self._sent_goals[goal_id] = None
        self._sent_goals.move_to_end(goal_id)
        while len(self._sent_goals) > REMEMBERED_GOALS:
            self._sent_goals.popitem(last=False)

    def _cancel_goal(self, message: dict[str, Any]) -> None:
        goal_id = message["id"]
        if not self.goals.cancel(goal_id, self) and goal_id not in self._sent_goals:
            raise ProtocolError(f"no goal {goal_id!r} of this client to cancel", goal_id)

    def _call_service(self, message: dict[str, Any]) -> None:
        name, request_id = message["service"], message.get("id")
        handler = self.services.get(name)
        arguments = message.get("args", {})
        if handler is None:
            problem = f"unknown service {name!r}; this server has {', '.join(self.services)}"
        else:
            problem = handler.problem(name, arguments)
        if handler is None or problem is not None:  # the call is answered, as rosbridge does: a failed response
            self.send(service_response(name, request_id, {"error": problem}, result=False))
            return
        future = self.goals.call(lambda service: handler.handler(service, arguments))
        call = asyncio.create_task(self._respond(name, request_id, future))
        self._calls.add(call)  # the loop keeps only weak references to tasks
        call.add_done_callback(self._calls.discard)

    async def _respond(self, name: str, request_id: str | None, future: Future[dict[str, Any]]) -> None:
        try:
            values = await asyncio.wrap_future(future)
        except Exception as error:  # the request failed (bad query, plan): the client gets the reason
            self.send(service_response(name, request_id, {"error": str(error)}, result=False))
            return
        self.send(service_response(name, request_id, values, result=True))

    @property
    def topics(self) -> frozenset[str]:
        """The topics this client subscribes to."""
        return frozenset(topic for topic, _ in self.subscriptions)

    def _subscribe(self, message: dict[str, Any]) -> None:
        topic = message["topic"]
        if topic not in TOPICS:
            raise ProtocolError(f"unknown topic {topic!r}; this server publishes {', '.join(TOPICS)}")
        subscription = (topic, message.get("id"))
        if subscription in self.subscriptions:
            return
        if len(self.subscriptions) >= MAX_SUBSCRIPTIONS:
            raise ProtocolError(
                f"too many subscriptions (at most {MAX_SUBSCRIPTIONS} per client); unsubscribe one first",
                message.get("id"),
            )
        self.subscriptions = self.subscriptions | {subscription}
        self.subscribers.add(self)

    def _unsubscribe(self, message: dict[str, Any]) -> None:
        topic, subscription_id = message["topic"], message.get("id")
        if subscription_id is None:
            self.subscriptions = frozenset(s for s in self.subscriptions if s[0] != topic)
        else:
            self.subscriptions = self.subscriptions - {(topic, subscription_id)}
        if not self.subscriptions:
            self.subscribers.discard(self)
