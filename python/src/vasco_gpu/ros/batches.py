"""The node's inputs taken in batches (scan_batch_interval): /tf and the scan topics wait in no
executor's wait set while batches run, so that their messages do not wake the node one by one
(each wake-up costs rclpy's Python executor more than the message's own work); a timer of the
node's takes what queued, as rclpy's wait_for_message takes a message, and the node poses and
maps those scans together. After a quiet second the subscriptions wait in the executor again,
so that an idle node sleeps, and the next message starts the batches.

Their QoS event handlers (rclpy's warning about a publisher with an incompatible QoS) wait in no
wait set while batching either: in rmw_fastrtps a subscription's events share its reader's
status condition, so an event handler in the executor's wait set wakes it whenever a message
has queued, and the executor spins until the batch takes it (80 % of a core at 40 Hz instead of
5 %). Each batch polls them instead, as the executor would, with a wait set of its own that
does not wait."""

from __future__ import annotations

import time
from contextlib import ExitStack

from rclpy import exceptions as rclpy_exceptions
from rclpy.callback_groups import CallbackGroup
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

__all__ = ["Batches", "QUIET_S"]

QUIET_S = 1.0  # seconds without a /tf or scan message after which batches stop until the next
DRAIN_MAX = 100_000  # messages a batch takes from one topic at most: a flood cannot hold the node
_InvalidHandle = getattr(rclpy_exceptions, "InvalidHandle", RuntimeError)


class BatchGroup(CallbackGroup):
    """The callback group of /tf and the scan topics. While batching, nothing of it (the
    subscriptions, their QoS event handlers) is in a wait set; otherwise a reentrant group:
    each callback as it comes."""

    def __init__(self):
        super().__init__()
        self.batching = False

    def can_execute(self, entity) -> bool:
        return not self.batching

    def beginning_execution(self, entity) -> bool:
        return self.can_execute(entity)

    def ending_execution(self, entity) -> None:
        pass


def _can_take(sub) -> bool:
    """Whether this rclpy lets the node take a subscription's messages itself."""
    return hasattr(sub, "handle") and hasattr(sub.handle, "take_message")


class Batches:
    """The subscriptions a batch takes, /tf first then the scan topics (``add``), and whether
    batches run. ``take`` calls each message's handler(msg, received: when DDS received it, on
    perf_counter's clock)."""

    def __init__(self, context):
        self.group = BatchGroup()
        self._context = context
        self._inputs = []  # (subscription, handler)
        self._events = []  # their QoS event handlers, polled by each batch
        self._last_taken = time.monotonic()

    @property
    def running(self) -> bool:
        return self.group.batching

    def add(self, sub, handler) -> None:
        self._inputs.append((sub, handler))
        self._events.extend(getattr(sub, "event_handlers", ()))

    def start(self, interval: float) -> None:
        """Batches every interval seconds (> 0; where this rclpy lets the node take messages),
        or none (0): each message a callback."""
        self.group.batching = interval > 0 and all(_can_take(sub) for sub, _ in self._inputs)
        self._last_taken = time.monotonic()

    def take(self, interval: float) -> None:
        """The messages queued on the scan topics, then on /tf (a /tf that came while the scans
        were taken is there for them). A second without one: batches stop."""
        if not self.group.batching:
            return
        now, now_ns = time.perf_counter(), time.time_ns()
        for sub, handler in self._inputs[1:] + self._inputs[:1]:
            for _ in range(DRAIN_MAX):
                try:
                    with sub.handle:
                        taken = sub.handle.take_message(sub.msg_type, sub.raw)
                except _InvalidHandle:  # destroyed: the node is shutting down
                    return
                if taken is None:
                    break
                self._last_taken = time.monotonic()
                handler(taken[0], now - _age(taken[1], now_ns, interval + QUIET_S))
        self._poll_events()
        if time.monotonic() - self._last_taken >= QUIET_S:
            self.group.batching = False

    def _poll_events(self) -> None:
        """Runs the callbacks of the subscriptions' QoS events that have come, as the executor
        runs a ready event handler (take_data, then its callback), from a wait set that does not
        wait (rclpy's wait_for_message builds its wait set so too)."""
        handlers = self._events
        if not handlers or self._context.handle is None:
            return
        try:
            with ExitStack() as held:
                for h in handlers:
                    held.enter_context(h)
                held.enter_context(self._context.handle)
                wait_set = _rclpy.WaitSet(0, 0, 0, 0, 0, len(handlers), self._context.handle)
                wait_set.clear_entities()
                for h in handlers:
                    h.add_to_wait_set(wait_set)
                wait_set.wait(0)
                ready = [h for h in handlers if h.is_ready(wait_set)]
                taken = [(h, h.take_data()) for h in ready]
        except _InvalidHandle:  # destroyed: the node is shutting down
            return
        for h, data in taken:
            if data:
                h.callback(data)


def _age(info, now_ns: int, limit: float) -> float:
    """Seconds since DDS received a message taken now: its received_timestamp, where the
    middleware gives one (Cyclone DDS gives 0) and it is at most limit seconds old (no step of
    the system clock); 0 otherwise (taken when received)."""
    received = info.get("received_timestamp", 0) if isinstance(info, dict) else 0
    age = (now_ns - received) * 1e-9 if 0 < received <= now_ns else 0.0
    return age if age <= limit else 0.0
