// What a killed recorder kept: every message of the CSV recording (a recorder that ran to the
// end beside it) received more than --flush-s before the kill must be in the recovered MCAP
// file, read through its index by Foxglove's @mcap/core. The recorder checks its flush deadline
// every 50 ms, so the bound is flush_s + 0.1 s.
// Usage: node check_crash.mjs RECOVERED.mcap CSV_DIR KILL_TIME_NS FLUSH_S. Exits 1 if one is lost.
import { readFileSync, existsSync } from "node:fs";
import { McapIndexedReader } from "@mcap/core";
import { decompress as zstdDecompress } from "fzstd";
import { parse as parseCsv } from "csv-parse/sync";

const [file, csvDir, killArg, flushArg] = process.argv.slice(2);
const killNs = BigInt(killArg);
const boundNs = BigInt(Math.round((Number(flushArg) + 0.1) * 1e9));
const bytes = new Uint8Array(readFileSync(file));
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
};
const indexed = await McapIndexedReader.Initialize({
  readable,
  decompressHandlers: { zstd: (data) => zstdDecompress(data) },
});
const published = new Map(); // channel id -> set of publish times (the DDS source time stamps)
let newest = 0n;
for await (const m of indexed.readMessages()) {
  if (!published.has(m.channelId)) published.set(m.channelId, new Set());
  published.get(m.channelId).add(m.publishTime);
  if (m.logTime > newest) newest = m.logTime;
}
let lost = 0;
let required = 0;
let keptAfter = 0;
let csvAfter = 0;
for (const channel of indexed.channelsById.values()) {
  const csvFile = `${csvDir}/${channel.topic.replace(/^\//, "").replaceAll("/", "_")}.csv`;
  if (!existsSync(csvFile)) continue;
  // Latest-value streams (health, progress) are sampled: two readers need not get the same ones.
  if (/health|progress/.test(channel.metadata.get("reader_profile") ?? "")) continue;
  const rows = parseCsv(readFileSync(csvFile), { columns: true, skip_empty_lines: true });
  const have = published.get(channel.id) ?? new Set();
  const seen = new Set();
  for (const row of rows) {
    const source = BigInt(row.source_timestamp_ns);
    if (seen.has(source)) continue; // a message's further rows
    seen.add(source);
    const age = killNs - BigInt(row.reception_timestamp_ns);
    if (age > boundNs) {
      required += 1;
      if (!have.has(source)) {
        lost += 1;
        if (lost <= 10) console.log(`LOST: ${channel.topic} source ${source}, received ${Number(age) / 1e9} s before the kill`);
      }
    } else if (age > 0n) {
      csvAfter += 1;
      if (have.has(source)) keptAfter += 1;
    }
  }
}
console.log(
  `kill at ${killNs} ns: ${required} messages received more than ${Number(boundNs) / 1e9} s ` +
    `before it, ${lost} of them lost; of the ${csvAfter} in the last ${Number(boundNs) / 1e9} s, ` +
    `${keptAfter} kept; the newest kept was logged ${Number(killNs - newest) / 1e9} s before the kill`,
);
if (required === 0) {
  console.log("FAIL: no message old enough to check");
  process.exit(1);
}
process.exit(lost === 0 ? 0 : 1);
