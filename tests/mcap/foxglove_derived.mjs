// The channels in Foxglove's own schemas that navbus derives (navbus/foxglove/location_fix,
// navbus/foxglove/log), checked against what Foxglove publishes and against the CSV recording
// of the same run:
//   - every message is valid under the JSON Schema its channel carries and under Foxglove's
//     published one (@foxglove/schemas, validated by Ajv);
//   - every LocationFix equals a deterministic solution of the CSV recording, found by its time
//     of validity: degrees from radians, the E N U covariance from the N E D sigmas (UNKNOWN and
//     zero where covariance_valid is 0), heading and E N U velocity, bit for bit;
//   - every Log line names a decision, command or outcome of the CSV recording.
// With `complete`, the other way too: every CSV solution has its LocationFix and every
// decision, command and outcome its Log line (a recorder that took everything).
import { readFileSync, existsSync } from "node:fs";
import Ajv from "ajv";
import foxgloveSchemas from "@foxglove/schemas/jsonschema.js"; // CommonJS: the default export
import { parse as parseCsv } from "csv-parse/sync";

const ajv = new Ajv({ strict: false, allErrors: true });
const kGpsEpochAfterUnixNs = 315964800n * 1000000000n;
const kGpsAheadOfUtcNs = 18n * 1000000000n;

export const isDerivedChannel = (encoding) => encoding === "json";

function csvRows(csvDir, topic) {
  const file = `${csvDir}/${topic.replaceAll("/", "_")}.csv`;
  return existsSync(file) ? parseCsv(readFileSync(file), { columns: true, skip_empty_lines: true }) : [];
}

function validators(schemaName, schemaText, fail) {
  const published = foxgloveSchemas[schemaName.replace(/^foxglove\./, "")];
  if (!published) {
    fail(`${schemaName}: not one of Foxglove's published schemas`);
    return [];
  }
  try {
    return [
      ["the channel's schema", ajv.compile(JSON.parse(schemaText))],
      ["Foxglove's published schema", ajv.compile(published)],
    ];
  } catch (e) {
    fail(`${schemaName}: the channel's schema does not compile: ${e.message}`);
    return [];
  }
}

function locationFixMismatch(fix, row) {
  const rad = Math.PI / 180;
  const s = [0, 1, 2].map((i) => Number(row[`pos_sigma_ned_m[${i}]`]));
  const v = [0, 1, 2].map((i) => Number(row[`vel_ned_mps[${i}]`]));
  const valid = row.covariance_valid === "1";
  const expected = {
    frame_id: `vehicle_${row.vehicle_id}`,
    latitude: Number(row.latitude_rad) / rad,
    longitude: Number(row.longitude_rad) / rad,
    altitude: Number(row.height_m),
    position_covariance: valid ? [s[1] * s[1], 0, 0, 0, s[0] * s[0], 0, 0, 0, s[2] * s[2]] : Array(9).fill(0),
    position_covariance_type: valid ? 2 : 0,
    heading: Number(row.yaw_rad),
    velocity: { x: v[1], y: v[0], z: -v[2] },
  };
  for (const [k, want] of Object.entries(expected)) {
    if (JSON.stringify(fix[k]) !== JSON.stringify(want)) {
      return `${k} ${JSON.stringify(fix[k])}, the solution gives ${JSON.stringify(want)}`;
    }
  }
  return null;
}

function checkLocationFixes(fixes, csvDir, complete, fail) {
  const solutions = new Map();
  for (const row of csvRows(csvDir, "navbus/nav/solution")) {
    if (row.output !== "DETERMINISTIC") continue;
    const k = `${row.vehicle_id}/${row.time_gps_ns}`;
    if (!solutions.has(k)) solutions.set(k, []);
    solutions.get(k).push(row);
  }
  let equal = 0;
  const seen = new Set();
  for (const fix of fixes) {
    const unixNs = BigInt(fix.timestamp.sec) * 1000000000n + BigInt(fix.timestamp.nsec);
    const gpsNs = unixNs - kGpsEpochAfterUnixNs + kGpsAheadOfUtcNs;
    const k = `${fix.frame_id.replace(/^vehicle_/, "")}/${gpsNs}`;
    const rows = solutions.get(k) ?? [];
    const misses = rows.map((row) => locationFixMismatch(fix, row));
    if (rows.length === 0) fail(`LocationFix at ${k}: no solution of that vehicle and time`);
    else if (!misses.includes(null)) fail(`LocationFix at ${k}: ${misses[0]}`);
    else {
      equal += 1;
      seen.add(k);
    }
  }
  if (complete && seen.size !== solutions.size) {
    fail(`${solutions.size - seen.size} of ${solutions.size} solutions have no LocationFix`);
  }
  return `${equal} of ${fixes.length} LocationFix messages equal a solution (${solutions.size} deterministic solutions recorded)`;
}

function checkLogs(logs, csvDir, complete, fail) {
  const expected = new Set();
  for (const d of csvRows(csvDir, "navbus/fault/decision")) expected.add(`decision ${d.decision_id} at`);
  for (const c of csvRows(csvDir, "navbus/filter/command")) expected.add(`command ${c.command_id} to vehicle`);
  for (const o of csvRows(csvDir, "navbus/nav/command_outcome")) {
    expected.add(`command ${o.command_id} of ${o.issuer}:`);
    // A command the filter answered existed, also where a recorder that joined late missed it
    // (an operator's tool writes as soon as its first reader matched).
    if (!complete) expected.add(`command ${o.command_id} to vehicle`);
  }
  const found = new Set();
  for (const log of logs) {
    const k = [...expected].find((e) => log.message.startsWith(e));
    if (k === undefined) fail(`Log line "${log.message}" names nothing of the CSV recording`);
    else found.add(k);
  }
  if (complete && found.size !== expected.size) {
    const missing = [...expected].filter((e) => !found.has(e));
    fail(`${missing.length} decisions, commands or outcomes have no Log line, e.g. "${missing[0]}"`);
  }
  const levels = logs.reduce((a, l) => ({ ...a, [l.level]: (a[l.level] ?? 0) + 1 }), {});
  return `${logs.length} Log lines (levels ${JSON.stringify(levels)}), ${found.size} of ${expected.size} decisions, commands and outcomes`;
}

/// Checks one derived channel's messages (Uint8Array each); returns a one-line description.
export function checkDerived({ topic, schemaName, schemaText, messages, csvDir, complete, fail }) {
  const checks = validators(schemaName, schemaText, fail);
  const decoded = [];
  for (const bytes of messages) {
    let m;
    try {
      m = JSON.parse(new TextDecoder().decode(bytes));
    } catch (e) {
      fail(`${topic}: a message is not JSON: ${e.message}`);
      continue;
    }
    for (const [which, validate] of checks) {
      if (!validate(m)) fail(`${topic}: invalid under ${which}: ${ajv.errorsText(validate.errors)}`);
    }
    decoded.push(m);
  }
  const what =
    schemaName === "foxglove.LocationFix"
      ? checkLocationFixes(decoded, csvDir, complete, fail)
      : checkLogs(decoded, csvDir, complete, fail);
  return `${topic}: ${schemaName} (jsonschema), ${decoded.length} messages valid under Foxglove's published schema; ${what}`;
}
