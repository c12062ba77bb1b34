// Decoded navbus messages compared with navbus's CSV recording of the same run, field by field
// (shared by check_mcap.mjs and the Foxglove bridge's check_bridge.mjs).
// CSV columns (records/formatters.hpp): "name", "name[i]" for arrays, "seq.field" (a row per
// element) for the sequence of structs, "seq.inner.field" (a row per element of each element's
// own sequence of structs, the element's cells repeated: a block of GNSS epochs, a row per
// satellite), "a;b;c" for a sequence of numbers, enums by name,
// booleans as 0/1, a nested struct's fields as "<struct>_<field>". Fields the CSV summarizes as
// text (diagnostics, decision candidates) are not compared.

// Every constant of a schema (OMG IDL enumerators and consts; ROS 2 msg constants, which carry
// the IDL enumerators): [name, value] pairs.
export function constants(definitions) {
  const all = [];
  for (const d of definitions) {
    for (const c of d.definitions ?? []) if (c.isConstant) all.push([c.name, c.value]);
  }
  return all;
}

// Compares one decoded message with its CSV rows; returns the number of cells compared. Calls
// fail(text) for each difference and counts the struct cells left uncompared in
// counts.summarized.
export function compareRows(topic, value, rows, enums, fail, counts) {
  let cells = 0;
  const columns = Object.keys(rows[0]).filter(
    (c) => c !== "source_timestamp_ns" && c !== "reception_timestamp_ns",
  );
  const at = rowElements(value, columns);
  rows.forEach((row, r) => {
    for (const column of columns) {
      const m =
        /^([a-z_0-9]+)(?:\[(\d+)\])?(?:\.([a-z_0-9]+)(?:\[(\d+)\])?)?(?:\.([a-z_0-9]+)(?:\[(\d+)\])?)?$/.exec(
          column,
        );
      if (!m) {
        fail(`${topic}: column '${column}' is not a field path`);
        continue;
      }
      let v = field(value, m[1]);
      const [element, inner] = at ? (at[r] ?? [r, -1]) : [r, -1];
      if (m[5] !== undefined) {
        if (row[column] === "" && inner < 0) continue; // an element without inner elements
        v = v?.[element]?.[m[3]]?.[inner]?.[m[5]];
        if (m[6] !== undefined) v = v?.[Number(m[6])];
      } else if (m[3] !== undefined) {
        if (row[column] === "" && (v?.length ?? 0) === 0) continue; // no element: empty cells
        v = v?.[element]?.[m[3]];
        if (m[4] !== undefined) v = v?.[Number(m[4])];
      } else if (m[2] !== undefined) {
        v = v?.[Number(m[2])];
      } else if (r > 0) {
        continue; // a message's own fields are repeated on each of its rows
      }
      if (v === undefined) {
        fail(`${topic}: column '${column}' has no decoded field`);
        continue;
      }
      // A struct, or a sequence of structs, that the CSV summarizes as one text cell: not
      // compared, and not counted as equal.
      const structs = Array.isArray(v) && v.length > 0 && typeof v[0] === "object";
      if (structs || (typeof v === "object" && !ArrayBuffer.isView(v) && !Array.isArray(v))) {
        counts.summarized += 1;
        continue;
      }
      if (!equalCell(row[column], v, enums)) {
        fail(`${topic}: '${column}' CSV '${row[column]}' decoded '${format(v)}'`);
        continue;
      }
      cells += 1;
    }
  });
  return cells;
}

// With a sequence inside the sequence's elements (columns "seq.inner.field"): for each CSV row,
// [element, inner element] (inner -1 for an element whose own sequence is empty: one row).
// Otherwise null: row r is element r.
function rowElements(value, columns) {
  const nested = columns.map((c) => /^([a-z_0-9]+)\.([a-z_0-9]+)\.[a-z_0-9]+/.exec(c)).find((m) => m);
  if (!nested) return null;
  const at = [];
  (field(value, nested[1]) ?? []).forEach((e, i) => {
    const n = e?.[nested[2]]?.length ?? 0;
    if (n === 0) at.push([i, -1]);
    for (let k = 0; k < n; k += 1) at.push([i, k]);
  });
  return at;
}

// A message's field by its CSV name; a nested struct's fields are named "<struct>_<field>"
// (FaultDecision.dither.peak_frequency_hz as dither_peak_frequency_hz).
function field(value, name) {
  if (name in value) return value[name];
  for (let i = name.indexOf("_"); i > 0; i = name.indexOf("_", i + 1)) {
    const outer = value[name.slice(0, i)];
    if (outer && typeof outer === "object" && !ArrayBuffer.isView(outer) && !Array.isArray(outer)) {
      const inner = field(outer, name.slice(i + 1));
      if (inner !== undefined) return inner;
    }
  }
  return undefined;
}

function format(v) {
  return ArrayBuffer.isView(v) || Array.isArray(v) ? Array.from(v).join(";") : String(v);
}

function equalCell(cell, v, enums) {
  if (typeof v === "bigint") return /^-?\d+$/.test(cell) && BigInt(cell) === v;
  if (typeof v === "boolean") return cell === (v ? "1" : "0");
  if (typeof v === "string") return cell === v;
  if (ArrayBuffer.isView(v) || Array.isArray(v)) {
    // A sequence of numbers as one cell.
    const parts = cell === "" ? [] : cell.split(";");
    return parts.length === v.length && parts.every((p, i) => Number(p) === Number(v[i]));
  }
  if (typeof v === "number") {
    // An enumerator by name: the CSV writes it without the enum's prefix (MODE_INERTIAL_ONLY
    // as INERTIAL_ONLY, records/message_fields.hpp's enumName).
    if (/^[A-Za-z][A-Za-z0-9_]*$/.test(cell)) {
      const upper = cell.toUpperCase();
      return enums.some(
        ([name, value]) => (name === upper || name.endsWith(`_${upper}`)) && value === v,
      );
    }
    return Number(cell) === v;
  }
  return false;
}
