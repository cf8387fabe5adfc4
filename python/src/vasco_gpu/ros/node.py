"""vasco_mapper, the ROS 2 node: scans in (posed by tf, or moved by the optimizer's Path), the
whole map out on /map within milliseconds of every Path. The mapping is LiveMap's (the same
Mapper, parameter table and map formats as log2map, bag2map and Python), the posing Posing's
(tf, the message table's adapters: those of the bag reader); this file only wires them to rclpy:
subscriptions (one per topic of each scan type of the message table), timers, services,
parameters, /map."""

from __future__ import annotations

import importlib
import time

from builtin_interfaces.msg import Time
from nav_msgs.msg import Path
from nav_msgs.srv import GetMap
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock, ClockType, JumpThreshold
from rclpy.duration import Duration
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from std_srvs.srv import SetBool, Trigger

from ..msgs.errors import BagError
from ..msgs.header import stamp_ns, stamp_text
from ..msgs.laser import ANGLES_OFF
from ..msgs.table import MESSAGE_TYPES, MessageType
from ..msgs.tf import TfLinkIgnored
from .batches import Batches
from .canvas import fixed_frame
from .latency import Reservoir, percentiles_text, steps_text
from .live_map import LiveMap, LiveMapError
from .path_cdr import read_path
from .publication import MapPublication
from .services import NodeServices
from .posing import TIME_JUMP_S, Posing, Refused, ScanFilter, Unposed, check_path
from .settings import Effect, Settings, SettingsError, declare_parameters, unknown_parameters
from .tf_messages import tf_message_type
from .transport import map_sized_shm_in_use

__all__ = ["MappingNode"]

NODE_NAME = "vasco_mapper"
REPLAY = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
# tf's queue and history are deeper than tf2's (100 messages, 10 s): a node busy for a moment, or
# a replay faster than real time, must find the transforms of the scans still queued for it.
TF = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
TF_STATIC = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.TRANSIENT_LOCAL, history=HistoryPolicy.KEEP_LAST)
PATH = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
# sensor_data's QoS (best effort, volatile) with a queue that holds a batch's scans: 100 is a
# laser at 1 kHz for scan_batch_interval 0.1 s, or at 40 Hz for 2.5 s
SENSOR = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT, durability=DurabilityPolicy.VOLATILE,
                    history=HistoryPolicy.KEEP_LAST)
SCAN_TYPES = tuple(t for t in MESSAGE_TYPES if t.role == "scan")


def message_class(kind: MessageType):
    """The rclpy message class of a row of the message table (sensor_msgs.msg.LaserScan, ...)."""
    return getattr(importlib.import_module(f"{kind.package}.msg"), kind.class_name)


class MappingNode(NodeServices, LifecycleNode):
    """The node, a managed one: construction reads and checks the parameters (SettingsError for a
    bad one, nothing started); configure makes the mapper, the outputs and the services,
    activate subscribes and maps, deactivate stops mapping (the subscriptions dropped: scans sent
    meanwhile are never mapped), cleanup and shutdown release the mapper. autostart (run.py)
    configures and activates it at once."""

    def __init__(self, **node_kwargs):
        super().__init__(NODE_NAME, **node_kwargs)
        self.settings = declare_parameters(self)  # settings.py's rows and the mapper's keys, checked
        self._check_unknown_parameters()
        for note in self.settings.notes:
            self.get_logger().info(note)
        self.live: LiveMap | None = None  # configure's, until cleanup
        self.active = False
        self.configure_error = ""  # why the last configure failed
        self.paused = False
        self.refused: dict[tuple[str, str], int] = {}
        self.noted: dict[tuple[str, str], int] = {}  # scans mapped with a caveat (no mount)
        self._kept_topics: set[str] = set()  # a scan of theirs kept for a Path logged
        self._angles_off: set[str] = set()  # a scan of theirs with angles off by rounding logged
        self._path_before_scans = False  # logged once
        self._last_scan = 0.0
        # bounded samples (latency.py): a node runs for days
        self.scan_ms = Reservoir()  # callback -> scan in the grid, per scan
        self.path_ms = Reservoir()  # callback -> /map published, per Path
        self.batch_ms = Reservoir()  # batch timer -> map_updates published, per batch that sent one
        # ... and its steps, per Path (ms): where a Path's time goes, in the summary
        self.path_steps: dict[str, Reservoir] = {
            k: Reservoir() for k in ("batch", "read", "repose", "finish", "message", "publish")}
        # ... and per batch that sent a map_update (map: the batch's scans into the grid)
        self.batch_steps: dict[str, Reservoir] = {k: Reservoir() for k in ("map", "finish", "message", "publish")}
        self._inputs: list = []  # activate's subscriptions
        self._batches: Batches | None = None
        self.add_on_set_parameters_callback(self._on_parameters)

    # -- lifecycle: configure, activate, deactivate, cleanup, shutdown -----------------------------
    def on_configure(self, state) -> TransitionCallbackReturn:
        try:
            self._configure()
        except Exception as e:  # SettingsError, SessionFileError, LiveMapError; rclpy's when shut down meanwhile
            self.configure_error = str(e)
            self.get_logger().error(f"configure failed: {e}")
            self._release()
            return TransitionCallbackReturn.FAILURE
        return TransitionCallbackReturn.SUCCESS

    def _configure(self) -> None:
        """The mapper (with load_session's scans), the outputs, the services, the timers."""
        s = self.settings
        frame, centre = fixed_frame(s.map_size, s.map_origin, s.params)  # (None, None): a grid that grows
        try:
            self.live = LiveMap(s.params, backend=s.backend, cuda_mode=s.cuda_mode, device=s.device,
                                threads=s.threads, max_memory=s.max_memory, frame=frame, frame_centre=centre)
        except (RuntimeError, ValueError) as e:  # e.g. cuda without a usable GPU
            raise SettingsError(f"backend {s.backend!r}: {e}") from None
        self.scan_filter = ScanFilter()
        self.posing = Posing(lambda: self.settings, self.resolve_topic_name, self._refuse, self._time_jumped,
                             Unposed(self._unposed_room, self._unposed_dropped), self._kept)
        self._latest_stamp = None  # the newest stamp (ns) of the latest scans mapped: /map's under a silent /clock
        if s.load_session:
            self._load_session(s.load_session)
        self.out = MapPublication(self, fixed=frame is not None)
        self._node_services = [self.create_service(kind, name, handler) for kind, name, handler in (
            (GetMap, "~/dynamic_map", self._dynamic_map), (Trigger, "~/save_map", self._save_map),
            (Trigger, "~/reset", self._reset), (SetBool, "~/pause", self._pause),
            (Trigger, "~/save_session", self._save_session))]
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        # On the steady clock, as the batches below: with use_sim_time and no /clock (a bag
        # paused or over, a simulator not publishing yet) ROS time stands still, and a timer on
        # it would never publish a map.
        self._timer = self.create_timer(s.map_update_interval, self._publish_if_changed, clock=steady)
        # Batches: every scan_batch_interval this timer takes what queued on /tf and the scan
        # topics (batches.py: they do not wake the node) and poses and maps those scans together
        # (one tf lookup, one insert: per scan, rclpy's wake-up, the callbacks' Python and the
        # GPU's launch cost more than the work). With scan_batch_interval 0 each message is a
        # callback, a scan is mapped on arrival or on a later /tf message, and this timer only
        # drops the scans past transform_timeout, running only while some wait. On the steady
        # clock: with use_sim_time and a paused (or absent) /clock, batches still come, and /tf
        # does not overflow its queue while it waits.
        self._retry = self.create_timer(self._retry_period(s), self._on_batch, clock=steady)
        for timer in (self._timer, self._retry):
            timer.cancel()  # activate starts them
        # /clock going back (a bag played again with --clock): as tf2's buffer does, and as stamps
        # going back do (posing.py); on_clock_change off: switching use_sim_time is no jump
        self._clock_jumps = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=-int(TIME_JUMP_S * 1e9)),
                          on_clock_change=False), post_callback=self._on_clock_jump)

    def on_activate(self, state) -> TransitionCallbackReturn:
        self._subscribe()
        self.active = True
        self._timer.reset()
        self._batches.start(self.settings.scan_batch_interval)
        self._arm()
        self.announce_ready()
        return super().on_activate(state)  # the lifecycle publishers

    def on_deactivate(self, state) -> TransitionCallbackReturn:
        self._flush()  # the scans received while active are mapped, and published
        self._publish_if_changed(settle=False)
        self._unsubscribe()
        self.active = False
        self._timer.cancel()
        self._arm()
        self.get_logger().info("inactive: scans are not mapped, maps not published until activated")
        return super().on_deactivate(state)

    def on_cleanup(self, state) -> TransitionCallbackReturn:
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state) -> TransitionCallbackReturn:
        if self.active:
            self.on_deactivate(state)
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def _release(self) -> None:
        """What configure made, dropped: the mapper and its scans, the outputs, the services."""
        if getattr(self, "_clock_jumps", None) is not None:
            self._clock_jumps.unregister()
            self._clock_jumps = None
        for timer in (getattr(self, "_timer", None), getattr(self, "_retry", None)):
            if timer is not None:
                self.destroy_timer(timer)
        self._timer = self._retry = None
        for service in getattr(self, "_node_services", ()):
            self.destroy_service(service)
        self._node_services = []
        if getattr(self, "out", None) is not None:
            self.out.destroy()
        self.out = None
        self.live = None

    def start(self) -> bool:
        """autostart: configure and activate now; False (configure_error says why) if configure failed."""
        if self.trigger_configure() != TransitionCallbackReturn.SUCCESS:
            return False
        return self.trigger_activate() == TransitionCallbackReturn.SUCCESS

    def _check_unknown_parameters(self) -> None:
        """Parameters set for the node (a params file, the command line) that it does not
        declare: one warning naming each, or with strict_parameters a start-up refusal."""
        overrides = getattr(self, "_parameter_overrides", {})  # rclpy's: no public accessor
        unknown = [n for n in overrides if not self.has_parameter(n) and not n.startswith("qos_overrides.")]
        if not unknown:
            return
        text = unknown_parameters(unknown, self.list_parameters([], 0).names)
        if self.settings.strict_parameters:
            raise SettingsError(f"{text} (strict_parameters: true)")
        self.get_logger().warning(f"{text}; strict_parameters:=true refuses them")

    def announce_ready(self) -> None:
        """The 'ready' line (tests and launch files wait for it), once the executor spins."""
        s = self.settings
        topics = [self.resolve_topic_name(t) for kind in SCAN_TYPES for t in getattr(s, kind.topics)]
        self.get_logger().info(
            f"ready: backend {self.live.backend}, scans on {', '.join(topics)}, poses from tf {s.map_frame} -> "
            f"the scans' frames and from the Path on "
            f"{self.resolve_topic_name(s.path_topic) if s.path_topic else '(none)'}; {self._batch_text()}"
            f"{'; maps in one piece over shared memory (up to 4 MiB)' if map_sized_shm_in_use() else ''}")

    def _batch_text(self) -> str:
        s = self.settings
        if self._batches.running:
            return f"scans mapped in batches every {s.scan_batch_interval:g} s"
        if s.scan_batch_interval > 0:
            return (f"scans gathered every {s.scan_batch_interval:g} s, each message a callback (this rclpy does not "
                    f"let the node take them itself)")
        return "each scan mapped on arrival"

    # -- parameters -------------------------------------------------------------------------
    def _on_parameters(self, changed) -> SetParametersResult:
        """A change taken whole or refused whole: settings.py checks it and says what it asks."""
        try:
            new, effects = self.settings.changed({c.name: c.value for c in changed})
            if Effect.REMAP in effects and self.live is not None:
                self.live.set_params(new.params)  # every stored scan mapped again
                self.out.again()
        except (SettingsError, LiveMapError, ValueError) as e:
            return SetParametersResult(successful=False, reason=str(e))
        for note in set(new.notes) - set(self.settings.notes):
            self.get_logger().info(note)
        for effect in effects:
            self._apply(effect, new)
        self.settings = new
        return SetParametersResult(successful=True)

    def _apply(self, effect: Effect, new: Settings) -> None:
        """What a parameter change asks of the running node, beside the mapper's (REMAP); an
        unconfigured node reads the new values at configure, an inactive one at activate."""
        if self.live is None:
            return
        if effect is Effect.PUBLISH_PERIOD:
            self._timer.timer_period_ns = int(new.map_update_interval * 1e9)
        elif effect is Effect.BATCH_PERIOD:
            self._flush()  # the scans gathered so far, at the old period's settings
            self._retry.timer_period_ns = int(self._retry_period(new) * 1e9)
            if self.active:
                self._batches.start(new.scan_batch_interval)
            self._arm()
        elif effect is Effect.REPUBLISH:
            self.out.again()

    # -- inputs -----------------------------------------------------------------------------
    @staticmethod
    def _retry_period(s: Settings) -> float:
        return s.scan_batch_interval if s.scan_batch_interval > 0 else 0.1

    def _pose_soon(self) -> None:
        """A scan (or a transform) came: pose the waiting scans now, or with the next batch."""
        if self.settings.scan_batch_interval > 0:
            self._arm()
        else:
            self._pose_pending()

    def _arm(self) -> None:
        """The batch timer runs while batches are taken, or some scan waits; else it sleeps."""
        need = self.active and (self._batches.running or bool(self.posing.pending))
        if need and self._retry.is_canceled():
            self._retry.reset()
        elif not need and not self._retry.is_canceled():
            self._retry.cancel()

    def _on_input(self, handler, msg) -> None:
        """A message on /tf or a scan topic as a callback: with scan_batch_interval 0, or the first
        after a quiet spell, which starts the batches again."""
        handler(msg, None)
        if not self._batches.running and self.settings.scan_batch_interval > 0:
            self._batches.start(self.settings.scan_batch_interval)
            self._arm()

    def _subscribe(self) -> None:
        """The inputs, made by activate (a batch takes /tf and the scans, batches.py)."""
        s = self.settings
        self._batches = Batches(self.context)
        made = self._inputs = []
        qos = SENSOR if s.scan_qos == "sensor_data" else REPLAY
        # tf first: rclpy's executor runs the ready callbacks of one wake-up in the order the
        # subscriptions were made, so a scan and the /tf of its stamp that came together are
        # taken tf first and the scan is mapped at once (a batch takes /tf after the scans)
        tf_type = tf_message_type()
        made.append(self.create_subscription(tf_type, "/tf_static", lambda m: self._on_tf(m, True), TF_STATIC))
        inputs = [(tf_type, "/tf", TF, lambda m, received: self._on_tf(m, False))]
        inputs += [(message_class(kind), t, qos, lambda m, received, t=t, k=kind: self._on_scan(m, t, k, received))
                   for kind in SCAN_TYPES if kind.batched for t in getattr(s, kind.topics)]
        for kind, topic, topic_qos, handler in inputs:
            made.append(self.create_subscription(kind, topic, lambda m, h=handler: self._on_input(h, m), topic_qos,
                                                 callback_group=self._batches.group))
            self._batches.add(made[-1], handler)
        # clouds (megabytes each) a callback each, as they come: their reading costs far more than
        # a wake-up, and a batch's queue of them would hold hundreds of megabytes
        alone_qos = qos_profile_sensor_data if s.scan_qos == "sensor_data" else REPLAY
        for kind in SCAN_TYPES:
            for topic in getattr(s, kind.topics) if not kind.batched else ():
                made.append(self.create_subscription(message_class(kind), topic,
                                                     lambda m, t=topic, k=kind: self._on_scan(m, t, k), alone_qos))
        if s.path_topic:  # as bytes: path_cdr.py reads them far faster than rclpy's objects
            made.append(self.create_subscription(Path, s.path_topic, self._on_path, PATH, raw=True))

    def _unsubscribe(self) -> None:
        """Deactivate's: no input left, so nothing queues for the node while it is inactive."""
        for sub in self._inputs:
            self.destroy_subscription(sub)
        self._inputs = []
        self._batches.start(0)

    def _refuse(self, topic: str, cause: str, text: str) -> None:
        """Counts a message not mapped; logs the first of each (topic, cause)."""
        key = (topic, cause)
        self.refused[key] = self.refused.get(key, 0) + 1
        if self.refused[key] == 1:
            self.get_logger().warning(f"{text} (further {cause} on {topic} are counted, not logged)")

    def _on_tf(self, msg, static: bool) -> None:
        topic = "/tf_static" if static else "/tf"
        try:
            self.posing.add_tf(msg, static)
        except TfLinkIgnored as e:  # left out, the message's other links kept: logged once a kind
            self._refuse(topic, f"{e.kind}s left out", f"{topic}: {e.message}")
        except BagError as e:
            self._refuse(topic, "bad transforms", f"{topic}: {e.message}")
            return
        if self.posing.pending or len(self.posing.unposed):
            self._pose_soon()

    def _paused_on(self, topic: str) -> bool:
        """While paused, a message on topic is counted and not mapped."""
        if self.paused:
            self.refused[(topic, "paused")] = self.refused.get((topic, "paused"), 0) + 1
        return self.paused

    def _skipped(self, msg, topic: str) -> bool:
        """throttle_scans and minimum_time_interval (slam_toolbox's): a skipped scan is counted."""
        s = self.settings
        if s.throttle_scans == 1 and s.minimum_time_interval == 0:
            return False
        cause = self.scan_filter.skip(topic, stamp_ns(msg.header.stamp), s.throttle_scans, s.minimum_time_interval)
        if cause:
            self.refused[(topic, cause)] = self.refused.get((topic, cause), 0) + 1
        return cause is not None

    def _on_scan(self, msg, topic: str, kind: MessageType, received: float | None = None) -> None:
        if self._paused_on(topic):
            return
        # before the skipping: after a jump, throttle_scans counts from the new time's first scan
        self.posing.stamp_seen(("scan", topic), stamp_ns(msg.header.stamp), lambda: self.resolve_topic_name(topic))
        if self._skipped(msg, topic):
            return
        off = self.posing.range_counts.get(ANGLES_OFF, 0)
        self.posing.add_scan(msg, topic, kind, received)
        if self.posing.range_counts.get(ANGLES_OFF, 0) > off and topic not in self._angles_off:
            self._angles_off.add(topic)
            self.get_logger().warning(
                f"{self.resolve_topic_name(topic)}: a scan's angle_max disagrees with its number of ranges by "
                f"rounding (as velodyne_laserscan publishes): each range mapped at angle_min + i * angle_increment "
                f"(logged once a topic)")
        self._pose_soon()

    def _unposed_room(self) -> int | None:
        """Bytes the scans given up as to tf may hold: max_memory less what the map stores."""
        return max(0, self.live.max_memory - self.live.bytes) if self.live.max_memory else None

    def _kept(self, topic: str, text: str) -> None:
        """A scan given up as to tf, kept for a Path: the first of each topic logged."""
        if topic not in self._kept_topics:
            self._kept_topics.add(topic)
            self.get_logger().warning(f"{text} (further ones on {topic} are counted, not logged)")

    def _unposed_dropped(self, p) -> None:
        self._refuse(p.topic, "scans dropped for memory while waiting for a pose",
                     f"{self.resolve_topic_name(p.topic)}: scan at stamp {stamp_text(p.ns)} dropped: the scans waiting "
                     f"for a pose (no transform within transform_timeout, no Path yet) reached max_memory "
                     f"{self.live.max_memory} bytes with the map; the oldest go first")

    def _pose_pending(self) -> None:
        """Maps every waiting scan whose transform is there; drops those past their deadline."""
        if self.posing.pending or len(self.posing.unposed):
            self._insert(self.posing.take_posed())
        self._arm()

    def _insert(self, posed: list, timed: bool = True) -> None:
        """Maps the posed scans [(pending, laser pose)], in one insert; when that is refused
        (max_memory), one by one, so that each refusal names its scan. timed: their latency
        counts in scan -> grid (not for scans a Path posed after they waited for it)."""
        if not posed:
            return
        mounts = [self.posing.mount(p.reading.frame) for p, _ in posed]
        try:
            self.live.add_many([p.ns for p, _ in posed], [pose for _, pose in posed],
                               [p.reading.ranges for p, _ in posed], [p.reading.first_angle for p, _ in posed],
                               [p.reading.angle_step for p, _ in posed], mounts)
        except LiveMapError as e:
            if len(posed) > 1:
                for one in posed:
                    self._insert([one], timed)
                return
            p = posed[0][0]
            self._refuse(p.topic, "scans over max_memory",
                         f"{self.resolve_topic_name(p.topic)}: scan at stamp {stamp_text(p.ns)} not mapped: {e}")
            return
        self._last_scan = time.monotonic()
        self.posing.unposed.fit()  # the map took memory: the waiting scans' room is less
        self._latest_stamp = max(p.ns for p, _ in posed)
        done = time.perf_counter()
        for (p, _), mount in zip(posed, mounts):
            if timed:
                self.scan_ms.append((done - p.received) * 1e3)
            if mount is None:  # mapped all the same: counted apart from the refusals
                key = (p.topic, "without a mount")
                self.noted[key] = self.noted.get(key, 0) + 1
                if self.noted[key] == 1:
                    self.get_logger().warning(
                        f"{self.resolve_topic_name(p.topic)}: no /tf_static chain {self.settings.base_frame} -> "
                        f"{p.reading.frame}: its scans are mapped at their tf pose, a Path cannot move them (further "
                        f"ones are counted, not logged)")

    def _on_batch(self) -> None:
        """The batch timer: the scans gathered mapped, and, on cuda while map_updates has a
        subscriber (nav2's static layer), what they changed sent at once: the rectangle they
        touched, small beside a full /map. On the CPU backends the publication timer's
        map_update_interval applies instead: each publication finishes the whole grid, which
        there costs about what the batch's mapping does (intel at 0.05 m, 632 x 630 cells:
        11.6 ms on cpu_double on the 2-core machine), where cuda finishes it on the GPU. The
        time from the timer to an update's publish() is the summary's batch -> map_updates."""
        start, version, updates = time.perf_counter(), self.live.version, self.out.counts["updates"]
        self._flush()
        mapped = time.perf_counter()
        # the session's backend is its renderer's name: cuda_float or cuda_exact
        if self.live.version != version and self.live.backend.startswith("cuda") and \
                self.out.update_pub.get_subscription_count():
            steps = self.out.publish(self.live, self.settings, self._map_stamp())
            if self.out.counts["updates"] != updates:
                self.batch_ms.append((time.perf_counter() - start) * 1e3)
                for k, v in {"map": mapped - start, **steps}.items():
                    self.batch_steps[k].append(v * 1e3)

    def _flush(self) -> None:
        """The batch: the scans gathered for it mapped (by the timer, and now before a Path, a
        map, a save)."""
        if self.active:
            self._batches.take(self.settings.scan_batch_interval)
        self._pose_pending()

    def _on_path(self, raw: bytes) -> None:
        start = time.perf_counter()
        self._flush()  # the scans received before the Path are moved by it
        flushed = time.perf_counter()
        try:
            stamps, poses = self._path_poses(raw)
        except Refused as e:
            self._refuse(self.settings.path_topic, e.cause, f"{e}; ignored")
            return
        # the scans no tf posed that the Path covers: mapped at its poses, then moved with the others
        self._insert(self.posing.take_on_path(stamps, poses, self.settings.max_gap_ns), timed=False)
        read = time.perf_counter()
        if len(self.live) == 0 and not self._path_before_scans:
            self._path_before_scans = True
            self.get_logger().info(f"{self.resolve_topic_name(self.settings.path_topic)}: a Path before any scan was "
                                   f"mapped: nothing to move (scans that come later are posed by tf until the next "
                                   f"Path; logged once)")
        try:
            counts = self.live.repose(stamps, poses, self.settings.max_gap_ns)
            if counts["moved"] or counts["in_gap"]:
                self.out.again()  # every scan may have moved: a whole /map
        except LiveMapError as e:
            self._refuse(self.settings.path_topic, "paths not rendered", f"Path not rendered: {e}")
            return
        rendered = time.perf_counter()
        published = self._publish_if_changed(settle=False)
        self.path_ms.append((time.perf_counter() - start) * 1e3)
        steps = {"batch": flushed - start, "read": read - flushed, "repose": rendered - read, **published}
        for k, v in steps.items():
            self.path_steps[k].append(v * 1e3)
        self.get_logger().debug(f"Path of {len(stamps)} poses: {counts}, published in {(time.perf_counter() - start) * 1e3:.1f} ms")

    def _path_poses(self, raw: bytes):
        """(stamps (k,) int64 ns, base poses (k, 3)) of a serialized nav_msgs/Path; Refused
        naming the topic and stamp for one that cannot be read or does not fit (posing.py)."""
        topic = self.resolve_topic_name(self.settings.path_topic)
        try:
            path = read_path(raw, Path)
        except ValueError as e:
            raise Refused(f"{topic}: {e}", "paths not readable") from None
        return check_path(path, self.settings.map_frame, topic)

    # -- outputs ----------------------------------------------------------------------------
    def _publish_if_changed(self, settle: bool = True, now: bool = False) -> dict:
        """Publishes /map and /map_metadata when the grid changed since the last publication. A
        grown grid is rendered once more when the stream has paused for an interval (LiveMap).
        Returns the seconds of its steps (finish, message, publish); empty when nothing was
        published. now: an update even right after a full map (MapPublication.publish)."""
        self._flush()
        quiet = time.monotonic() - self._last_scan > self.settings.map_update_interval
        if settle and quiet:
            try:
                self.live.settle()
            except LiveMapError as e:
                self.get_logger().warning(f"grid not rendered again after growing: {e}")
        return self.out.publish(self.live, self.settings, self._map_stamp(), now=now)

    def _map_stamp(self) -> Time:
        """/map's stamp: the node's clock (ROS time: sim time while /clock ticks, the last /clock
        when it paused); while it reads 0 (use_sim_time before any /clock) the newest stamp of
        the latest scans mapped, so that a map's stamp is a time of its data, which tf can look
        up, not 0."""
        now = self.get_clock().now()
        if now.nanoseconds == 0 and self._latest_stamp is not None:
            return Time(sec=self._latest_stamp // 10**9, nanosec=self._latest_stamp % 10**9)
        return now.to_msg()

    def _start_over(self) -> int:
        """A new map: the stored scans, the waiting ones and the skipping's counts dropped, and
        the newest stamps forgotten (a replay after a reset is no jump); returns how many scans
        were dropped."""
        n = self.live.reset()
        if self.active:  # the map of the dropped scans replaced at once by an empty one
            self.out.reset(self.settings.map_frame, self._map_stamp())
        else:
            self.out.reset()
        self.posing.pending.clear()
        self.posing.unposed.clear()
        self.posing.jumps.clear()
        self.scan_filter = ScanFilter()
        self._latest_stamp = None
        return n

    def _time_jumped(self, where: str, back_ns: int) -> None:
        """Stamps (or /clock) went back more than TIME_JUMP_S: tf's history cleared, as tf2 does;
        on_time_jump reset: a new map (a bag played twice maps one pass), keep: the stored scans
        stay (the same stamps twice: doubled evidence). One log line."""
        self.posing.clear_time()
        self.scan_filter = ScanFilter()
        if self.settings.on_time_jump == "reset":
            what = f"a new map ({self._start_over()} scans dropped; on_time_jump: reset)"
        else:
            what = f"the map keeps its {len(self.live)} scans (on_time_jump: keep)"
        self.get_logger().warning(f"time went back {back_ns * 1e-9:.3f} s on {where}: tf's history cleared, {what}")

    def _on_clock_jump(self, jump) -> None:
        """/clock went back: a jump where the stamps seen lie ahead of the new time (none where
        the scans or /tf told of it first)."""
        back = self.posing.jumps.ahead_of(self.get_clock().now().nanoseconds)
        if back:
            self._time_jumped("/clock", back)

    def summary(self) -> str:
        """What the node did: scans mapped, what it refused, and its own latencies."""
        refused = ", ".join(f"{n} {cause} on {topic}" for (topic, cause), n in sorted(self.refused.items()))
        noted = ", ".join(f"{n} {cause} on {topic}" for (topic, cause), n in sorted(self.noted.items()))
        stored = len(self.live) if self.live is not None else 0  # 0 after cleanup
        text = (f"{stored} scans mapped" + (f" ({noted}: a Path cannot move them)" if noted else "")
                + (f"; not mapped: {refused}" if refused else "")
                + (f"; {len(self.posing.unposed)} scans waiting for a pose (no transform, no Path over their stamps)"
                   if self.live is not None and len(self.posing.unposed) else ""))
        for what, ms in (("scan -> grid", self.scan_ms), ("Path -> /map published", self.path_ms)):
            text += percentiles_text(what, ms)
        if self.path_ms:
            text += "; Path steps p50 ms: " + steps_text(self.path_steps, (50,))
        text += percentiles_text("batch -> map_updates published", self.batch_ms)
        if self.batch_ms:
            text += "; batch steps p50/p99 ms: " + steps_text(self.batch_steps, (50, 99))
        c = self.out.counts if getattr(self, "out", None) is not None else None
        if c and c["maps"]:
            text += (f"; published {c['maps']} maps ({c['map_bytes'] / 1e6:.2f} MB) and {c['updates']} map_updates "
                     f"({c['update_bytes'] / 1e6:.2f} MB)")
        return text
