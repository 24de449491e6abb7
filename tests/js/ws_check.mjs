// Connects Foxglove's own WebSocket client (@foxglove/ws-protocol) to a running cairnd, subscribes
// to every advertised channel, decodes each message with the advertised protobuf schema
// (protobufjs), and prints one JSON line of what it saw.
//   node ws_check.mjs URL SECONDS [EXTRA_CLIENTS]
// EXTRA_CLIENTS further raw connections subscribe to everything and then vanish abruptly, half
// of them in the middle of the stream, to check that the server survives them.
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";
import protobuf from "protobufjs";
import descriptor from "protobufjs/ext/descriptor/index.js";

const { FoxgloveClient } = wsProtocol;
const [url, seconds, extra = "0"] = process.argv.slice(2);
const result = { channels: {}, serverInfo: null, errors: [] };

function rootFor(channel) {
  const bytes = Buffer.from(channel.schema, "base64");
  const set = descriptor.FileDescriptorSet.decode(bytes);
  return protobuf.Root.fromDescriptor(set);
}

function timeOf(topic, m) {
  const ns = m.timeNs ?? m.time_ns;
  if (ns !== undefined && ns !== null) return BigInt(ns.toString());
  if (m.timestamp) return BigInt(m.timestamp.seconds.toString()) * 1000000000n + BigInt(m.timestamp.nanos ?? 0);
  return null;
}

// Abrupt clients: connect, subscribe, then drop the TCP connection without a close handshake.
for (let i = 0; i < Number(extra); i++) {
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  ws.on("error", () => {});
  ws.on("message", (data, isBinary) => {
    if (isBinary) return;
    const msg = JSON.parse(data.toString());
    if (msg.op === "advertise") {
      ws.send(JSON.stringify({ op: "subscribe", subscriptions: msg.channels.map((c, k) => ({ id: k, channelId: c.id })) }));
      setTimeout(() => ws.terminate(), i % 2 === 0 ? 50 : 400);
    }
  });
}

const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const subs = new Map();
client.on("serverInfo", (info) => { result.serverInfo = info.name; });
client.on("error", (e) => result.errors.push(String(e?.message ?? e)));
client.on("advertise", (channels) => {
  for (const ch of channels) {
    try {
      const type = ch.encoding === "json"
          ? { decode: (bytes) => JSON.parse(new TextDecoder().decode(bytes)) }
          : rootFor(ch).lookupType(ch.schemaName);
      const id = client.subscribe(ch.id);
      subs.set(id, { ch, type });
      result.channels[ch.topic] = { schema: ch.schemaName, count: 0, increasing: true, first: null, last: null, decodeErrors: 0 };
    } catch (e) {
      result.errors.push(`schema of ${ch.topic}: ${e.message}`);
    }
  }
});
// Width and height from a JPEG's start-of-frame segment (null when the data is no JPEG).
function jpegSize(d) {
  if (d.length < 4 || d[0] !== 0xff || d[1] !== 0xd8) return { width: null, height: null };
  for (let i = 2; i + 9 < d.length;) {
    if (d[i] !== 0xff) return { width: null, height: null };
    const marker = d[i + 1];
    const length = (d[i + 2] << 8) | d[i + 3];
    if (marker >= 0xc0 && marker <= 0xc3) return { height: (d[i + 5] << 8) | d[i + 6], width: (d[i + 7] << 8) | d[i + 8] };
    i += 2 + length;
  }
  return { width: null, height: null };
}

client.on("message", ({ subscriptionId, data }) => {
  const s = subs.get(subscriptionId);
  if (!s) return;
  const r = result.channels[s.ch.topic];
  try {
    const m = s.type.decode(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    const t = timeOf(s.ch.topic, m);
    if (t !== null && r.last !== null && t <= BigInt(r.last)) r.increasing = false;
    if (t !== null && r.first === null) r.first = t.toString();
    if (t !== null) r.last = t.toString();
    if (s.ch.topic.endsWith("/image")) r.lastImage = { width: m.width, height: m.height, bytes: m.data.length, encoding: m.encoding };
    if (s.ch.topic.endsWith("/image/compressed")) r.lastImage = { format: m.format, bytes: m.data.length, ...jpegSize(m.data) };
    if (s.ch.topic === "/graph") {
      const e = m.entities[0] ?? { spheres: [], lines: [], texts: [] };
      r.lastGraph = { entities: m.entities.length, id: e.id, frame: e.frameId ?? e.frame_id, spheres: e.spheres.length,
                      lines: e.lines.length, texts: e.texts.length };
    }
    if (s.ch.topic === "/log") (r.lines ??= []).push({ level: m.level, message: m.message, name: m.name });
    r.count++;
  } catch (e) {
    r.decodeErrors++;
  }
});
setTimeout(() => {
  client.close();
  console.log(JSON.stringify(result));
  process.exit(0);
}, Number(seconds) * 1000);
