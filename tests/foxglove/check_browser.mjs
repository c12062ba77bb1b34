// A real browser negotiates the bridge's subprotocol: Debian's Chromium, headless, driven by
// playwright-core, opens browser_page.html, which connects to the bridge with the subprotocol
// foxglove.websocket.v1 (as Foxglove's web app does) and lists the server's name, the
// negotiated subprotocol and every advertised topic; the same page without the subprotocol is
// refused (the handshake fails, as the specification asks of a server).
// Usage: node check_browser.mjs ws://HOST:PORT PAGE.html TOPIC... (topics that must be listed).
// Exits 77 (skipped) when Chromium cannot start here, 1 naming the first difference.
import { chromium } from "playwright-core";

const [url, pagePath, ...topics] = process.argv.slice(2);
const subprotocol = "foxglove.websocket.v1";
let failures = 0;
const fail = (what) => {
  failures += 1;
  console.log(`FAIL: ${what}`);
};

let browser;
try {
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox"], // as root in a container: Chromium's sandbox needs user namespaces
  });
} catch (e) {
  console.log(`SKIP: Chromium does not start here: ${e.message.split("\n")[0]}`);
  process.exit(77);
}
console.log(`browser: Chromium ${browser.version()}`);
const open = async (protocol) => {
  const page = await browser.newPage();
  const query = `url=${encodeURIComponent(url)}&protocol=${encodeURIComponent(protocol)}`;
  await page.goto(`file://${pagePath}?${query}`);
  await page.waitForFunction(() => document.getElementById("state").textContent !== "connecting",
                             null, { timeout: 20000 });
  return page;
};

// With the subprotocol: open, Server Info, every expected topic advertised.
const page = await open(subprotocol);
const text = (id) => page.evaluate((i) => document.getElementById(i).textContent, id);
try {
  await page.waitForFunction(
    (n) => document.querySelectorAll("#topics li").length >= n, topics.length, { timeout: 20000 });
} catch {
  fail(`fewer than ${topics.length} topics advertised within 20 s`);
}
const listed = await page.evaluate(() =>
  [...document.querySelectorAll("#topics li")].map((li) => li.textContent));
if ((await text("state")) !== "open") fail(`state ${await text("state")}, not open`);
if ((await text("protocol")) !== subprotocol) fail(`negotiated "${await text("protocol")}"`);
if ((await text("server")) !== "navbus") fail(`server name "${await text("server")}"`);
for (const topic of topics) {
  if (!listed.some((l) => l.startsWith(`${topic} `))) fail(`${topic} is not listed`);
}
console.log(`with ${subprotocol}: ${await text("state")}, negotiated "${await text("protocol")}", ` +
            `server "${await text("server")}", ${listed.length} topics listed:`);
for (const l of listed) console.log(`  ${l}`);

// Without it: the server refuses the handshake; the browser sees an error, then code 1006.
const refused = await open("");
const refusedState = await refused.evaluate(() => document.getElementById("state").textContent);
if (refusedState === "open") fail("a connection without the subprotocol was accepted");
console.log(`without a subprotocol: ${refusedState} (refused)`);

await browser.close();
if (failures > 0) {
  console.log(`${failures} failures`);
  process.exit(1);
}
console.log("browser check: ok");
