// Writes the EuRoC CSV of tests/formats/write_formats.py as MCAP files with
// the @mcap/core writer (an implementation independent of gravcal's reader),
// sensor_msgs/msg/Imu in CDR serialised here.
//
// usage: node write_mcap.mjs <node_modules folder> <euroc.csv> <out folder>
// Writes mcap_plain.mcap (no chunks), mcap_chunked.mcap (uncompressed chunks),
// mcap_zstd.mcap and mcap_lz4.mcap (chunks compressed by the zstd and lz4
// command-line tools, LZ4 frame format as MCAP requires).
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const [modules, eurocPath, out] = process.argv.slice(2);
const require = createRequire(path.join(modules, "index.js"));
const { McapWriter } = require("@mcap/core");

const IMU_DEFINITION = `std_msgs/Header header
geometry_msgs/Quaternion orientation
float64[9] orientation_covariance
geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance
geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance
`;

function cdrImu(ns, gyro, accel) {
  const frame = Buffer.from("imu_link\0");
  let size = 8 + 4 + frame.length;
  const pad = (8 - (size % 8)) % 8;
  const body = Buffer.alloc(size + pad + 37 * 8);
  body.writeInt32LE(Number(ns / 1000000000n), 0);
  body.writeUInt32LE(Number(ns % 1000000000n), 4);
  body.writeUInt32LE(frame.length, 8);
  frame.copy(body, 12);
  const values = [0, 0, 0, 1, ...Array(9).fill(0), ...gyro, ...Array(9).fill(0), ...accel,
                  ...Array(9).fill(0)];
  values.forEach((v, i) => body.writeDoubleLE(v, size + pad + 8 * i));
  return Buffer.concat([Buffer.from([0, 1, 0, 0]), body]);
}

class MemoryWritable {
  constructor() { this.parts = []; this.size = 0n; }
  position() { return this.size; }
  async write(buffer) { this.parts.push(Buffer.from(buffer)); this.size += BigInt(buffer.byteLength); }
}

const lines = fs.readFileSync(eurocPath, "utf8").split(/\r?\n/).filter((l) => l && !l.startsWith("#"));
const samples = lines.map((l) => {
  const f = l.split(",");
  return { ns: BigInt(f[0]), gyro: f.slice(1, 4).map(Number), accel: f.slice(4, 7).map(Number) };
});

function tool(name, args) {
  return (data) => ({ compression: name, compressedData: execFileSync(name, args, { input: data }) });
}

const variants = {
  mcap_plain: { useChunks: false },
  mcap_chunked: { useChunks: true, chunkSize: 256 * 1024 },
  mcap_zstd: { useChunks: true, chunkSize: 256 * 1024, compressChunk: tool("zstd", ["-c", "-q"]) },
  mcap_lz4: { useChunks: true, chunkSize: 256 * 1024, compressChunk: tool("lz4", ["-c", "-q"]) },
};

for (const [name, options] of Object.entries(variants)) {
  const writable = new MemoryWritable();
  const writer = new McapWriter({ writable, ...options });
  await writer.start({ profile: "ros2", library: "gravcal formats test" });
  const schemaId = await writer.registerSchema({
    name: "sensor_msgs/msg/Imu", encoding: "ros2msg", data: new TextEncoder().encode(IMU_DEFINITION),
  });
  const logSchema = await writer.registerSchema({
    name: "std_msgs/msg/String", encoding: "ros2msg", data: new TextEncoder().encode("string data\n"),
  });
  const imu = await writer.registerChannel({
    topic: "/imu/data", schemaId, messageEncoding: "cdr", metadata: new Map(),
  });
  const status = await writer.registerChannel({
    topic: "/status", schemaId: logSchema, messageEncoding: "cdr", metadata: new Map(),
  });
  let k = 0;
  for (const s of samples) {
    const logTime = s.ns + 1000n;
    await writer.addMessage({ channelId: imu, sequence: k, logTime, publishTime: logTime,
                              data: cdrImu(s.ns, s.gyro, s.accel) });
    if (k % 100 === 0) {
      await writer.addMessage({ channelId: status, sequence: k, logTime, publishTime: logTime,
                                data: Buffer.from([0, 1, 0, 0, 3, 0, 0, 0, 111, 107, 0]) });
    }
    ++k;
  }
  await writer.end();
  fs.writeFileSync(path.join(out, name + ".mcap"), Buffer.concat(writable.parts));
}
