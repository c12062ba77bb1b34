// `navbus foxglove` checked with Foxglove's own client library (@foxglove/ws-protocol over the
// `ws` WebSocket): the server's info, every advertised channel's schema parsed by Foxglove's
// OMG IDL parser, every channel subscribed and its messages decoded (@foxglove/omgidl-
// serialization); after the run, the middle message of each channel equals the CSV recording of
// the same run, field by field; the bridge hop (the frame's receive time, the bridge's DDS
// reception, to this client's reception) on the low-latency solution channel.
// The repository's Foxglove layout names only advertised topics and plots only numbers
// (layout_check.mjs).
// Usage: node check_bridge.mjs ws://HOST:PORT CSV_DIR SECONDS LAYOUT.json [LATENCY_TOPIC]
// Listens SECONDS seconds, then compares once CSV_DIR.done exists (the CSV recorder finished).
// Exits 1 naming the first differences.
import { readFileSync, existsSync } from "node:fs";
import wsProtocol from "@foxglove/ws-protocol"; // CommonJS: its named exports via the default

import WebSocket from "ws";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { parse as parseCsv } from "csv-parse/sync";
import { compareRows, constants } from "./csv_compare.mjs";
import { checkDerived, isDerivedChannel } from "./foxglove_derived.mjs";
import { checkLayout } from "./layout_check.mjs";

const { FoxgloveClient } = wsProtocol;

const [url, csvDir, seconds, layoutFile, latencyTopic = "navbus/nav/solution_low_latency"] =
  process.argv.slice(2);
const advertised = new Map(); // topic -> its middle message decoded (null: none or not decoded)
let failures = 0;
const fail = (what) => {
  failures += 1;
  if (failures <= 20) console.log(`FAIL: ${what}`);
};
const nowNs = () => BigInt(Math.round((performance.timeOrigin + performance.now()) * 1e6));

const client = new FoxgloveClient({
  ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});
const channels = new Map(); // id -> {channel, reader, enums, messages: [], hops: []}
const bySubscription = new Map();
let serverInfo;
let statuses = 0;
client.on("open", () => console.log("connected"));
client.on("serverInfo", (info) => (serverInfo = info));
client.on("status", (s) => {
  statuses += 1;
  fail(`status from the server: ${JSON.stringify(s)}`);
});
client.on("error", (e) => fail(`client error: ${e}`));
client.on("advertise", (list) => {
  for (const channel of list) {
    if (channels.has(channel.id)) continue;
    if (isDerivedChannel(channel.encoding)) {
      // Foxglove's own schemas (JSON): checked by foxglove_derived.mjs after the run.
      channels.set(channel.id, { channel, derived: true, messages: [], hops: [] });
      bySubscription.set(client.subscribe(channel.id), channels.get(channel.id));
      continue;
    }
    let reader, enums;
    try {
      if (channel.encoding !== "cdr" || channel.schemaEncoding !== "omgidl") {
        throw new Error(`encoding ${channel.encoding}, schema ${channel.schemaEncoding}`);
      }
      const definitions = parseIDL(channel.schema);
      reader = new MessageReader(channel.schemaName, definitions);
      enums = constants(definitions);
    } catch (e) {
      fail(`${channel.topic}: schema does not parse: ${e.message}`);
      continue;
    }
    channels.set(channel.id, { channel, reader, enums, messages: [], hops: [] });
    bySubscription.set(client.subscribe(channel.id), channels.get(channel.id));
  }
});
client.on("unadvertise", (ids) => console.log(`withdrawn: channels ${ids.join(", ")}`));
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const received = nowNs();
  const c = bySubscription.get(subscriptionId);
  if (!c) {
    fail(`a message for subscription ${subscriptionId}, which this client never made`);
    return;
  }
  c.messages.push(new Uint8Array(data.buffer, data.byteOffset, data.byteLength).slice());
  c.hops.push(Number(received - timestamp) / 1e6);
});

await new Promise((resolve) => setTimeout(resolve, Number(seconds) * 1000));
client.close();
console.log("listening done");
// The CSV recorder beside the run ends after it: the caller creates CSV_DIR.done then.
for (let waited = 0; !existsSync(`${csvDir}.done`); waited += 0.2) {
  if (waited > 120) {
    fail(`${csvDir}.done did not appear: the CSV recorder did not finish`);
    process.exit(1);
  }
  await new Promise((resolve) => setTimeout(resolve, 200));
}

if (!serverInfo) fail("no Server Info");
else console.log(`server: ${serverInfo.name}, session ${serverInfo.sessionId}`);
let compared = 0;
let derivedChecked = 0;
const percentile = (sorted, p) => sorted[Math.min(sorted.length - 1, Math.floor(p * sorted.length))];
for (const c of channels.values()) {
  const { channel, reader, enums, messages, hops } = c;
  if (!advertised.has(channel.topic)) advertised.set(channel.topic, null);
  if (messages.length === 0) {
    console.log(`${channel.topic}: advertised, no message`);
    continue;
  }
  if (c.derived) {
    const { topic, schemaName, schema: schemaText } = channel;
    console.log(checkDerived({ topic, schemaName, schemaText, messages, csvDir, complete: false, fail }));
    derivedChecked += 1;
    continue;
  }
  let decoded;
  try {
    decoded = messages.map((m) => reader.readMessage(m));
  } catch (e) {
    fail(`${channel.topic}: a message does not decode: ${e.message}`);
    continue;
  }
  const csvFile = `${csvDir}/${channel.topic.replace(/^\//, "").replaceAll("/", "_")}.csv`;
  if (!existsSync(csvFile)) {
    fail(`${channel.topic}: no CSV recording ${csvFile}`);
    continue;
  }
  // The CSV rows of each message (a message has a row per element of its sequence of structs),
  // grouped by the writer's source time stamp; the middle message must equal one of them.
  const rows = parseCsv(readFileSync(csvFile), { columns: true, skip_empty_lines: true });
  const groups = new Map();
  for (const row of rows) {
    if (!groups.has(row.source_timestamp_ns)) groups.set(row.source_timestamp_ns, []);
    groups.get(row.source_timestamp_ns).push(row);
  }
  const middle = decoded[Math.floor(decoded.length / 2)];
  advertised.set(channel.topic, middle);
  let match = null;
  for (const group of groups.values()) {
    const misses = [];
    const cells = compareRows(channel.topic, middle, group, enums, (w) => misses.push(w), {
      summarized: 0,
    });
    if (misses.length === 0 && cells > 0) {
      match = cells;
      break;
    }
  }
  const sorted = [...hops].sort((a, b) => a - b);
  console.log(
    `${channel.topic}: ${messages.length} messages decoded (${channel.schemaName}); the middle ` +
      (match ? `one equals the CSV recording (${match} fields)` : "one matches no CSV row") +
      `; bridge hop p50 ${percentile(sorted, 0.5).toFixed(3)} ms, p99 ${percentile(sorted, 0.99).toFixed(3)} ms`,
  );
  if (match) compared += 1;
  else fail(`${channel.topic}: the middle message equals no message of ${csvFile}`);
  if (channel.topic === latencyTopic) {
    console.log(
      `bridge hop on ${latencyTopic} (${hops.length} frames): p50 ${percentile(sorted, 0.5).toFixed(3)} ms, ` +
        `p99 ${percentile(sorted, 0.99).toFixed(3)} ms, p99.9 ${percentile(sorted, 0.999).toFixed(3)} ms, ` +
        `max ${sorted[sorted.length - 1].toFixed(3)} ms`,
    );
  }
}
if (compared === 0) fail("no channel compared");
console.log(checkLayout(JSON.parse(readFileSync(layoutFile)), advertised, fail));
if (derivedChecked !== 2) fail(`${derivedChecked} of the 2 channels in Foxglove's schemas carried messages`);
if (statuses > 0) fail(`${statuses} status messages`);
console.log(`${channels.size} channels advertised, ${compared} compared with the CSV recording`);
if (failures > 0) {
  console.log(`${failures} failures`);
  process.exit(1);
}
console.log("bridge check: ok");
