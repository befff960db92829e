// fieldtex studio, mesh modes: the jobs panel, one row per job (state, progress bar and
// cancel button while it runs, its error, links to its files), kept current from the
// server's event stream.
import { $, status, post } from './page.js';

function jobRow(job) {
  let row = document.getElementById(`job-${job.id}`);
  if (!row) {
    row = document.createElement('div');
    row.id = `job-${job.id}`;
    row.className = 'job';
    $('jobs').prepend(row);
  }
  return row;
}
/** Draws (or redraws) the row of `job`; its GLB files get a view button calling
 *  `handlers.onView(ref)`. */
export function renderJob(job, handlers) {
  window.studioMesh.jobs[job.id] = job;
  const row = jobRow(job);
  row.textContent = '';
  const head = document.createElement('div');
  head.textContent = `${job.kind} ${job.id}: ${job.state}${job.stage ? ' — ' + job.stage : ''} (${job.seconds.toFixed(1)} s)`;
  row.appendChild(head);
  if (job.state === 'running' || job.state === 'queued') {
    const bar = document.createElement('progress');
    bar.max = Math.max(1, job.total); bar.value = job.done;
    const cancel = document.createElement('button');
    cancel.textContent = 'Cancel';
    cancel.onclick = () => post(`/api/jobs/cancel?id=${job.id}`, {}).catch((e) => status(e.message, true));
    row.append(bar, cancel);
  }
  if (job.error) {
    const e = document.createElement('div');
    e.className = 'error';
    e.textContent = job.error;
    row.appendChild(e);
  }
  for (const f of job.files || []) {
    const a = document.createElement('a');
    const rel = `${job.dir}/${f}`;
    a.href = `/api/file?path=${encodeURIComponent(rel)}`;
    a.textContent = f; a.download = f;
    row.append(a, ' ');
    if (f.endsWith('.glb')) {
      const v = document.createElement('button');
      v.textContent = 'view';
      v.onclick = () => handlers.onView({ root: 'workspace', path: rel });
      row.append(v, ' ');
    }
  }
}
/** Shows `job` and follows its event stream; `handlers.onEnd(job)` runs once it has
 *  finished (done, failed or cancelled). */
export function watchJob(job, handlers) {
  renderJob(job, handlers);
  const es = new EventSource(`/api/jobs/events?id=${encodeURIComponent(job.id)}`);
  es.onmessage = (ev) => {
    const j = JSON.parse(ev.data);
    renderJob(j, handlers);
    if (['done', 'failed', 'cancelled'].includes(j.state)) {
      es.close();
      handlers.onEnd(j);
    }
  };
  es.addEventListener('end', () => es.close());
  es.onerror = () => es.close();
}
