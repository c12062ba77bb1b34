// navbus's MCAP file read by Foxglove's own libraries, independent of navbus's reader:
//   1. @mcap/core's stream reader reads every record front to back, checking the chunks' CRCs;
//   2. its indexed reader opens the file from the footer (summary, statistics, chunk and
//      message indexes) and reads every message through the index: the same messages, and the
//      statistics' counts;
//   3. every channel's schema is parsed by Foxglove's parser (OMG IDL: @foxglove/omgidl-parser;
//      ROS 2 msg: @foxglove/rosmsg) and every message decoded from its CDR bytes
//      (@foxglove/omgidl-serialization, @foxglove/rosmsg2-serialization);
//   4. the decoded fields equal the CSV recording of the same run (navbus record --format csv),
//      message by message, matched by their DDS source time stamps;
//   5. with --foxglove, the channels in Foxglove's schemas (LocationFix, Log) are valid under
//      Foxglove's published schemas and equal the recorded solutions and decisions, every one.
// Usage: node check_mcap.mjs FILE.mcap CSV_DIR [--ros2] [--foxglove]. Exits 1 naming the first difference.
import { readFileSync, existsSync } from "node:fs";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader as IdlReader } from "@foxglove/omgidl-serialization";
import { parse as parseRosMsg } from "@foxglove/rosmsg";
import { MessageReader as Ros2Reader } from "@foxglove/rosmsg2-serialization";
import { decompress as zstdDecompress } from "fzstd";
import { parse as parseCsv } from "csv-parse/sync";
import { compareRows, constants } from "./csv_compare.mjs";
import { checkDerived, isDerivedChannel } from "./foxglove_derived.mjs";

const [file, csvDir, ...flags] = process.argv.slice(2);
const ros2 = flags.includes("--ros2");
const expectDerived = flags.includes("--foxglove"); // recorded with navbus record --foxglove
const bytes = new Uint8Array(readFileSync(file));
const decompressHandlers = {
  zstd: (data, size) => {
    const out = zstdDecompress(data);
    if (BigInt(out.length) !== size) throw new Error(`zstd chunk: ${out.length} != ${size} bytes`);
    return out;
  },
};
let failures = 0;
const fail = (what) => {
  failures += 1;
  if (failures <= 20) console.log(`FAIL: ${what}`);
};

// 1. Every record, front to back.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(bytes);
const streamed = [];
const opcodes = new Map();
for (let record; (record = stream.nextRecord()); ) {
  opcodes.set(record.type, (opcodes.get(record.type) ?? 0) + 1);
  if (record.type === "Message") streamed.push(record);
}
if (!stream.done()) fail("the stream reader did not reach the end of the file");
console.log(`stream reader: ${[...opcodes].map(([k, v]) => `${v} ${k}`).join(", ")}`);

// 2. Through the index.
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
};
const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const stats = indexed.statistics;
const viaIndex = [];
for await (const m of indexed.readMessages({ validateCrcs: true })) viaIndex.push(m);
console.log(
  `indexed reader: ${indexed.chunkIndexes.length} chunk indexes, ${indexed.channelsById.size} ` +
    `channels, ${indexed.schemasById.size} schemas, ${viaIndex.length} messages; statistics ` +
    `${stats?.messageCount} messages, ${stats?.chunkCount} chunks`,
);
if (stats === undefined) fail("no Statistics record in the summary");
if (BigInt(viaIndex.length) !== stats?.messageCount) fail("the index and the statistics disagree");
if (viaIndex.length !== streamed.length) fail("the index and the stream disagree on the count");
for (const [id, n] of stats?.channelMessageCounts ?? []) {
  const counted = viaIndex.filter((m) => m.channelId === id).length;
  if (BigInt(counted) !== n) fail(`channel ${id}: statistics ${n}, index ${counted}`);
}
const key = (m) => `${m.channelId}/${m.sequence}/${m.logTime}`;
const byKey = new Map(streamed.map((m) => [key(m), m]));
for (const m of viaIndex) {
  const s = byKey.get(key(m));
  if (!s || Buffer.compare(Buffer.from(s.data), Buffer.from(m.data)) !== 0) {
    fail(`message ${key(m)} differs between the index and the stream`);
  }
}
if (indexed.header.profile !== (ros2 ? "ros2" : "")) fail(`profile '${indexed.header.profile}'`);

// 3 and 4. Decode every channel and compare with the CSV recording.
let topicsCompared = 0;
let derivedChecked = 0; // channels in Foxglove's schemas (navbus record --foxglove)
const counts = { summarized: 0 }; // CSV cells that summarize structs as text, left uncompared
const recordFileName = (topic) => `${topic.replace(/^\//, "").replaceAll("/", "_")}.csv`;
for (const channel of indexed.channelsById.values()) {
  const schema = indexed.schemasById.get(channel.schemaId);
  const messages = viaIndex.filter((m) => m.channelId === channel.id);
  if (isDerivedChannel(channel.messageEncoding)) {
    const schemaText = new TextDecoder().decode(schema.data);
    const bytes = messages.map((m) => m.data);
    console.log(
      checkDerived({ topic: channel.topic, schemaName: schema.name, schemaText, messages: bytes,
                     csvDir, complete: true, fail }),
    );
    derivedChecked += 1;
    continue;
  }
  const expectedEncoding = ros2 ? "ros2msg" : "omgidl";
  if (schema.encoding !== expectedEncoding || channel.messageEncoding !== "cdr") {
    fail(`${channel.topic}: schema ${schema.encoding}, messages ${channel.messageEncoding}`);
    continue;
  }
  const text = new TextDecoder().decode(schema.data);
  let reader, enums;
  if (ros2) {
    const definitions = parseRosMsg(text, { ros2: true });
    reader = new Ros2Reader(definitions);
    enums = constants(definitions);
  } else {
    const definitions = parseIDL(text);
    reader = new IdlReader(schema.name, definitions);
    enums = constants(definitions);
  }
  const decoded = messages.map((m) => ({ m, value: reader.readMessage(m.data) }));
  const csvFile = `${csvDir}/${recordFileName(channel.topic)}`;
  if (!existsSync(csvFile)) {
    fail(`${channel.topic}: no CSV recording ${csvFile}`);
    continue;
  }
  const rows = parseCsv(readFileSync(csvFile), { columns: true, skip_empty_lines: true });
  // A message's rows (one per element of its sequence of structs) by source time stamp.
  const csvBySource = new Map();
  for (const row of rows) {
    const k = row.source_timestamp_ns;
    if (!csvBySource.has(k)) csvBySource.set(k, []);
    csvBySource.get(k).push(row);
  }
  let compared = 0;
  let cells = 0;
  for (const { m, value } of decoded) {
    const group = csvBySource.get(m.publishTime.toString());
    if (!group) continue;
    compared += 1;
    cells += compareRows(channel.topic, value, group, enums, fail, counts);
  }
  console.log(
    `${channel.topic}: ${schema.name} (${schema.encoding}), ${messages.length} messages decoded, ` +
      `${compared} compared with ${rows.length ? csvFile.split("/").pop() : "no rows"} ` +
      `(${cells} fields equal)`,
  );
  if (messages.length === 0 && rows.length === 0) continue; // nothing published on it
  if (compared === 0) fail(`${channel.topic}: no message matched the CSV recording`);
  // Reliable streams: every message is in both recordings. Health and progress reports are
  // latest-value streams, which a slower reader samples.
  const latestValue = /health|progress/.test(channel.metadata.get("reader_profile") ?? "");
  if (!latestValue && compared !== messages.length) {
    fail(`${channel.topic}: ${messages.length - compared} messages not in the CSV recording`);
  }
  if (compared > 0) topicsCompared += 1;
}
if (topicsCompared === 0) fail("no topic was compared");
if (expectDerived && derivedChecked !== 2) fail(`${derivedChecked} of 2 channels in Foxglove's schemas`);
console.log(`${counts.summarized} CSV cells summarize structs as text and were not compared`);
console.log(`${topicsCompared} topics decoded and equal to the CSV recording`);
if (failures > 0) {
  console.log(`${failures} failures`);
  process.exit(1);
}
console.log("mcap check: ok");

