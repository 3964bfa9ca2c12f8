// Open every channel of an MCAP log the way Foxglove does, with the libraries Foxglove uses:
// @mcap/core reads the records, @foxglove/rosmsg parses each ros2msg schema and
// @foxglove/rosmsg2-serialization decodes every CDR message.
//
// Foxglove refuses a channel whose ros2msg schema is empty unless the schema is std_msgs/Empty
// (its parseChannel keeps a list of the schema names known to be empty); that rule is applied
// here too.
//
// Usage: node check_log.mjs LOG.mcap OUT.json
// Writes {topic: {schema, count, messages: [...]}} (decoded messages as JSON: typed arrays as
// lists, bigints as numbers, NaN and infinities as strings) and exits 0; exits 1 with one line
// per refused channel or undecodable message on stderr.
import { readFileSync, writeFileSync } from "node:fs";

import { McapStreamReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";

const KNOWN_EMPTY_SCHEMA_NAMES = new Set(["std_msgs/Empty", "std_msgs/msg/Empty"]);

function jsonable(value) {
  if (typeof value === "bigint") return Number(value);
  if (typeof value === "number" && !Number.isFinite(value)) return String(value).toLowerCase();
  if (ArrayBuffer.isView(value)) return Array.from(value, jsonable);
  if (Array.isArray(value)) return value.map(jsonable);
  if (value !== null && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, jsonable(v)]));
  }
  return value;
}

const [logPath, outPath] = process.argv.slice(2);
if (!logPath || !outPath) {
  console.error("usage: node check_log.mjs LOG.mcap OUT.json");
  process.exit(2);
}
const reader = new McapStreamReader({ validateCrcs: true });
reader.append(new Uint8Array(readFileSync(logPath)));
const schemas = new Map();
const channels = new Map();
const result = {};
const problems = [];
const decoder = new TextDecoder();
// The logs are written without compression; a compressed chunk is reported, not decoded.
const records = function* () {
  try {
    for (let record; (record = reader.nextRecord()); ) yield record;
  } catch (error) {
    problems.push(`the log cannot be read further: ${error.message}`);
  }
};
for (const record of records()) {
  if (record.type === "Schema") {
    schemas.set(record.id, record);
  } else if (record.type === "Channel") {
    if (channels.has(record.id)) continue; // the summary section repeats the channels
    const schema = schemas.get(record.schemaId);
    const entry = { topic: record.topic, schema: schema?.name ?? "", reader: undefined };
    channels.set(record.id, entry);
    result[record.topic] = { schema: entry.schema, count: 0, messages: [] };
    try {
      if (!schema) throw new Error("no schema");
      if (record.messageEncoding !== "cdr") throw new Error(`encoding ${record.messageEncoding}`);
      if (schema.encoding !== "ros2msg") throw new Error(`schema encoding ${schema.encoding}`);
      const text = decoder.decode(schema.data);
      if (text.trim().length === 0 && !KNOWN_EMPTY_SCHEMA_NAMES.has(schema.name)) {
        throw new Error(`empty schema for ${schema.name}`);
      }
      entry.reader = new MessageReader(parse(text, { ros2: true }));
    } catch (error) {
      problems.push(`${record.topic}: channel refused: ${error.message}`);
    }
  } else if (record.type === "Message") {
    const entry = channels.get(record.channelId);
    if (!entry?.reader) continue;
    try {
      const message = entry.reader.readMessage(record.data);
      result[entry.topic].count += 1;
      result[entry.topic].messages.push(jsonable(message));
    } catch (error) {
      problems.push(`${entry.topic}: a message does not decode: ${error.message}`);
    }
  }
}
writeFileSync(outPath, JSON.stringify(result));
for (const problem of problems) console.error(problem);
process.exit(problems.length ? 1 : 0);
