// N Foxglove clients (@foxglove/ws-protocol) on one bridge, each subscribed to every channel as
// it is advertised, counting what it receives, until STOP_FILE exists.
// Usage: node load_clients.mjs ws://HOST:PORT N STOP_FILE
import { existsSync } from "node:fs";
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const [url, n, stopFile] = process.argv.slice(2);
const clients = [];
for (let i = 0; i < Number(n); i += 1) {
  const c = { frames: 0, bytes: 0, channels: new Set(), statuses: 0, open: false };
  c.client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  c.client.on("open", () => (c.open = true));
  c.client.on("advertise", (list) => {
    for (const channel of list) {
      if (c.channels.has(channel.id)) continue;
      c.channels.add(channel.id);
      c.client.subscribe(channel.id);
    }
  });
  c.client.on("message", ({ data }) => {
    c.frames += 1;
    c.bytes += data.byteLength;
  });
  c.client.on("status", () => (c.statuses += 1));
  c.client.on("error", (e) => console.log(`client ${i + 1}: ${e}`));
  clients.push(c);
}
while (!clients.every((c) => c.open)) await new Promise((r) => setTimeout(r, 50));
console.log(`connected: ${clients.length} clients`);
while (!existsSync(stopFile)) await new Promise((r) => setTimeout(r, 100));
clients.forEach((c, i) => {
  console.log(`client ${i + 1}: ${c.channels.size} channels subscribed, ${c.frames} frames, ` +
              `${(c.bytes / 1e6).toFixed(1)} MB, ${c.statuses} statuses`);
  c.client.close();
});
const bad = clients.filter((c) => c.frames === 0 || c.statuses > 0).length;
process.exit(bad === 0 ? 0 : 1);
