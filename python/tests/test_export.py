"""omniloc.export's parts on known answers, without Node (ctest mcap_export_py reads whole exports
with @mcap/core): the 2-sigma ellipse, exact point clouds, the MCAP file's frame (magic, footer,
summary offsets) and its determinism."""
import base64
import math
import struct
import unittest
import zlib

from omniloc.export import foxglove, mcap, scene


class Ellipse(unittest.TestCase):
    def test_axis_aligned(self):
        # sigma_x 0.1 m, sigma_y 0.05 m: 2-sigma full axes 0.4 and 0.2, the major along x.
        a, b, angle = scene.ellipse_2sigma([0.01, 0.0, 0.0, 0.0, 0.0025, 0.0, 0.0, 0.0, 0.001])
        self.assertAlmostEqual(a, 0.4, places=12)
        self.assertAlmostEqual(b, 0.2, places=12)
        self.assertAlmostEqual(angle, 0.0, places=12)

    def test_rotated_by_45_degrees(self):
        # The same ellipse turned by 45 degrees: cov = R diag(0.01, 0.0025) R^T.
        c = 0.5 * (0.01 + 0.0025)
        d = 0.5 * (0.01 - 0.0025)
        a, b, angle = scene.ellipse_2sigma([c, d, 0.0, d, c, 0.0, 0.0, 0.0, 0.0])
        self.assertAlmostEqual(a, 0.4, places=12)
        self.assertAlmostEqual(b, 0.2, places=12)
        self.assertAlmostEqual(angle, math.pi / 4, places=12)

    def test_not_positive_semi_definite(self):
        self.assertIsNone(scene.ellipse_2sigma([0.01, 0.02, 0.0, 0.02, 0.01, 0.0, 0.0, 0.0, 0.0]))


class PointCloud(unittest.TestCase):
    def decode(self, msg):
        data = base64.b64decode(msg["data"])
        kind = "f" if msg["fields"][0]["type"] == foxglove.FLOAT32 else "d"
        flat = struct.unpack(f"<{len(data) // struct.calcsize(kind)}{kind}", data)
        return list(zip(flat[0::2], flat[1::2])), kind

    def test_float32_values_stay_float32(self):
        pts = [(6.769733905792236, -0.013618206605315208), (0.5, 2.0)]  # float32 values, as view.jsonl holds
        got, kind = self.decode(foxglove.point_cloud(0, "r0/estimate", pts))
        self.assertEqual(kind, "f")
        self.assertEqual(got, pts)

    def test_other_values_are_float64(self):
        pts = [(1.2345, -0.1), (2.0, 3.0)]  # a recording's 4 decimals: not float32 values
        msg = foxglove.point_cloud(0, "r0/truth", pts)
        got, kind = self.decode(msg)
        self.assertEqual(kind, "d")
        self.assertEqual(msg["point_stride"], 16)
        self.assertEqual(got, pts)


class File(unittest.TestCase):
    def build(self, compress):
        schemas = [mcap.Schema(id=1, name="x.Y", encoding="jsonschema", data=b"{}")]
        channels = [mcap.Channel(id=0, schema_id=1, topic="/a", message_encoding="json"),
                    mcap.Channel(id=1, schema_id=1, topic="/b", message_encoding="json", metadata={"latching": "1"})]
        messages = [mcap.Message(channel_id=k % 2, log_time=1000 * k, publish_time=1000 * k, data=b'{"k":%d}' % k) for k in range(50)]
        return mcap.build("test", schemas, channels, messages, compress=compress, chunk_bytes=400)

    def test_frame_summary_and_crcs(self):
        data, compression = self.build(compress=False)
        self.assertEqual(compression, "")
        self.assertEqual(data[:8], mcap.MAGIC)
        self.assertEqual(data[-8:], mcap.MAGIC)
        footer = data[-8 - 29:-8]
        op, length, summary_start, offsets_start, crc = struct.unpack("<BQQQI", footer)
        self.assertEqual((op, length), (mcap.OP_FOOTER, 20))
        self.assertEqual(crc, zlib.crc32(data[summary_start:len(data) - 8 - 4]))
        # The data end record just before the summary holds the CRC of everything before it.
        end = summary_start - 13
        self.assertEqual(data[end], mcap.OP_DATA_END)
        self.assertEqual(struct.unpack("<I", data[end + 9:end + 13])[0], zlib.crc32(data[:end]))
        # Summary offsets: schema, channel, statistics and chunk index groups, each where it says.
        groups = {}
        at = offsets_start
        while at < len(data) - 8 - 29:
            op, length, group_op, start, size = struct.unpack("<BQBQQ", data[at:at + 26])
            self.assertEqual(op, mcap.OP_SUMMARY_OFFSET)
            groups[group_op] = (start, size)
            self.assertEqual(data[start], group_op)
            at += 9 + length
        self.assertEqual(sorted(groups), [mcap.OP_SCHEMA, mcap.OP_CHANNEL, mcap.OP_CHUNK_INDEX, mcap.OP_STATISTICS])
        start, _ = groups[mcap.OP_STATISTICS]
        count, schemas, channels, _, _, chunks = struct.unpack("<QHIIII", data[start + 9:start + 9 + 26])
        self.assertEqual((count, schemas, channels), (50, 1, 2))
        self.assertGreater(chunks, 1)  # 50 small messages in chunks of 400 bytes

    def test_same_messages_same_bytes(self):
        self.assertEqual(self.build(compress=True), self.build(compress=True))


if __name__ == "__main__":
    unittest.main()
