"""Interrupts of a command (Ctrl-C, SIGTERM): one orderly way out.

While :class:`InterruptHandling` is active, SIGINT and SIGTERM raise :class:`Interrupted` (a KeyboardInterrupt)
in the main thread, so ``with`` blocks unwind: the answering service stops the engine, waits for the experts'
worker threads and closes the belief store. The command then prints ``interrupted`` and ends the process with
:data:`EXIT_INTERRUPTED` (:meth:`InterruptHandling.exit`). A second signal while the first is being handled
ends the process at once, with the same line and status (the belief store survives that: every write is one
SQLite transaction).

The process ends with ``os._exit`` after flushing its output, without running the interpreter's finalizers:
a C extension interrupted while it was being imported (Open3D) reports a failure from its static destructors,
and native code still running in a worker thread may abort the process ("terminate called without an active
exception") when the interpreter exits. Everything that matters was closed while unwinding.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from types import FrameType, TracebackType
from typing import NoReturn, TextIO

EXIT_INTERRUPTED = 130
"""Exit status of an interrupted command (128 + SIGINT, as shells report Ctrl-C)."""

MESSAGE = "interrupted"

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(KeyboardInterrupt):
    """The process received SIGINT or SIGTERM; ``signum`` says which."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


class InterruptHandling:
    """Turns SIGINT and SIGTERM into :class:`Interrupted` while active (see the module).

    ``received`` is the first signal's number (None until one came): code that sees an exception caused by the
    interrupt (a C extension may wrap it in another error) asks it whether the process was interrupted.
    Signal handlers can only be installed in the main thread; elsewhere this does nothing.
    """

    def __init__(self, stream: TextIO | None = None) -> None:
        self.received: int | None = None
        self._stream = stream
        self._previous: dict[int, object] = {}

    def __enter__(self) -> InterruptHandling:
        if threading.current_thread() is threading.main_thread():
            for signum in SIGNALS:
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        for signum, previous in self._previous.items():
            signal.signal(signum, previous)  # type: ignore[arg-type]
        self._previous.clear()

    def report(self) -> int:
        """Print the one line saying the command was interrupted; returns :data:`EXIT_INTERRUPTED`."""
        stream = self._stream or sys.stderr
        print(MESSAGE, file=stream, flush=True)
        return EXIT_INTERRUPTED

    def exit(self) -> NoReturn:
        """Print the line, flush the output and end the process with :data:`EXIT_INTERRUPTED` (see the module)."""
        self.report()
        for stream in (sys.stdout, sys.stderr):
            stream.flush()
        os._exit(EXIT_INTERRUPTED)

    def _handle(self, signum: int, _: FrameType | None) -> None:
        if self.received is not None:  # a second interrupt while the first unwinds: leave now
            self.exit()
        self.received = signum
        raise Interrupted(signum)
