"""vasco_gpu.ros: the ROS 2 mapping node ``vasco_mapper`` (console script ``vasco_map_node``,
or ``python -m vasco_gpu.ros``). Scans (LaserScan, MultiEchoLaserScan) posed by tf, the
optimizer's nav_msgs/Path moving every stored scan, the whole map republished on ``map``.
Needs rclpy (a system ROS 2, or ``pip install ".[ros]"``); ``import vasco_gpu`` does not
import this package. Guide: docs/ros.md."""

from __future__ import annotations

__all__ = ["main"]


def main(argv=None) -> int:
    """Runs the node until SIGINT or SIGTERM; 0 on a clean exit, 2 for a bad parameter, 1 when
    ROS 2 is not there."""
    import signal
    import sys

    if _asks_version(sys.argv if argv is None else argv):  # answered before rclpy (slow, maybe missing) loads
        from .. import __version__

        print(f"vasco_map_node (vasco_gpu) {__version__}")
        return 0
    # A SIGINT while rclpy loads can land inside importlib's lock callbacks, where Python prints
    # it as an ignored exception: not printed (the node exits 0, as for any SIGINT while starting)
    hook = sys.unraisablehook
    sys.unraisablehook = lambda u: None if isinstance(u.exc_value, KeyboardInterrupt) else hook(u)
    from .message_buffers import keep_message_buffers
    from .transport import use_map_sized_shm

    keep_message_buffers()  # before the large allocations start
    use_map_sized_shm()  # before rclpy loads Fast DDS
    # SIGINT is held back while rclpy and the message packages load: one landing inside the
    # import could end the process by the default action, exit -2 with nothing printed (Jazzy,
    # a loaded machine: 4 starts of 72; strace shows Python resetting SIGINT to its default and
    # killing itself before rclpy installed a handler). Held back, it is raised here after.
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        try:
            from .run import main as run
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, before)
    except KeyboardInterrupt:  # SIGINT while rclpy loads: nothing started yet
        return 0
    except ImportError as e:  # rclpy or a message package
        if _interrupted(e):  # SIGINT inside an extension's initialisation: pybind11 raises ImportError from it
            return 0
        print(f"vasco_map_node: {e.name or e} does not import: install the ROS 2 extra (pip install "
              "'.[ros]' ./ros from the repository, Python 3.10 or newer; Jazzy: '.[ros-jazzy]') or source a ROS 2 "
              "installation (docs/ros.md)", file=sys.stderr)
        return 1
    try:
        return run(argv)
    except KeyboardInterrupt:  # a SIGINT passed on by rclpy's handler, landing between run's own guards
        return 0


def _asks_version(argv) -> bool:
    """Whether the command line (argv[0] the program) has --version before any --ros-args, where
    everything after belongs to ROS 2."""
    args = list(argv[1:])
    return "--version" in (args[:args.index("--ros-args")] if "--ros-args" in args else args)


def _interrupted(e: BaseException) -> bool:
    """Whether a KeyboardInterrupt is among the causes of e."""
    seen = set()
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False
