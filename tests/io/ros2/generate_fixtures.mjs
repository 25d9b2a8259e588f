// Writes keyplace's ROS 2 bag test fixtures (tests/data/ros2/) from a slice of a CARMEN log, with
// writers keyplace does not contain: @mcap/core (MCAP), @foxglove/rosmsg2-serialization (CDR),
// sql.js (SQLite, for rosbag2's sqlite3 storage), @foxglove/wasm-zstd and lz4js (chunk codecs).
// The tests read the committed fixtures; node is needed only to write them again:
//
//   cd tests/io/ros2 && npm ci && node generate_fixtures.mjs
//
// Input: tests/data/ros2/fr079-raw-first150.log.gz, the first 150 FLASER lines of
// ../shared/data/fr079-raw.log.gz with every ODOM line before the 151st scan (committed beside the
// bags; `node generate_fixtures.mjs --slice PATH` cuts it again from the full log). Each scan
// becomes a sensor_msgs/msg/LaserScan on /scan (stamp = ipc_timestamp, frame "laser", 360 beams
// from -pi/2 in steps of pi/360, range_max 80 m as keyplace's FLASER default), each ODOM line a
// nav_msgs/msg/Odometry on /odom (or a /tf transform odom -> base_link), the laser at x = -0.04 m
// on /tf_static; every message's recorder time (log_time, timestamp) is the line's
// logger_timestamp.
//
// Output (each a rosbag2 directory with metadata.yaml):
//   mcap-none/   MCAP, chunks uncompressed      mcap-zstd/  MCAP, zstd chunks
//   mcap-lz4/    MCAP, lz4 chunks                sqlite3/    rosbag2 sqlite3 (.db3)
//   mcap-tf/     MCAP, zstd chunks, odometry only on /tf (no /odom topic)
//
// `node generate_fixtures.mjs --seeds` also writes the fuzz seeds of tests/fuzz/corpus/mcap (the
// first 4 scans cut to 24 beams, MCAP with 1 KiB chunks per compression), tests/fuzz/corpus/ros2_sqlite
// (the same 4 scans as sqlite3 storage, odometry on /odom or on /tf) and tests/fuzz/corpus/ros2_cdr
// (one CDR message of each type).

import fs from "node:fs";
import path from "node:path";
import zlib from "node:zlib";
import { fileURLToPath } from "node:url";

import { McapWriter } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "lz4js";
import initSqlJs from "sql.js";

const here = path.dirname(fileURLToPath(import.meta.url));
const outDir = path.resolve(here, "../../data/ros2");
const slicePath = path.join(outDir, "fr079-raw-first150.log.gz");
const kScans = 150;

// ROS 2 message definitions, concatenated as rosbag2 stores them in an MCAP schema (ros2msg).
const kHeader = "builtin_interfaces/Time stamp\nstring frame_id\n";
const kTime = "int32 sec\nuint32 nanosec\n";
const kDefinitions = {
  "sensor_msgs/msg/LaserScan": [
    "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n" +
      "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\n" +
      "float32[] ranges\nfloat32[] intensities\n",
    ["std_msgs/Header", kHeader],
    ["builtin_interfaces/Time", kTime],
  ],
  "nav_msgs/msg/Odometry": [
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n" +
      "geometry_msgs/TwistWithCovariance twist\n",
    ["std_msgs/Header", kHeader],
    ["builtin_interfaces/Time", kTime],
    ["geometry_msgs/PoseWithCovariance", "Pose pose\nfloat64[36] covariance\n"],
    ["geometry_msgs/Pose", "Point position\nQuaternion orientation\n"],
    ["geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"],
    ["geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"],
    ["geometry_msgs/TwistWithCovariance", "Twist twist\nfloat64[36] covariance\n"],
    ["geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"],
    ["geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"],
  ],
  "tf2_msgs/msg/TFMessage": [
    "geometry_msgs/TransformStamped[] transforms\n",
    ["geometry_msgs/TransformStamped",
     "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"],
    ["std_msgs/Header", kHeader],
    ["builtin_interfaces/Time", kTime],
    ["geometry_msgs/Transform", "Vector3 translation\nQuaternion rotation\n"],
    ["geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"],
    ["geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"],
  ],
};

function definitionText(type) {
  const [main, ...deps] = kDefinitions[type];
  let text = main;
  for (const [name, body] of deps) text += "=".repeat(80) + "\nMSG: " + name + "\n" + body;
  return text;
}

const writers = {};
for (const type of Object.keys(kDefinitions)) {
  writers[type] = new MessageWriter(parse(definitionText(type), { ros2: true }));
}

// Keeps the first kScans FLASER lines and the ODOM lines before the next one.
function cutSlice(fullLog) {
  const lines = zlib.gunzipSync(fs.readFileSync(fullLog)).toString("utf8").split("\n");
  const kept = [];
  let scans = 0;
  for (const line of lines) {
    if (line.startsWith("FLASER") && ++scans > kScans) break;
    kept.push(line);
  }
  fs.writeFileSync(slicePath, zlib.gzipSync(kept.join("\n") + "\n", { level: 9 }));
}

function stampOf(seconds) {
  // The decimal text of the log split at the point, so no binary rounding enters the stamp.
  const [sec, frac = ""] = seconds.split(".");
  return { sec: Number(sec), nanosec: Number((frac + "000000000").slice(0, 9)) };
}

function nanoseconds(seconds) {
  const { sec, nanosec } = stampOf(seconds);
  return BigInt(sec) * 1000000000n + BigInt(nanosec);
}

function quaternion(theta) {
  return { x: 0, y: 0, z: Math.sin(theta / 2), w: Math.cos(theta / 2) };
}

// [{topic, type, logTime (bigint ns), message}] in log order.
function messagesOf(tfOdometry, seedScans = 0) {
  const text = zlib.gunzipSync(fs.readFileSync(slicePath)).toString("utf8");
  const out = [];
  let scans = 0;
  const laser = {
    header: { stamp: { sec: 0, nanosec: 0 }, frame_id: "base_link" },
    child_frame_id: "laser",
    transform: { translation: { x: -0.04, y: 0, z: 0 }, rotation: quaternion(0) },
  };
  out.push({ topic: "/tf_static", type: "tf2_msgs/msg/TFMessage", logTime: 0n,
             message: { transforms: [laser] } });
  for (const line of text.split("\n")) {
    const f = line.split(" ");
    if (f[0] === "FLASER") {
      if (seedScans > 0 && ++scans > seedScans) break;
      const n = Number(f[1]);
      const beams = seedScans > 0 ? 24 : n;
      const ranges = Float32Array.from(f.slice(2, 2 + beams).map(Number));
      const rest = f.slice(2 + n);  // x y theta odom_x odom_y odom_theta ipc host logger
      out.push({ topic: "/scan", type: "sensor_msgs/msg/LaserScan", logTime: nanoseconds(rest[8]),
                 message: {
                   header: { stamp: stampOf(rest[6]), frame_id: "laser" },
                   angle_min: -Math.PI / 2, angle_max: Math.PI / 2 - Math.PI / n,
                   angle_increment: Math.PI / n, time_increment: 0, scan_time: 0,
                   range_min: 0, range_max: 80, ranges, intensities: new Float32Array(0),
                 } });
    } else if (f[0] === "ODOM") {
      const [x, y, theta, tv, rv] = f.slice(1, 6).map(Number);
      const header = { stamp: stampOf(f[7]), frame_id: "odom" };
      const logTime = nanoseconds(f[9]);
      if (tfOdometry) {
        out.push({ topic: "/tf", type: "tf2_msgs/msg/TFMessage", logTime, message: {
          transforms: [{ header, child_frame_id: "base_link",
                         transform: { translation: { x, y, z: 0 }, rotation: quaternion(theta) } }],
        } });
      } else {
        out.push({ topic: "/odom", type: "nav_msgs/msg/Odometry", logTime, message: {
          header, child_frame_id: "base_link",
          pose: { pose: { position: { x, y, z: 0 }, orientation: quaternion(theta) },
                  covariance: new Float64Array(36) },
          twist: { twist: { linear: { x: tv, y: 0, z: 0 }, angular: { x: 0, y: 0, z: rv } },
                   covariance: new Float64Array(36) },
        } });
      }
    }
  }
  return out;
}

function metadataYaml(storage, file, messages) {
  const topics = new Map();
  for (const m of messages) {
    const entry = topics.get(m.topic) ?? { type: m.type, count: 0 };
    entry.count += 1;
    topics.set(m.topic, entry);
  }
  const start = messages.reduce((a, m) => (m.logTime < a ? m.logTime : a), messages[0].logTime);
  const end = messages.reduce((a, m) => (m.logTime > a ? m.logTime : a), messages[0].logTime);
  let yaml = "rosbag2_bagfile_information:\n  version: 5\n";
  yaml += `  storage_identifier: ${storage}\n  duration:\n    nanoseconds: ${end - start}\n`;
  yaml += `  starting_time:\n    nanoseconds_since_epoch: ${start}\n`;
  yaml += `  message_count: ${messages.length}\n  topics_with_message_count:\n`;
  for (const [name, { type, count }] of topics) {
    yaml += `    - topic_metadata:\n        name: ${name}\n        type: ${type}\n`;
    yaml += `        serialization_format: cdr\n        offered_qos_profiles: ""\n`;
    yaml += `      message_count: ${count}\n`;
  }
  yaml += `  compression_format: ""\n  compression_mode: ""\n`;
  yaml += `  relative_file_paths:\n    - ${file}\n  files:\n    - path: ${file}\n`;
  yaml += `      starting_time:\n        nanoseconds_since_epoch: ${start}\n`;
  yaml += `      duration:\n        nanoseconds: ${end - start}\n`;
  yaml += `      message_count: ${messages.length}\n`;
  return yaml;
}

class BufferWritable {
  constructor() { this.chunks = []; this.size = 0n; }
  position() { return this.size; }
  async write(buffer) { this.chunks.push(Buffer.from(buffer)); this.size += BigInt(buffer.length); }
  bytes() { return Buffer.concat(this.chunks); }
}

async function mcapBytes(messages, compression, chunkSize) {
  const compressors = {
    none: undefined,
    zstd: (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 19) }),
    lz4: (data) => ({ compression: "lz4", compressedData: Uint8Array.from(lz4.compress(data)) }),
  };
  const writable = new BufferWritable();
  const writer = new McapWriter({ writable, chunkSize, compressChunk: compressors[compression] });
  await writer.start({ profile: "ros2", library: "keyplace generate_fixtures.mjs" });
  const channels = new Map();
  for (const m of messages) {
    if (!channels.has(m.topic)) {
      const schemaId = await writer.registerSchema({
        name: m.type, encoding: "ros2msg",
        data: new TextEncoder().encode(definitionText(m.type)) });
      channels.set(m.topic, await writer.registerChannel({
        topic: m.topic, schemaId, messageEncoding: "cdr", metadata: new Map() }));
    }
  }
  let sequence = 0;
  for (const m of messages) {
    await writer.addMessage({ channelId: channels.get(m.topic), sequence: sequence++,
                              logTime: m.logTime, publishTime: m.logTime,
                              data: writers[m.type].writeMessage(m.message) });
  }
  await writer.end();
  return writable.bytes();
}

async function writeMcap(dir, compression, tfOdometry) {
  const messages = messagesOf(tfOdometry);
  const file = path.basename(dir) + "_0.mcap";
  fs.mkdirSync(dir, { recursive: true });
  // 64 KiB chunks: several per fixture, so that a cut file keeps some complete ones.
  fs.writeFileSync(path.join(dir, file), await mcapBytes(messages, compression, 64 * 1024));
  fs.writeFileSync(path.join(dir, "metadata.yaml"), metadataYaml("mcap", file, messages));
}

// rosbag2's sqlite3 storage schema (version 3): topics and messages tables. The fuzz seeds use
// 512-byte pages (SQLite's least) to keep them small.
async function sqliteBytes(messages, pageBytes = 0) {
  const SQL = await initSqlJs();
  const db = new SQL.Database();
  if (pageBytes > 0) db.run(`PRAGMA page_size = ${pageBytes}`);
  db.run("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)");
  db.run("INSERT INTO schema VALUES (3, 'humble')");
  db.run("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, " +
         "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)");
  db.run("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, " +
         "timestamp INTEGER NOT NULL, data BLOB NOT NULL)");
  db.run("CREATE INDEX timestamp_idx ON messages (timestamp ASC)");
  const ids = new Map();
  for (const m of messages) {
    if (!ids.has(m.topic)) {
      ids.set(m.topic, ids.size + 1);
      db.run("INSERT INTO topics VALUES (?, ?, ?, 'cdr', '')", [ids.get(m.topic), m.topic, m.type]);
    }
  }
  const insert = db.prepare("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)");
  for (const m of messages) {
    // sql.js binds numbers as doubles: the stamps (< 2^53 ns) stay exact.
    insert.run([ids.get(m.topic), Number(m.logTime), writers[m.type].writeMessage(m.message)]);
  }
  insert.free();
  const bytes = Buffer.from(db.export());
  db.close();
  return bytes;
}

async function writeSqlite(dir) {
  const messages = messagesOf(false);
  const file = path.basename(dir) + "_0.db3";
  fs.mkdirSync(dir, { recursive: true });
  fs.writeFileSync(path.join(dir, file), await sqliteBytes(messages));
  fs.writeFileSync(path.join(dir, "metadata.yaml"), metadataYaml("sqlite3", file, messages));
}

async function writeSeeds() {
  const fuzz = path.resolve(here, "../../fuzz/corpus");
  fs.mkdirSync(path.join(fuzz, "mcap"), { recursive: true });
  fs.mkdirSync(path.join(fuzz, "ros2_cdr"), { recursive: true });
  fs.mkdirSync(path.join(fuzz, "ros2_sqlite"), { recursive: true });
  for (const compression of ["none", "lz4", "zstd"]) {
    const bytes = await mcapBytes(messagesOf(false, 4), compression, 1024);
    fs.writeFileSync(path.join(fuzz, "mcap", `fr079-4-scans-${compression}.mcap`), bytes);
  }
  fs.writeFileSync(path.join(fuzz, "mcap", "fr079-4-scans-tf-zstd.mcap"),
                   await mcapBytes(messagesOf(true, 4), "zstd", 1024));
  fs.writeFileSync(path.join(fuzz, "ros2_sqlite", "fr079-4-scans.db3"),
                   await sqliteBytes(messagesOf(false, 4), 512));
  fs.writeFileSync(path.join(fuzz, "ros2_sqlite", "fr079-4-scans-tf.db3"),
                   await sqliteBytes(messagesOf(true, 4), 512));
  const seen = new Set();
  for (const m of messagesOf(false, 2).concat(messagesOf(true, 2))) {
    const name = m.type.split("/").pop() + (m.topic === "/tf_static" ? "-static" : "");
    if (seen.has(name)) continue;
    seen.add(name);
    fs.writeFileSync(path.join(fuzz, "ros2_cdr", `${name}.cdr`), writers[m.type].writeMessage(m.message));
  }
}

const sliceFlag = process.argv.indexOf("--slice");
if (sliceFlag > 0) cutSlice(process.argv[sliceFlag + 1]);
await zstd.isLoaded;
await writeMcap(path.join(outDir, "mcap-none"), "none", false);
await writeMcap(path.join(outDir, "mcap-zstd"), "zstd", false);
await writeMcap(path.join(outDir, "mcap-lz4"), "lz4", false);
await writeMcap(path.join(outDir, "mcap-tf"), "zstd", true);
await writeSqlite(path.join(outDir, "sqlite3"));
if (process.argv.includes("--seeds")) await writeSeeds();
console.log("wrote", outDir);
