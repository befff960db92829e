// fieldtex studio: the page helpers both modes share (element lookup, the status
// line, turning an HTTP error answer into a thrown Error with the server's text, and
// JSON POSTs).

export const $ = (id) => document.getElementById(id);

export function status(text, error = false) {
  $('status').textContent = text;
  $('status').className = error ? 'error' : '';
}

export async function check(resp) {
  if (resp.ok) return resp;
  let msg = `${resp.status}`;
  try { msg += ': ' + (await resp.json()).error; } catch (_) { /* not JSON */ }
  throw new Error(msg);
}

/** POSTs `body` as JSON to `path`; the checked response. */
export async function post(path, body) {
  return check(await fetch(path, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) }));
}
