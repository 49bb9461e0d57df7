"""A Scene (omniloc.export.scene) as MCAP bytes: one schema per message type used, one channel per
topic, JSON-encoded messages (compact, finite numbers only) in time order."""
from __future__ import annotations

import json
import pathlib
from typing import BinaryIO, Callable

from omniloc.export import foxglove
from omniloc.export import mcap
from omniloc.export.scene import Scene, read_png

_ENCODER = json.JSONEncoder(separators=(",", ":"), allow_nan=False, check_circular=False)


def encode(scene: Scene, out: BinaryIO, compress: bool = True) -> str:
    """Writes the MCAP file of the scene to `out`; returns its chunk compression ("lz4" or "")."""
    schema_ids: dict[str, int] = {}
    schemas: list[mcap.Schema] = []
    channels: list[mcap.Channel] = []
    channel_ids: dict[str, int] = {}

    def channel(topic: str, schema_name: str, metadata: dict[str, str]) -> int:
        if topic in channel_ids:
            return channel_ids[topic]
        if schema_name not in schema_ids:
            schema_ids[schema_name] = len(schemas) + 1  # schema id 0 means "no schema"
            data = json.dumps(foxglove.SCHEMAS[schema_name], sort_keys=True, separators=(",", ":")).encode("utf-8")
            schemas.append(mcap.Schema(id=schema_ids[schema_name], name=schema_name, encoding="jsonschema", data=data))
        channel_ids[topic] = len(channels)
        channels.append(mcap.Channel(id=channel_ids[topic], schema_id=schema_ids[schema_name], topic=topic, message_encoding="json",
                                     metadata=metadata))
        return channel_ids[topic]

    messages: list[mcap.Message] = []
    for topic, ns, payload in scene.messages:
        cid = channel(topic, *scene.topics[topic])
        data = payload if isinstance(payload, bytes) else _ENCODER.encode(payload).encode("utf-8")
        messages.append(mcap.Message(channel_id=cid, log_time=ns, publish_time=ns, data=data))
    for topic, ns, frame, path in scene.images:
        cid = channel(topic, "foxglove.CompressedImage", {})
        messages.append(mcap.Message(channel_id=cid, log_time=ns, publish_time=ns, data=_image_message(ns, frame, path)))
    return mcap.write(out, "omniloc export", schemas, channels, messages, compress=compress)


def _image_message(ns: int, frame: str, path: pathlib.Path) -> Callable[[], bytes]:
    """The image's message, made when its chunk is written (InputFileError if it is no PNG)."""
    def make() -> bytes:
        return _ENCODER.encode(foxglove.compressed_image(ns, frame, read_png(path))).encode("utf-8")
    return make
