// GLB in and out for the tests that spoil a file on purpose: its JSON and binary chunk.
import { readFileSync, writeFileSync } from 'node:fs';

export function readGlb(path) {
  const b = readFileSync(path);
  const jsonLength = b.readUInt32LE(12);
  const json = JSON.parse(b.subarray(20, 20 + jsonLength).toString('utf8'));
  const at = 20 + jsonLength;
  const bin = at < b.length ? b.subarray(at + 8, at + 8 + b.readUInt32LE(at)) : Buffer.alloc(0);
  return { json, bin };
}

export function writeGlb(path, { json, bin }) {
  let text = Buffer.from(JSON.stringify(json), 'utf8');
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const body = Buffer.concat([bin, Buffer.alloc((4 - (bin.length % 4)) % 4)]);
  const header = Buffer.alloc(12);
  header.writeUInt32LE(0x46546c67, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + text.length + 8 + body.length, 8);
  const chunk = (length, type) => { const c = Buffer.alloc(8); c.writeUInt32LE(length, 0); c.writeUInt32LE(type, 4); return c; };
  writeFileSync(path, Buffer.concat([header, chunk(text.length, 0x4e4f534a), text, chunk(body.length, 0x004e4942), body]));
}
