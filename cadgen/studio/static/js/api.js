// cadgen studio: the page's only way to the server. Every /api and /files request carries the
// token from the page's own URL (?token=, printed by `cadgen studio`): as a header where fetch
// can set one, in the query where it cannot (EventSource, links, the GLB loader).

const token = new URLSearchParams(window.location.search).get("token") || "";

/** An API error: the server's one-sentence message, the field it names, every problem. */
export class ApiError extends Error {
  constructor(status, body) {
    super((body && body.error) || `HTTP ${status}`);
    this.status = status;
    this.field = body && body.field;
    this.problems = (body && body.problems) || [];
    this.body = body || {};
  }
}

export function hasToken() {
  return token !== "";
}

/** `url` with the token in its query: for EventSource, <a href> and loaders. */
export function withToken(url) {
  const separator = url.includes("?") ? "&" : "?";
  return `${url}${separator}token=${encodeURIComponent(token)}`;
}

async function request(method, url, body, signal) {
  const init = {method, signal, headers: {"X-Cadgen-Token": token}};
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  const response = await fetch(url, init);
  let payload = null;
  try {
    payload = await response.json();
  } catch (error) {
    payload = {error: `the server answered ${response.status} without JSON`};
  }
  if (!response.ok) throw new ApiError(response.status, payload);
  return payload;
}

export const getJson = (url, signal) => request("GET", url, undefined, signal);
export const postJson = (url, body, signal) => request("POST", url, body, signal);
