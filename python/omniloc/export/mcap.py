"""An MCAP file writer (https://mcap.dev/spec, version 0): the data section (magic, header, schemas,
channels, messages in chunks each followed by its message indexes, data end with the data
section's CRC) and the summary section (schemas, channels, statistics, chunk indexes), the summary
offsets and the footer with the summary's CRC, so a reader seeks by time without a scan.

Messages are given whole (write() takes them all): an export knows every message before it writes,
and writing the data section in one pass from a sorted list keeps chunk boundaries and therefore the
bytes the same for the same input. The file is written as it is made, a chunk at a time. Chunks are
compressed with LZ4 frames (Debian's python3-lz4, a dependency of python3-matplotlib) where the
module is importable, else stored uncompressed ("").
"""
from __future__ import annotations

import io
import struct
import zlib
from dataclasses import dataclass, field
from typing import BinaryIO, Callable, Optional

MAGIC = b"\x89MCAP0\r\n"

OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
OP_MESSAGE_INDEX, OP_CHUNK_INDEX, OP_STATISTICS, OP_SUMMARY_OFFSET, OP_DATA_END = 0x07, 0x08, 0x0B, 0x0E, 0x0F

# Uncompressed bytes per chunk: small enough that a seek decompresses little, large enough that LZ4
# finds the repetition between frames' JSON (the same keys every frame).
CHUNK_BYTES = 512 * 1024


def _lz4() -> Optional[Callable[[bytes], bytes]]:
    try:
        import lz4.frame
    except ImportError:
        return None
    compress: Callable[[bytes], bytes] = lz4.frame.compress
    return compress


@dataclass(frozen=True)
class Schema:
    id: int
    name: str
    encoding: str
    data: bytes


@dataclass(frozen=True)
class Channel:
    id: int
    schema_id: int
    topic: str
    message_encoding: str
    metadata: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Message:
    channel_id: int
    log_time: int  # nanoseconds
    publish_time: int
    data: bytes | Callable[[], bytes]


def _string(s: str) -> bytes:
    b = s.encode("utf-8")
    return struct.pack("<I", len(b)) + b


def _record(op: int, content: bytes) -> bytes:
    return struct.pack("<BQ", op, len(content)) + content


def _schema(s: Schema) -> bytes:
    return _record(OP_SCHEMA, struct.pack("<H", s.id) + _string(s.name) + _string(s.encoding) + struct.pack("<I", len(s.data)) + s.data)


def _channel(c: Channel) -> bytes:
    meta = b"".join(_string(k) + _string(v) for k, v in sorted(c.metadata.items()))
    return _record(OP_CHANNEL, struct.pack("<HH", c.id, c.schema_id) + _string(c.topic) + _string(c.message_encoding) +
                   struct.pack("<I", len(meta)) + meta)


@dataclass
class _ChunkIndex:
    start: int
    end: int
    offset: int
    length: int
    index_offsets: dict[int, int]
    index_length: int
    compression: str
    compressed_size: int
    uncompressed_size: int

    def record(self) -> bytes:
        offsets = b"".join(struct.pack("<HQ", c, o) for c, o in sorted(self.index_offsets.items()))
        return _record(OP_CHUNK_INDEX, struct.pack("<QQQQ", self.start, self.end, self.offset, self.length) +
                       struct.pack("<I", len(offsets)) + offsets + struct.pack("<Q", self.index_length) +
                       _string(self.compression) + struct.pack("<QQ", self.compressed_size, self.uncompressed_size))


class _Sink:
    """The file being written: its length so far and the running CRC of the data section."""

    def __init__(self, out: BinaryIO) -> None:
        self.out = out
        self.length = 0
        self.crc = 0

    def write(self, data: bytes) -> None:
        self.out.write(data)
        self.length += len(data)
        self.crc = zlib.crc32(data, self.crc)


def write(out: BinaryIO, library: str, schemas: list[Schema], channels: list[Channel], messages: list[Message],
          compress: bool = True, chunk_bytes: int = CHUNK_BYTES) -> str:
    """Writes the whole MCAP file to `out` and returns the chunks' compression ("lz4", or "" for
    none). Messages are written in log-time order (stable: equal times keep the given order),
    sequence numbers per channel. A message's data may be given as a function that makes it, called
    once as its chunk is written: a recording's camera images are then read one chunk at a time
    rather than all held at once."""
    lz4 = _lz4() if compress else None
    compression = "lz4" if lz4 is not None else ""
    sink = _Sink(out)
    sink.write(MAGIC)
    sink.write(_record(OP_HEADER, _string("") + _string(library)))
    schema_bytes = b"".join(_schema(s) for s in schemas)
    channel_bytes = b"".join(_channel(c) for c in channels)
    sink.write(schema_bytes + channel_bytes)

    ordered = sorted(messages, key=lambda m: m.log_time)
    sequence: dict[int, int] = {}
    counts: dict[int, int] = {c.id: 0 for c in channels}
    indexes: list[_ChunkIndex] = []
    i = 0
    while i < len(ordered):
        body = bytearray()
        per_channel: dict[int, list[tuple[int, int]]] = {}
        start = ordered[i].log_time
        end = start
        while i < len(ordered) and (not body or len(body) < chunk_bytes):
            m = ordered[i]
            seq = sequence.get(m.channel_id, 0)
            sequence[m.channel_id] = seq + 1
            counts[m.channel_id] = counts.get(m.channel_id, 0) + 1
            per_channel.setdefault(m.channel_id, []).append((m.log_time, len(body)))
            data = m.data if isinstance(m.data, bytes) else m.data()
            body += _record(OP_MESSAGE, struct.pack("<HIQQ", m.channel_id, seq, m.log_time, m.publish_time) + data)
            start, end = min(start, m.log_time), max(end, m.log_time)
            i += 1
        raw = bytes(body)
        stored = lz4(raw) if lz4 is not None else raw
        chunk_offset = sink.length
        sink.write(_record(OP_CHUNK, struct.pack("<QQQI", start, end, len(raw), zlib.crc32(raw)) + _string(compression) +
                           struct.pack("<Q", len(stored)) + stored))
        chunk_length = sink.length - chunk_offset
        index_offsets: dict[int, int] = {}
        index_start = sink.length
        for cid in sorted(per_channel):
            index_offsets[cid] = sink.length
            entries = b"".join(struct.pack("<QQ", t, o) for t, o in per_channel[cid])
            sink.write(_record(OP_MESSAGE_INDEX, struct.pack("<HI", cid, len(entries)) + entries))
        indexes.append(_ChunkIndex(start=start, end=end, offset=chunk_offset, length=chunk_length, index_offsets=index_offsets,
                                   index_length=sink.length - index_start, compression=compression, compressed_size=len(stored),
                                   uncompressed_size=len(raw)))

    sink.write(_record(OP_DATA_END, struct.pack("<I", sink.crc)))
    summary_start = sink.length
    summary = bytearray()
    groups: list[tuple[int, int, int]] = []

    def group(op: int, data: bytes) -> None:
        if data:
            groups.append((op, summary_start + len(summary), len(data)))
            summary.extend(data)

    group(OP_SCHEMA, schema_bytes)
    group(OP_CHANNEL, channel_bytes)
    channel_counts = b"".join(struct.pack("<HQ", c, n) for c, n in sorted(counts.items()))
    first = ordered[0].log_time if ordered else 0
    last = max((m.log_time for m in ordered), default=0)
    group(OP_STATISTICS, _record(OP_STATISTICS, struct.pack("<QHIIII", len(ordered), len(schemas), len(channels), 0, 0, len(indexes)) +
                                 struct.pack("<QQ", first, last) + struct.pack("<I", len(channel_counts)) + channel_counts))
    group(OP_CHUNK_INDEX, b"".join(ci.record() for ci in indexes))
    summary_offset_start = summary_start + len(summary)
    for op, start_, length in groups:
        summary += _record(OP_SUMMARY_OFFSET, struct.pack("<BQQ", op, start_, length))
    summary += struct.pack("<BQQQ", OP_FOOTER, 20, summary_start, summary_offset_start)
    summary += struct.pack("<I", zlib.crc32(summary)) + MAGIC
    out.write(summary)
    return compression


def build(library: str, schemas: list[Schema], channels: list[Channel], messages: list[Message],
          compress: bool = True, chunk_bytes: int = CHUNK_BYTES) -> tuple[bytes, str]:
    """The whole file as bytes (write() to memory), and the chunks' compression."""
    buf = io.BytesIO()
    compression = write(buf, library, schemas, channels, messages, compress=compress, chunk_bytes=chunk_bytes)
    return buf.getvalue(), compression
