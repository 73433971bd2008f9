// cadgen studio: the design's parameters as plain JSON (what tomllib gives for the file), read
// and written by dotted paths ("planter.L2", "cam.duckbill.blade_length").

export function clone(value) {
  return value === undefined ? undefined : JSON.parse(JSON.stringify(value));
}

export function getPath(params, path) {
  let node = params;
  for (const key of path.split(".")) {
    if (node === null || typeof node !== "object" || !(key in node)) return undefined;
    node = node[key];
  }
  return node;
}

/** Sets (or with `undefined`, removes: the schema default then applies) the value at `path`. */
export function setPath(params, path, value) {
  const keys = path.split(".");
  let node = params;
  for (const key of keys.slice(0, -1)) {
    if (node[key] === null || typeof node[key] !== "object" || Array.isArray(node[key])) {
      if (value === undefined) return;
      node[key] = {};
    }
    node = node[key];
  }
  const last = keys[keys.length - 1];
  if (value === undefined) delete node[last];
  else node[last] = value;
}

export function sameJson(a, b) {
  return JSON.stringify(a) === JSON.stringify(b);
}
