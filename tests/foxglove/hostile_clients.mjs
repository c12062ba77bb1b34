// Clients that misbehave against `navbus foxglove`, each checked for the answer the bridge owes
// it (run beside check_bridge.mjs, which must see none of it):
//   no subprotocol -> HTTP 400; malformed JSON, an unknown op, a subscription to an unknown
//   channel, a second subscription to one channel, an unknown unsubscription and a binary message
//   -> a Status of level 2 naming the problem, the connection kept; an oversized message -> the
//   connection closed with 1009 (message too big); a client that subscribes to everything and
//   stops reading for 10 s, and one that sends half a frame and disconnects.
// Usage: node hostile_clients.mjs ws://HOST:PORT. Exits 1 naming what went wrong.
import net from "node:net";
import WebSocket from "ws";

const url = process.argv[2];
const subprotocol = "foxglove.websocket.v1";
let failures = 0;
const fail = (what) => {
  failures += 1;
  console.log(`FAIL: ${what}`);
};
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/// Opens a client and resolves once its Server Info and first Advertise came.
function open(protocols = [subprotocol]) {
  return new Promise((resolve, reject) => {
    const ws = new WebSocket(url, protocols);
    const texts = [];
    const channels = [];
    ws.on("message", (data, binary) => {
      if (binary) return;
      const m = JSON.parse(data.toString());
      texts.push(m);
      if (m.op === "advertise") channels.push(...m.channels);
      if (m.op === "advertise" && texts.some((t) => t.op === "serverInfo")) resolve({ ws, texts, channels });
    });
    ws.on("unexpected-response", (req, res) => reject(new Error(`HTTP ${res.statusCode}`)));
    ws.on("error", reject);
  });
}

/// Sends `payload` and waits for a Status; checks its level and that it mentions `expect`.
async function expectStatus(client, payload, expect, what) {
  const before = client.texts.length;
  client.ws.send(payload);
  for (let waited = 0; waited < 3000; waited += 20) {
    const status = client.texts.slice(before).find((t) => t.op === "status");
    if (status) {
      if (status.level !== 2 || !status.message.includes(expect)) {
        fail(`${what}: status ${JSON.stringify(status)}, expected level 2 with '${expect}'`);
      } else {
        console.log(`${what}: error status "${status.message}"`);
      }
      return;
    }
    await sleep(20);
  }
  fail(`${what}: no status within 3 s`);
}

// No subprotocol: the upgrade is refused.
try {
  const c = await open([]);
  c.ws.close();
  fail("a client without the subprotocol was accepted");
} catch (e) {
  if (String(e.message).includes("HTTP 400")) console.log("no subprotocol: HTTP 400");
  else fail(`no subprotocol: ${e.message}`);
}

const c = await open();
await expectStatus(c, "{not json", "not JSON", "malformed JSON");
await expectStatus(c, JSON.stringify({ op: "fly" }), "not supported", "unknown op");
await expectStatus(c, JSON.stringify([1, 2]), "not a JSON object", "an array");
await expectStatus(
  c,
  JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 987654 }] }),
  "not advertised",
  "unknown channel",
);
await expectStatus(
  c,
  JSON.stringify({ op: "subscribe", subscriptions: [{ id: -1, channelId: 0 }] }),
  "not an unsigned 32-bit integer",
  "negative id",
);
await expectStatus(c, JSON.stringify({ op: "unsubscribe", subscriptionIds: [77] }), "no subscription", "unknown unsubscription");
await expectStatus(c, Buffer.from([1, 0, 0, 0, 0, 42]), "binary messages are not taken", "binary message");
if (c.channels.length > 0) {
  const id = c.channels[0].id;
  c.ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 5, channelId: id }] }));
  await expectStatus(
    c,
    JSON.stringify({ op: "subscribe", subscriptions: [{ id: 6, channelId: id }] }),
    "already subscribed",
    "second subscription to a channel",
  );
}
if (c.ws.readyState !== WebSocket.OPEN) fail("the connection did not survive its refused requests");
c.ws.close();

// Oversized: closed with 1009.
{
  const big = await open();
  const code = await new Promise((resolve) => {
    big.ws.on("close", (code) => resolve(code));
    big.ws.send("x".repeat(200 * 1024));
  });
  if (code !== 1009) fail(`oversized message: closed with ${code}, expected 1009`);
  else console.log("oversized message (200 KiB): closed with 1009 (message too big)");
}

// Half a frame, then gone.
await new Promise((resolve) => {
  const { hostname, port } = new URL(url);
  const socket = net.connect(Number(port), hostname, () => {
    socket.write(
      "GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n" +
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n" +
        `Sec-WebSocket-Protocol: ${subprotocol}\r\n\r\n`,
    );
    setTimeout(() => {
      socket.write(Buffer.from([0x81, 0xfe, 0x01])); // a masked text frame's header, cut
      socket.destroy();
      console.log("half a frame, then disconnected");
      resolve();
    }, 300);
  });
  socket.on("error", () => resolve());
});

// Subscribes to everything, then does not read for 8 s.
{
  const slow = await open();
  await sleep(2000); // the simulator's channels advertised by now
  const subs = slow.channels.map((ch, i) => ({ id: i, channelId: ch.id }));
  slow.ws.send(JSON.stringify({ op: "subscribe", subscriptions: subs }));
  await sleep(200);
  slow.ws._socket.pause();
  console.log(`stalled reader: subscribed to ${subs.length} channels, not reading for 10 s`);
  await sleep(10000);
  slow.ws.terminate();
}

if (failures > 0) {
  console.log(`${failures} failures`);
  process.exit(1);
}
console.log("hostile clients: ok");
process.exit(0);
