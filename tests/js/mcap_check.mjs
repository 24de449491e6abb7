// Reads MCAP files with Foxglove's own readers (@mcap/core), as Foxglove Studio and the mcap CLI
// do, and prints one JSON line per file: what the indexed reader and the streaming reader saw.
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import { open, readFile } from "node:fs/promises";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";

await zstd.isLoaded;
await lz4.isLoaded;
const decompressHandlers = {
  zstd: (buf, size) => zstd.decompress(buf, Number(size)),
  lz4: (buf, size) => lz4(buf, Number(size)),
};

for (const path of process.argv.slice(2)) {
  const out = { path };
  const fh = await open(path, "r");
  try {
    const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(fh), decompressHandlers });
    let n = 0;
    for await (const _ of reader.readMessages()) n++;
    out.indexed = { messages: n, statistics_messages: Number(reader.statistics?.messageCount ?? -1),
                    chunks: reader.chunkIndexes.length, channels: reader.channelsById.size };
  } catch (e) {
    out.indexed_error = e.message;
  }
  await fh.close();
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(await readFile(path));
  let n = 0;
  try {
    for (let rec; (rec = stream.nextRecord()); ) if (rec.type === "Message") n++;
    out.stream = { messages: n, done: stream.done() };
  } catch (e) {
    out.stream = { messages: n, error: e.message };
  }
  console.log(JSON.stringify(out));
}
