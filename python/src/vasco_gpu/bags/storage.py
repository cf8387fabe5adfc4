"""Opening a bag with rosbags: what the file is (sniffed from its first bytes), the path rosbags
needs, the ROS 2 Humble definitions of types a bag does not define, why an open failed (and
the repair tool a cut-short recording wants), and one pass over the messages of some topics.

Importing this module raises ImportError when rosbags is not installed.
"""

from __future__ import annotations

from contextlib import contextmanager, suppress
from pathlib import Path

from rosbags.highlevel import AnyReader  # an ImportError here: rosbags is not installed
from rosbags.typesys import Stores, get_typestore

from ..msgs.errors import BagError
from ..msgs.header import stamp_text
from ..msgs.table import short_type

_MAGICS = (  # (first bytes, what it is, the suffix rosbags needs for it)
    (b"#ROSBAG V", "a ROS 1 bag", ".bag"),
    (b"\x89MCAP", "an MCAP file", ".mcap"),
    (b"SQLite format 3\x00", "an SQLite3 file", ".db3"),
)


def _sniff(path: Path) -> tuple[str, str] | None:
    """(what, expected suffix) from a file's first bytes, or None if it is none of the three."""
    with suppress(OSError), path.open("rb") as f:
        head = f.read(16)
        for magic, what, suffix in _MAGICS:
            if head.startswith(magic):
                return what, suffix
    return None


def _storage_target(path) -> Path:
    """The path to hand to rosbags, after the checks whose errors rosbags words poorly.

    rosbags picks the format from the name: a directory is a ROS 2 bag (needs metadata.yaml),
    ``.bag`` ROS 1, ``.mcap`` / ``.db3`` a bare ROS 2 storage file. A directory without
    metadata.yaml but with exactly one storage file is read through that file.
    """
    p = Path(path)
    if not p.exists():
        raise BagError(path, "no such file or directory")
    if p.is_dir():
        if (p / "metadata.yaml").exists():
            return p
        inner = sorted(x for x in p.iterdir() if x.suffix in (".mcap", ".db3") and x.is_file())
        if len(inner) == 1:
            return inner[0]
        if not inner:
            raise BagError(path, "is a directory without metadata.yaml and without a .db3 or .mcap file: "
                                 "not a ROS 2 bag")
        names = ", ".join(x.name for x in inner)
        raise BagError(path, f"is a directory without metadata.yaml holding several storage files ({names}); "
                             "a split bag needs its metadata.yaml")
    if p.stat().st_size == 0:
        raise BagError(path, "is empty (0 bytes): not a ROS bag")
    sniffed = _sniff(p)
    if sniffed is None:
        raise BagError(path, "is not a ROS bag: it starts like none of a ROS 1 bag, an MCAP file or an "
                             "SQLite3 database")
    what, suffix = sniffed
    if p.suffix != suffix:
        raise BagError(path, f"is {what} but its name does not end in {suffix}; rosbags chooses the format "
                             f"by the name, so rename it (or link it) to end in {suffix}")
    return p


def _storage_kind(target: Path) -> str:
    """".bag", ".mcap" or ".db3": the storage of the path handed to rosbags (a ROS 2 bag
    directory's by the storage files in it)."""
    if target.is_dir():
        suffixes = {x.suffix for x in target.iterdir() if x.is_file()}
        return ".mcap" if ".mcap" in suffixes else ".db3" if ".db3" in suffixes else ""
    return target.suffix


def _repair_hint(target: Path, err: BaseException) -> str:
    """What is wrong with the file, as far as rosbags' failure tells, and the tool that repairs
    it or reads it otherwise: a recording cut short loses what is written at the end (a ROS 1
    bag's index, an MCAP file's footer, an SQLite database's last pages)."""
    text = str(err).lower()
    kind = _storage_kind(target)
    checked = isinstance(err, AssertionError) or "assert" in text
    if kind == ".bag" and (checked or "index" in text or "header" in text or "chunk" in text or "record" in text):
        return ("; the bag's index or record headers are damaged (a recording cut short loses its index) or "
                "laid out otherwise than rosbags reads them: ROS 1's 'rosbag reindex BAG' rebuilds the index, "
                "'rosbag filter BAG OUT.bag True' rewrites every record; then read the result")
    if kind == ".mcap" and (checked or any(w in text for w in ("magic", "footer", "summary", "record", "chunk"))):
        return ("; an MCAP file cut short has no footer and no summary: 'mcap recover FILE -o OUT.mcap' (the "
                "mcap command line tool) writes what can be read into OUT.mcap; then read that file")
    if kind == ".db3" and ("malformed" in text or "not a database" in text or "corrupt" in text or checked):
        return ("; the SQLite database is damaged (a recording cut short): \"sqlite3 FILE.db3 '.recover' | "
                "sqlite3 OUT.db3\" copies what can be read into OUT.db3; then read that file")
    if checked:
        return "; the file is damaged, or written otherwise than rosbags reads it"
    return ""


def reason(err: BaseException) -> str:
    """One line saying what an exception from rosbags says; for a failed check without a message
    (an AssertionError), the check and where rosbags makes it."""
    text = str(err).strip()
    if not text and isinstance(err, AssertionError):
        return _failed_check(err)
    return (text or type(err).__name__).splitlines()[0]


def _failed_check(err: AssertionError) -> str:
    """'rosbags' check `assert size == 47` (rosbag1/reader.py, line 643) failed' from the
    traceback's innermost frame."""
    import linecache
    import traceback

    frames = traceback.extract_tb(err.__traceback__)
    if not frames:
        return "a check of rosbags' reader failed"
    last = frames[-1]
    source = (last.line or linecache.getline(last.filename, last.lineno)).strip()
    where = Path(last.filename)
    name = "/".join(where.parts[-2:])
    return f"a check of rosbags' reader failed: `{source}` ({name}, line {last.lineno})"


@contextmanager
def open_bag(path):
    """An open rosbags AnyReader on path; any failure to open is a BagError chained to the cause."""
    target = _storage_target(path)
    default = get_typestore(Stores.ROS2_HUMBLE)
    try:
        reader = AnyReader([target], default_typestore=default)
        reader.open()
    except Exception as err:  # rosbags raises many kinds (ReaderError, KeyError, sqlite3, zstd, ...)
        raise BagError(path, f"cannot be read as a ROS bag: {reason(err)}{_repair_hint(target, err)}") from err
    try:
        _ensure_types(reader, default)
        yield reader
    finally:
        with suppress(Exception):
            reader.close()


def _ensure_types(reader, default) -> None:
    """Registers the default (ROS 2 Humble) definitions of types the bag uses but does not define.

    AnyReader falls back to the default store only when no connection has a definition; a bag
    that defines some types and not others would otherwise fail on the undefined ones.
    """
    missing = {c.msgtype for c in reader.connections} - set(reader.typestore.fielddefs)
    if missing and reader.is2:
        extra = {k: v for k, v in default.fielddefs.items() if k not in reader.typestore.fielddefs}
        with suppress(Exception):
            reader.typestore.register(extra)


def read_messages(reader, path, handlers: dict, progress) -> None:
    """One pass over the connections of the topics in handlers, in bag order, each message
    deserialized with the bag's definitions and passed to its topic's handler with the time the
    bag received it (whole nanoseconds); progress (a reader.Progress) ticks once a message."""
    topics = reader.topics
    connections = [c for name in handlers for c in topics[name].connections]
    stream = reader.messages(connections=connections)
    while True:
        try:
            item = next(stream, None)
        except Exception as err:
            hint = _repair_hint(Path(path), err)
            raise BagError(path, f"reading failed after {progress.done} messages: {reason(err)}{hint}") from err
        if item is None:
            break
        connection, t_ns, raw = item
        try:
            msg = reader.deserialize(raw, connection.msgtype)
        except Exception as err:
            raise BagError(path, f"cannot deserialize a {short_type(connection.msgtype)} message on "
                                 f"{connection.topic!r} received at {stamp_text(t_ns)}: {reason(err)}",
                           topic=connection.topic) from err
        try:
            handlers[connection.topic](msg, t_ns)
        except AttributeError as err:
            if not _is_message(getattr(err, "obj", None)):
                raise  # not the message's shape: a fault of ours, left as it is
            raise BagError(path, _missing_field_text(connection, t_ns, err), topic=connection.topic) from err
        progress.tick()


def _is_message(obj) -> bool:
    """Whether obj is a message rosbags deserialized (its classes carry their type's name)."""
    return isinstance(getattr(type(obj), "__msgtype__", None), str)


def _missing_field_text(connection, t_ns: int, err: AttributeError) -> str:
    """Why a message lacks a field the reader needs: the bag defines its type otherwise than ROS
    (a custom message under a standard name, or another version of it)."""
    kind = short_type(connection.msgtype)
    inner = short_type(type(err.obj).__msgtype__)
    where = "" if inner == kind else f" in its {inner}"
    return (f"topic {connection.topic!r} ({kind}): the message received at {stamp_text(t_ns)} has no field "
            f"{getattr(err, 'name', None) or str(err)!r}{where}: the bag defines {kind} otherwise than ROS does "
            "(a custom message under a standard name?), so it cannot be read as one")
