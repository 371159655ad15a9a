// The page's side of the HTTP API (docs/server.md): a fetch wrapper whose failures reach the
// message box, the status poll with its progress bar, and the count of work under way.
const $ = (id) => document.getElementById(id);

/// Requests and refreshes under way; the tests wait until it is 0.
export const work = { tasks: 0 };

/// Runs an asynchronous piece of work, counted in work.tasks.
export async function task(job) {
  work.tasks += 1;
  try { return await job(); } finally { work.tasks -= 1; }
}

/// Shows `text` at the bottom of the view. kind 'error' stays until replaced or cleared; 'hint'
/// stays until replaced; 'info' hides itself after 2.5 s. An info or hint never replaces an
/// error that is shown: message('') clears it first (a new user action does so).
export function message(text, kind = 'error') {
  const box = $('message');
  if (text && kind !== 'error' && !box.hidden && box.className === 'error') return;
  box.textContent = text;
  box.className = kind;
  box.hidden = !text;
  if (kind === 'info' && text) setTimeout(() => { if (box.textContent === text) box.hidden = true; }, 2500);
}
export const shownError = () => (!$('message').hidden && $('message').className === 'error'
  ? $('message').textContent : '');

/// An answer other than 2xx: its HTTP status and the server's message.
export class ApiError extends Error {
  constructor(status, text) { super(text); this.status = status; }
}

/// fetch('api/' + path); a refusal shows the server's message (its JSON "error") and throws
/// ApiError; a server that does not answer throws with a message that says so.
export async function api(path, options = {}) {
  let response;
  try {
    response = await fetch('api/' + path, options);
  } catch (e) {
    const text = `the server does not answer (${e.message}); is remora serve still running?`;
    message(text);
    throw new ApiError(0, text);
  }
  if (!response.ok) {
    let text = `${response.status} ${response.statusText}`;
    try { text = (await response.json()).error || text; } catch (e) { /* not JSON */ }
    message(text);
    throw new ApiError(response.status, text);
  }
  return response;
}
export const json = async (path, options) => (await api(path, options)).json();
/// A response's body as one ArrayBuffer, read from its stream (into a buffer of its
/// Content-Length when it has one): chromium hands over a binary answer sooner this way than
/// through response.arrayBuffer() (docs/server.md, "Design notes on the drag's frames").
export async function bodyBytes(response) {
  if (!response.body) return new ArrayBuffer(0); // 204, or a HEAD request
  const reader = response.body.getReader();
  const length = parseInt(response.headers.get('Content-Length') ?? '', 10);
  let out = new Uint8Array(Number.isFinite(length) && length >= 0 ? length : 0), size = 0;
  for (;;) {
    const { value, done } = await reader.read();
    if (done) break;
    if (size + value.byteLength > out.length) { // no (or a wrong) Content-Length: grow
      const grown = new Uint8Array(Math.max(2 * out.length, size + value.byteLength));
      grown.set(out.subarray(0, size));
      out = grown;
    }
    out.set(value, size);
    size += value.byteLength;
  }
  return size === out.length ? out.buffer : out.buffer.slice(0, size);
}
export const binary = async (path, Type) => new Type(await bodyBytes(await api(path)));
export const post = (path, body) => api(path, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                                body: JSON.stringify(body ?? {}) });

/// Vertex ids (increasing; an array or a typed array) as POST /api/region takes them: {ranges: [[first, count], ...]}, runs
/// of consecutive ids, when there are at most half as many runs as ids (a scan's or a subdivided
/// mesh's vertex order keeps neighbours together, so a support has far fewer runs than ids),
/// else the ids themselves. A smaller body travels faster: chromium takes far longer for a
/// request body of 256 KB than of 128 KB (docs/server.md, "What the page downloads").
export function compactIds(ids) {
  const ranges = [];
  for (let i = 0; i < ids.length;) {
    let j = i + 1;
    while (j < ids.length && ids[j] === ids[j - 1] + 1) ++j;
    ranges.push([ids[i], j - i]);
    i = j;
  }
  return 2 * ranges.length <= ids.length ? { ranges } : Array.from(ids);
}

/// Polls the status until the server is not busy; calls onBusy(status) on every busy answer and
/// returns the first other status. A job's error (status.error) is shown.
export async function waitUntilReady(onBusy) {
  for (;;) {
    // A long poll: the server answers as soon as the job ends, else after 200 ms with its progress.
    const s = await json('status?wait=200');
    if (s.state !== 'busy') {
      if (s.error) message(s.error);
      return s;
    }
    onBusy(s);
  }
}
