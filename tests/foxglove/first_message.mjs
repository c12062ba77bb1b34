// Waits for a bridge to advertise TOPIC, subscribes (printing "connected", then "subscribed to
// TOPIC"), and prints the channels advertised and the first message's size. Exits 1 if TOPIC is not advertised or carries nothing within SECONDS.
// Usage: node first_message.mjs ws://HOST:PORT TOPIC SECONDS
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const [url, topic, seconds] = process.argv.slice(2);
const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const advertised = [];
const timer = setTimeout(() => {
  console.log(`advertised: ${advertised.join(", ") || "nothing"}`);
  console.log(`FAIL: no message of ${topic} within ${seconds} s`);
  process.exit(1);
}, Number(seconds) * 1000);
client.on("open", () => console.log("connected"));
client.on("advertise", (list) => {
  for (const channel of list) {
    advertised.push(channel.topic);
    if (channel.topic !== topic) continue;
    client.subscribe(channel.id);
    console.log(`subscribed to ${topic}`);
  }
});
client.on("message", ({ data }) => {
  clearTimeout(timer);
  console.log(`advertised: ${advertised.join(", ")}`);
  console.log(`${topic}: a message of ${data.byteLength} bytes`);
  client.close();
  process.exit(0);
});
