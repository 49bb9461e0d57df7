#!/usr/bin/env node
// Reads an MCAP file that `omniloc export` wrote with the MCAP project's own reader (@mcap/core) and
// checks it as a reader that is not ours sees it:
//  - every record, in order, from the stream reader (chunk CRCs checked), the data section's CRC
//    (computed here) against the data end record, the summary's CRC (the indexed reader checks it
//    on opening, and it is computed here too);
//  - the summary: schemas and channels as in the data section, statistics equal to what the file
//    holds, summary offsets that point at their groups, each chunk index at its chunk and message
//    indexes, each message index entry at a message of that channel and time;
//  - every message read through the indexes, decoded as JSON and valid against the Foxglove JSON
//    schemas of @foxglove/schemas (foxglove.*), or against the schema the file carries (omniloc.*);
//    a time-range read returns exactly the messages of that range;
//  - with --run DIR: each /r<id>/estimate equals est.tum's row (est_r<id>.tum from the second robot),
//    each /r<id>/truth gt.tum's, each /r<id>/line_points view.jsonl's line points of the frame;
//    with --recording DIR: /r<id>/truth and /r<id>/line_points equal the recording's frames and
//    each /r<id>/camera image the recorded PNG.
// Usage: node check.js FILE.mcap [--run DIR] [--recording DIR]. Exit 0: all hold; 1: a check failed
// (each failure on stderr); prints a one-line summary of what it read.
"use strict";
const fs = require("fs");
const path = require("path");
const zlib = require("zlib");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const lz4 = require("lz4js");
const Ajv = require("ajv");
const foxgloveSchemas = require("@foxglove/schemas/jsonschema");

const failures = [];
function fail(msg) {
  failures.push(msg);
  if (failures.length <= 30) console.error("FAIL: " + msg);
}
function check(cond, msg) {
  if (!cond) fail(msg);
  return cond;
}

const decompressHandlers = {
  lz4: (buffer, size) => lz4.decompress(buffer, Number(size)),
};

function readableOf(bytes) {
  return {
    size: async () => BigInt(bytes.length),
    read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
  };
}

// The first record of `bytes` (a slice of the file or of a chunk), parsed by @mcap/core.
function recordAt(bytes, opts = {}) {
  const r = new McapStreamReader({ noMagicPrefix: true, includeChunks: true, decompressHandlers, ...opts });
  r.append(bytes);
  return r.nextRecord();
}

// The first record of a chunk's records from `at` on: a message needs its channel known first, so
// the file's schema and channel records (`prelude`) go before it.
function recordInChunk(prelude, raw, at) {
  const r = new McapStreamReader({ noMagicPrefix: true });
  r.append(prelude);
  r.append(raw.subarray(at));
  for (let rec; (rec = r.nextRecord()); ) {
    if (rec.type !== "Schema" && rec.type !== "Channel") return rec;
  }
  return undefined;
}

function sameJson(a, b) {
  return JSON.stringify(a, (k, v) => (typeof v === "bigint" ? v.toString() : v)) ===
    JSON.stringify(b, (k, v) => (typeof v === "bigint" ? v.toString() : v));
}

function yaw(q) {
  return Math.atan2(2 * q.w * q.z, q.w * q.w - q.z * q.z);
}
function angleDiff(a, b) {
  let d = (a - b) % (2 * Math.PI);
  if (d > Math.PI) d -= 2 * Math.PI;
  if (d < -Math.PI) d += 2 * Math.PI;
  return Math.abs(d);
}
function ns(t) {
  return BigInt(Math.max(0, Math.round(t * 1e9)));
}

// Points of a foxglove.PointCloud as [x, y] numbers (float32 or float64 fields).
function cloudPoints(msg) {
  const data = Buffer.from(msg.data, "base64");
  const fx = msg.fields.find((f) => f.name === "x");
  const fy = msg.fields.find((f) => f.name === "y");
  const out = [];
  for (let o = 0; o + msg.point_stride <= data.length; o += msg.point_stride) {
    const get = (f) => (f.type === 7 ? data.readFloatLE(o + f.offset) : data.readDoubleLE(o + f.offset));
    out.push([get(fx), get(fy)]);
  }
  check(data.length % msg.point_stride === 0, `point cloud data of ${data.length} bytes is not whole points of ${msg.point_stride}`);
  return out;
}

// Blobs drawn as rays in the robot frame: one line per blob of view.jsonl, from the robot along its
// bearing to its distance (3 m where it has none). Frames before the first blob may have no message.
function compareBlobs(kind, msgs, frames) {
  const withBlobs = frames.filter((f) => (f.blobs || []).length > 0);
  if (withBlobs.length === 0) {
    check(msgs.length === 0, `${kind}: ${msgs.length} messages, view.jsonl has no blobs`);
    return 0;
  }
  const first = frames.findIndex((f) => (f.blobs || []).length > 0);
  const expected = frames.slice(first);
  if (!check(msgs.length === expected.length, `${kind}: ${msgs.length} messages for ${expected.length} frames from the first blob on`)) return 0;
  let n = 0;
  expected.forEach((f, i) => {
    const lines = msgs[i].msg.entities[0].lines;
    const blobs = f.blobs || [];
    if (!check(lines.length === blobs.length, `${kind} frame ${f.k}: ${lines.length} rays for ${blobs.length} blobs`)) return;
    blobs.forEach((b, j) => {
      n += 1;
      const d = b.distance == null ? 3.0 : b.distance;
      const end = lines[j].points[1];
      check(Math.abs(end.x - d * Math.cos(b.bearing)) < 1e-12 && Math.abs(end.y - d * Math.sin(b.bearing)) < 1e-12,
        `${kind} frame ${f.k} blob ${j}: ray to (${end.x}, ${end.y}), bearing ${b.bearing} distance ${b.distance}`);
    });
  });
  return n;
}

function readTum(file) {
  return fs.readFileSync(file, "utf8").split("\n").filter((l) => l.trim() && !l.startsWith("#")).map((l) => {
    const v = l.trim().split(/\s+/).map(Number);
    return { t: v[0], x: v[1], y: v[2], qz: v[6], qw: v[7] };
  });
}

function robotIds(runDir) {
  const lines = fs.readFileSync(path.join(runDir, "frames.csv"), "utf8").split("\n").filter((l) => l);
  const col = lines[0].split(",").indexOf("robot");
  const ids = [];
  for (const l of lines.slice(1)) {
    const id = Number(l.split(",")[col]);
    if (!ids.includes(id)) ids.push(id);
  }
  return ids;
}

// Each /r<id>/numbers message against frames.csv's row: every non-empty cell (but robot) as the
// same number (mode as its text), no key for an empty cell.
function compareNumbers(kind, msgs, runDir, id) {
  const lines = fs.readFileSync(path.join(runDir, "frames.csv"), "utf8").split("\n").filter((l) => l);
  const header = lines[0].split(",");
  const rows = lines.slice(1).map((l) => l.split(",")).filter((r) => Number(r[header.indexOf("robot")]) === id);
  if (!check(msgs.length === rows.length, `${kind}: ${msgs.length} messages, frames.csv has ${rows.length} rows of r${id}`)) return 0;
  let n = 0;
  rows.forEach((row, k) => {
    const m = msgs[k].msg;
    check(m.k === k && msgs[k].logTime === ns(Number(row[header.indexOf("t")])), `${kind} ${k}: frame or time`);
    header.forEach((col, j) => {
      if (col === "robot") return;
      n += 1;
      if (col === "mode") check(m.mode === row[j], `${kind} ${k}: mode ${m.mode}, frames.csv ${row[j]}`);
      else if (row[j] === "") check(!(col in m), `${kind} ${k}: ${col} given, frames.csv's cell is empty`);
      else check(m[col] === Number(row[j]), `${kind} ${k}: ${col} ${m[col]}, frames.csv ${row[j]}`);
    });
  });
  return n;
}

function comparePoses(kind, msgs, rows, file) {
  if (!check(msgs.length === rows.length, `${kind}: ${msgs.length} messages, ${file} has ${rows.length} rows`)) return;
  rows.forEach((row, i) => {
    const m = msgs[i];
    const p = m.msg.pose.position;
    check(m.logTime === ns(row.t), `${kind} ${i}: log time ${m.logTime}, ${file} row t ${row.t}`);
    check(p.x === row.x && p.y === row.y, `${kind} ${i}: (${p.x}, ${p.y}), ${file} row (${row.x}, ${row.y})`);
    // The file keeps the quaternion to 9 decimals: the yaw agrees to that.
    check(angleDiff(yaw(m.msg.pose.orientation), yaw({ z: row.qz, w: row.qw })) < 2e-9, `${kind} ${i}: yaw differs from ${file}'s row`);
  });
}

function compareLinePoints(kind, msgs, expected) {
  if (!check(msgs.length === expected.length, `${kind}: ${msgs.length} point clouds for ${expected.length} frames`)) return 0;
  let n = 0;
  expected.forEach((e, k) => {
    const got = cloudPoints(msgs[k].msg);
    check(msgs[k].logTime === ns(e.t), `${kind} frame ${k}: log time ${msgs[k].logTime}, expected t ${e.t}`);
    if (!check(got.length === e.points.length, `${kind} frame ${k}: ${got.length} points, expected ${e.points.length}`)) return;
    e.points.forEach((p, i) => {
      n += 1;
      check(got[i][0] === p[0] && got[i][1] === p[1], `${kind} frame ${k} point ${i}: (${got[i]}), expected (${p})`);
    });
  });
  return n;
}

async function main() {
  const args = process.argv.slice(2);
  const file = args[0];
  const opt = (name) => (args.indexOf(name) >= 0 ? args[args.indexOf(name) + 1] : undefined);
  const runDir = opt("--run");
  const recDir = opt("--recording");
  const bytes = new Uint8Array(fs.readFileSync(file));

  // 1. Every record, in file order, by the stream reader.
  const stream = new McapStreamReader({ includeChunks: true, decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const records = [];
  for (let r; (r = stream.nextRecord()); ) records.push(r);
  check(stream.done(), "the stream reader did not reach a valid footer");
  const types = records.map((r) => r.type);
  check(types[0] === "Header", "the first record is not the header");
  check(types[types.length - 1] === "Footer", "the last record is not the footer");
  const dataEndAt = types.indexOf("DataEnd");
  check(dataEndAt > 0, "no data end record");
  const streamMessages = records.slice(0, dataEndAt).filter((r) => r.type === "Message");
  const chunks = records.filter((r) => r.type === "Chunk");
  check(chunks.length > 0, "no chunks");

  // 2. CRCs: the data section's (magic to the data end record) and the summary's.
  const footer = records[records.length - 1];
  const summaryStart = Number(footer.summaryStart);
  const dataEndOffset = summaryStart - (1 + 8 + 4);
  check(bytes[dataEndOffset] === 0x0f, "the data end record is not just before the summary");
  const dataEnd = records[dataEndAt];
  check(dataEnd.dataSectionCrc !== 0, "the data section CRC is not given");
  check(crc32(bytes.subarray(0, dataEndOffset)) === dataEnd.dataSectionCrc, "the data section CRC does not match");
  const footerAt = bytes.length - 8 - (1 + 8 + 20);
  check(footer.summaryCrc !== 0, "the summary CRC is not given");
  check(crc32(bytes.subarray(summaryStart, footerAt + 1 + 8 + 16)) === footer.summaryCrc, "the summary CRC does not match");

  // 3. The summary, through the indexed reader (which checks the summary CRC and reads the indexes).
  const reader = await McapIndexedReader.Initialize({ readable: readableOf(bytes), decompressHandlers });
  const dataSchemas = records.slice(0, dataEndAt).filter((r) => r.type === "Schema");
  const dataChannels = records.slice(0, dataEndAt).filter((r) => r.type === "Channel");
  check(reader.schemasById.size === dataSchemas.length && dataSchemas.every((s) => sameJson(reader.schemasById.get(s.id), s)),
    "the summary's schemas differ from the data section's");
  check(reader.channelsById.size === dataChannels.length && dataChannels.every((c) => sameJson(reader.channelsById.get(c.id), c)),
    "the summary's channels differ from the data section's");
  const st = reader.statistics;
  if (check(st !== undefined, "no statistics record")) {
    check(st.messageCount === BigInt(streamMessages.length), `statistics: ${st.messageCount} messages, the file holds ${streamMessages.length}`);
    check(st.schemaCount === dataSchemas.length && st.channelCount === dataChannels.length, "statistics: schema or channel count");
    check(st.chunkCount === chunks.length, `statistics: ${st.chunkCount} chunks, the file holds ${chunks.length}`);
    const perChannel = new Map();
    for (const m of streamMessages) perChannel.set(m.channelId, (perChannel.get(m.channelId) || 0n) + 1n);
    check(sameJson([...st.channelMessageCounts.entries()].sort((a, b) => a[0] - b[0]), [...perChannel.entries()].sort((a, b) => a[0] - b[0])),
      "statistics: per-channel message counts differ from the file's");
    const times = streamMessages.map((m) => m.logTime);
    const lo = times.reduce((a, b) => (b < a ? b : a));
    const hi = times.reduce((a, b) => (b > a ? b : a));
    check(st.messageStartTime === lo && st.messageEndTime === hi, "statistics: message start or end time");
  }
  for (const op of [3, 4, 8, 11]) {
    const so = reader.summaryOffsetsByOpcode.get(op);
    if (!check(so !== undefined, `no summary offset for opcode ${op}`)) continue;
    const first = recordAt(bytes.subarray(Number(so.groupStart), Number(so.groupStart + so.groupLength)));
    check(first !== undefined && { 3: "Schema", 4: "Channel", 8: "ChunkIndex", 11: "Statistics" }[op] === first.type,
      `summary offset of opcode ${op} does not point at its group`);
  }
  const group = (op) => {
    const so = reader.summaryOffsetsByOpcode.get(op);
    return so ? bytes.subarray(Number(so.groupStart), Number(so.groupStart + so.groupLength)) : new Uint8Array();
  };
  const prelude = new Uint8Array([...group(3), ...group(4)]);
  check(reader.chunkIndexes.length === chunks.length, `${reader.chunkIndexes.length} chunk indexes for ${chunks.length} chunks`);
  let indexEntries = 0;
  for (const ci of reader.chunkIndexes) {
    const chunk = recordAt(bytes.subarray(Number(ci.chunkStartOffset), Number(ci.chunkStartOffset + ci.chunkLength)));
    if (!check(chunk && chunk.type === "Chunk", `chunk index at ${ci.chunkStartOffset}: no chunk there`)) continue;
    check(chunk.messageStartTime === ci.messageStartTime && chunk.messageEndTime === ci.messageEndTime &&
      chunk.compression === ci.compression && BigInt(chunk.records.length) === ci.compressedSize &&
      chunk.uncompressedSize === ci.uncompressedSize, `chunk index at ${ci.chunkStartOffset} disagrees with its chunk`);
    const raw = chunk.compression === "" ? chunk.records : decompressHandlers[chunk.compression](chunk.records, chunk.uncompressedSize);
    check(crc32(raw) === chunk.uncompressedCrc, `chunk at ${ci.chunkStartOffset}: CRC of its records`);
    let indexBytes = 0n;
    for (const [channelId, offset] of ci.messageIndexOffsets) {
      const mi = recordAt(bytes.subarray(Number(offset)));
      if (!check(mi && mi.type === "MessageIndex" && mi.channelId === channelId, `message index of channel ${channelId} not at ${offset}`)) continue;
      indexBytes += BigInt(1 + 8 + 2 + 4 + 16 * mi.records.length);
      for (const [logTime, at] of mi.records) {
        indexEntries += 1;
        const m = recordInChunk(prelude, raw, Number(at));
        check(m && m.type === "Message" && m.channelId === channelId && m.logTime === logTime,
          `message index entry (${logTime}, ${at}) of channel ${channelId} does not point at its message`);
      }
    }
    check(indexBytes === ci.messageIndexLength, `chunk at ${ci.chunkStartOffset}: message index length ${ci.messageIndexLength}, found ${indexBytes}`);
  }
  check(indexEntries === streamMessages.length, `${indexEntries} message index entries for ${streamMessages.length} messages`);

  // 4. Every message through the indexes, decoded and validated.
  const ajv = new Ajv({ strict: false, allErrors: false });
  const validators = new Map();
  for (const [id, s] of reader.schemasById) {
    check(s.encoding === "jsonschema", `schema ${s.name}: encoding ${s.encoding}`);
    const own = JSON.parse(new TextDecoder().decode(s.data));
    const theirs = s.name.startsWith("foxglove.") ? foxgloveSchemas[s.name.slice("foxglove.".length)] : undefined;
    check(!s.name.startsWith("foxglove.") || theirs !== undefined, `schema ${s.name}: not one of @foxglove/schemas`);
    check(own.title === s.name, `schema ${s.name}: its title is ${own.title}`);
    validators.set(id, { official: theirs ? ajv.compile(theirs) : undefined, own: ajv.compile(own) });
  }
  const byTopic = new Map();
  let count = 0;
  let lastTime = -1n;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    count += 1;
    check(m.logTime >= lastTime, "messages not in log time order");
    lastTime = m.logTime;
    const ch = reader.channelsById.get(m.channelId);
    check(ch.messageEncoding === "json", `${ch.topic}: message encoding ${ch.messageEncoding}`);
    let msg;
    try {
      msg = JSON.parse(new TextDecoder("utf-8", { fatal: true }).decode(m.data));
    } catch (e) {
      fail(`${ch.topic}: a message is not JSON (${e.message})`);
      continue;
    }
    const v = validators.get(ch.schemaId);
    for (const [which, fn] of [["@foxglove/schemas", v.official], ["the file's own schema", v.own]]) {
      if (fn && !fn(msg)) fail(`${ch.topic} at ${m.logTime}: not valid against ${which}: ${ajv.errorsText(fn.errors)}`);
    }
    if (msg.timestamp) {
      const t = BigInt(msg.timestamp.sec) * 1000000000n + BigInt(msg.timestamp.nsec);
      check(t === m.logTime && m.publishTime === m.logTime, `${ch.topic}: timestamp ${t}, log time ${m.logTime}, publish time ${m.publishTime}`);
    }
    if (!byTopic.has(ch.topic)) byTopic.set(ch.topic, []);
    byTopic.get(ch.topic).push({ logTime: m.logTime, msg });
  }
  check(count === streamMessages.length, `the indexed reader read ${count} messages, the stream ${streamMessages.length}`);
  if (st && st.messageEndTime > st.messageStartTime) {
    const a = st.messageStartTime + (st.messageEndTime - st.messageStartTime) / 3n;
    const b = st.messageStartTime + (2n * (st.messageEndTime - st.messageStartTime)) / 3n;
    let inRange = 0;
    for await (const m of reader.readMessages({ startTime: a, endTime: b })) {
      check(m.logTime >= a && m.logTime <= b, "a time-range read returned a message outside the range");
      inRange += 1;
    }
    const expected = streamMessages.filter((m) => m.logTime >= a && m.logTime <= b).length;
    check(inRange === expected, `a time-range read returned ${inRange} messages, the file holds ${expected} in the range`);
  }
  const field = byTopic.get("/field") || [];
  if (field.length) {
    check(field.length === 1, `/field: ${field.length} messages, expected one`);
    const ch = [...reader.channelsById.values()].find((c) => c.topic === "/field");
    check(ch.metadata.get("latching") === "1", "/field is not marked latching");
  }

  // 5. The round trip against the run folder or the recording.
  const summary = { file, messages: count, chunks: chunks.length, compression: chunks[0] ? chunks[0].compression : "", topics: {} };
  for (const [t, ms] of byTopic) summary.topics[t] = ms.length;
  // What a Plot panel can plot: the keys of each robot's per-frame numbers.
  summary.number_keys = {};
  for (const [t, ms] of byTopic) {
    if (t.endsWith("/numbers")) summary.number_keys[t] = [...new Set(ms.flatMap((m) => Object.keys(m.msg)))].sort();
  }
  let points = 0;
  let poses = 0;
  const runView = runDir && fs.existsSync(path.join(runDir, "view.jsonl"));
  if (runDir) {
    const ids = robotIds(runDir);
    const view = runView
      ? fs.readFileSync(path.join(runDir, "view.jsonl"), "utf8").split("\n").filter((l) => l.trim()).map((l) => JSON.parse(l)) : null;
    ids.forEach((id, i) => {
      const suffix = i === 0 ? "" : `_r${id}`;
      summary.numbers = (summary.numbers || 0) + compareNumbers(`/r${id}/numbers`, byTopic.get(`/r${id}/numbers`) || [], runDir, id);
      const est = readTum(path.join(runDir, `est${suffix}.tum`));
      comparePoses(`/r${id}/estimate`, byTopic.get(`/r${id}/estimate`) || [], est, `est${suffix}.tum`);
      poses += est.length;
      if (fs.existsSync(path.join(runDir, `gt${suffix}.tum`))) {
        const gt = readTum(path.join(runDir, `gt${suffix}.tum`));
        comparePoses(`/r${id}/truth`, byTopic.get(`/r${id}/truth`) || [], gt, `gt${suffix}.tum`);
        poses += gt.length;
      }
      if (view) {
        const frames = view.filter((o) => o.robot === id).map((o) => ({ t: o.t, points: o.line_points }));
        points += compareLinePoints(`/r${id}/line_points`, byTopic.get(`/r${id}/line_points`) || [], frames);
        summary.blobs = (summary.blobs || 0) + compareBlobs(`/r${id}/blobs`, byTopic.get(`/r${id}/blobs`) || [],
          view.filter((o) => o.robot === id));
      }
    });
  }
  if (recDir) {
    const head = JSON.parse(fs.readFileSync(path.join(recDir, "recording.json"), "utf8"));
    const name = head.frames_file || "frames.jsonl";
    let text = fs.readFileSync(path.join(recDir, name));
    if (name.endsWith(".gz")) text = zlib.gunzipSync(text);
    const frames = text.toString("utf8").split("\n").filter((l) => l.trim()).map((l) => JSON.parse(l));
    head.robots.forEach((r, i) => {
      const id = r.id;
      const mine = frames.map((f) => ({ t: f.t, k: f.k, robot: f.robots[i] }));
      if (!runView) {
        points += compareLinePoints(`/r${id}/line_points`, byTopic.get(`/r${id}/line_points`) || [],
          mine.map((f) => ({ t: f.t, points: f.robot.line_points })));
      }
      if (!runDir) {
        const truth = mine.filter((f) => Array.isArray(f.robot.truth));
        const msgs = byTopic.get(`/r${id}/truth`) || [];
        if (check(msgs.length === truth.length, `/r${id}/truth: ${msgs.length} messages, the recording has ${truth.length} truths`)) {
          truth.forEach((f, j) => {
            const p = msgs[j].msg.pose;
            poses += 1;
            check(msgs[j].logTime === ns(f.t) && p.position.x === f.robot.truth[0] && p.position.y === f.robot.truth[1] &&
              angleDiff(yaw(p.orientation), f.robot.truth[2]) < 1e-12, `/r${id}/truth frame ${f.k} differs from the recording's`);
          });
        }
      }
      if (head.images === true) {
        const imgs = byTopic.get(`/r${id}/camera`) || [];
        check(imgs.length > 0, `/r${id}/camera: no images, the recording holds them`);
        for (const m of imgs) {
          const k = frames.findIndex((f) => ns(f.t) === m.logTime);
          const png = fs.readFileSync(path.join(recDir, "images", `r${id}_${String(k).padStart(6, "0")}.png`));
          check(k >= 0 && Buffer.from(m.msg.data, "base64").equals(png) && m.msg.format === "png",
            `/r${id}/camera at ${m.logTime}: not the recorded PNG`);
        }
        summary.images = (summary.images || 0) + imgs.length;
      }
    });
  }
  summary.round_trip = { poses, line_points: points };
  console.log(JSON.stringify(summary));
  if (failures.length) {
    console.error(`${failures.length} check(s) failed in ${file}`);
    process.exit(1);
  }
}

main().catch((e) => {
  console.error(`FAIL: ${process.argv[2]}: ${e && e.stack ? e.stack : e}`);
  process.exit(1);
});
