// The Foxglove layout in the repository (config/foxglove/navbus_layout.json) against what the
// bridge serves: every panel of the arrangement has its configuration and every configuration a
// place; every topic a panel names is advertised; every plotted message path resolves to a
// number in a decoded message of its channel.
// checkLayout(layout, advertised: Map topic -> decoded message or null, fail) -> description.

function leaves(node) {
  return typeof node === "string" ? [node] : [...leaves(node.first), ...leaves(node.second)];
}

/// A message path such as navbus/nav/solution.pos_sigma_ned_m[0]: its topic and its steps.
function splitPath(path) {
  const dot = path.indexOf(".");
  const topic = dot < 0 ? path : path.slice(0, dot);
  const steps = dot < 0 ? [] : path.slice(dot + 1).split(/\.|(?=\[)/).map((s) => {
    const index = /^\[(\d+)\]$/.exec(s);
    return index ? Number(index[1]) : s;
  });
  return { topic, steps };
}

function resolve(value, steps) {
  return steps.reduce((v, step) => (v === undefined || v === null ? undefined : v[step]), value);
}

export function checkLayout(layout, advertised, report) {
  let failures = 0;
  const fail = (what) => {
    failures += 1;
    report(what);
  };
  const placed = leaves(layout.layout);
  const configured = Object.keys(layout.configById);
  for (const id of placed) if (!layout.configById[id]) fail(`layout: panel ${id} has no configuration`);
  for (const id of configured) if (!placed.includes(id)) fail(`layout: panel ${id} is not placed`);
  const paths = [];
  for (const [id, config] of Object.entries(layout.configById)) {
    for (const key of ["followTopic", "topicToRender", "topicPath"]) {
      if (config[key]) paths.push({ id, path: config[key], numeric: false });
    }
    for (const p of config.paths ?? []) paths.push({ id, path: p.value, numeric: true });
  }
  let resolved = 0;
  for (const { id, path, numeric } of paths) {
    const { topic, steps } = splitPath(path);
    if (!advertised.has(topic)) {
      fail(`layout: ${id} names ${topic}, which the bridge did not advertise`);
      continue;
    }
    if (!numeric) continue;
    const message = advertised.get(topic);
    if (message === null) {
      fail(`layout: ${id} plots ${path}, but ${topic} carried no message to check it on`);
      continue;
    }
    const v = resolve(message, steps);
    if (typeof v !== "number" && typeof v !== "bigint") {
      fail(`layout: ${id} plots ${path}, which is ${JSON.stringify(v)} in a message, not a number`);
      continue;
    }
    resolved += 1;
  }
  return `layout: ${placed.length} panels, ${paths.length} topics and paths named, ` +
    `${resolved} plotted paths resolve to numbers, ${failures} problems`;
}
