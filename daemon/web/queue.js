// The queue: a row per job with its state, warnings, time left and the
// buttons for what can be done to it; rows are dragged to reorder the queue.

import { api, attempt, showError } from './api.js';
import { $, element } from './dom.js';
import { renderDevices } from './machines.js';
import { state } from './state.js';
import { fillJobChoices, showGuide, showSheets } from './tabs.js';
import { sheetsDone, timeLeft } from './words.js';

// What to load for a sheet, where the plan says it: ", posterboard (0.8 mm),
// 32 x 18 in (its kit: steps 181-364; once cut, steps 1-364 can be done)".
function whatToLoad(job, sheet) {
  const summary = job.summary || {};
  const kits = Array.isArray(summary.kits) ? summary.kits : [];
  const kit = kits[sheet - 1];
  return (summary.stock ? `, ${summary.stock}` : '') + (kit ? ` (its kit: ${kit})` : '');
}

// The machine and material a job is cut on and with, under its source.
function cutWith(job) {
  const summary = job.summary || {};
  if (!summary.material) return null;
  return element('div', { class: 'cut-with' }, `${summary.material} on ${summary.machine}`);
}

// A job waiting for its operator after a frame (not for a sheet to be loaded).
function framedWaiting(job) {
  return (job.waiting_for || '').includes('framed');
}

// What a waiting job waits for, in the words of its buttons.
function waitingSaid(job) {
  if (framedWaiting(job)) return `${job.waiting_for}: press “In place: cut”, or “Frame” to trace it again`;
  const sheet = job.waiting_sheet || job.sheet + 1;
  return `sheet ${sheet - 1} cut: load sheet ${sheet}${whatToLoad(job, sheet)}, then press “Next sheet loaded” `
    + '(“Frame” traces it first)';
}

function actionsOf(job) {
  const buttons = [];
  const act = (label, action, body, extra = {}) =>
    buttons.push(element('button', {
      type: 'button', 'data-action': action, ...extra,
      onclick: () => attempt(async () => {
        const arguments_ = typeof body === 'function' ? body() : body;
        if (arguments_ === null) return;
        await api('POST', `/api/jobs/${job.id}/${action}`, arguments_ || {});
        await refreshJobs();
      }),
    }, label));
  // A device that cannot cut now (offline, gone): no Start, but why. (One in
  // a fault can: the daemon starts a cut on it, and the operator has cleared it.)
  const device = state.devices.find((d) => d.name === job.device);
  const unable = device && ['offline', 'gone'].includes(device.state) ? device : null;
  // A job whose device is no longer configured, or cannot cut: moved to another.
  if (job.device_missing || (unable && ['queued', 'ready', 'interrupted', 'failed'].includes(job.state))) {
    if (job.device_missing) buttons.push(element('span', { class: 'unable' }, job.device_missing));
    const others = state.devices.filter((d) => d.name !== job.device).map((d) => d.name);
    if (others.length) {
      act('Move to…', 'move', () => {
        const answer = window.prompt(`Cut job ${job.id} on which device (${others.join(', ')})?`, others[0]);
        return answer === null ? null : { device: answer.trim() };
      });
    }
  }
  switch (job.state) {
    case 'ready':
      if (job.device_missing) {
        // (Said beside Move to…, above.)
      } else if (unable) {
        buttons.push(element('span', { class: 'unable' },
          `${unable.name} is ${unable.state}${unable.message ? `: ${unable.message}` : ''}`));
      } else if (job.framing_sheet) {
        buttons.push(element('span', { class: 'unable' }, `framing sheet ${job.framing_sheet}…`));
      } else {
        act('Start', 'start', {}, { class: 'primary' });
        act('Frame', 'frame', { sheet: 1 }, { title: 'Trace sheet 1’s box, to check where it is' });
      }
      break;
    case 'running':
      if (job.waiting_for_next) {
        act(framedWaiting(job) ? 'In place: cut' : 'Next sheet loaded', 'next', {}, { class: 'primary' });
        act('Frame', 'frame', {}, { title: `Trace sheet ${job.waiting_sheet}’s box` });
      }
      act('Pause', 'pause');
      break;
    case 'paused':
      act('Resume', 'resume', {}, { class: 'primary' });
      break;
    case 'interrupted':
    case 'failed':
      // Only a cut that was under way goes on; a plan that failed has no sheets.
      if (!job.sheets || !job.sheet) break;
      if (job.framing_sheet) {
        buttons.push(element('span', { class: 'unable' }, `framing sheet ${job.framing_sheet}…`));
        break;
      }
      if (!unable && !job.device_missing) {
        act('Frame', 'frame', { sheet: job.sheet },
          { title: `Trace sheet ${job.sheet}’s box, to check where it is` });
      }
      act('Resume from sheet…', 'resume', () => {
        const goesOn = job.stroke > 0 && job.stroke < job.strokes;
        const answer = window.prompt(goesOn
          ? `Go on from which sheet (1 to ${job.sheets})? Sheet ${job.sheet}, left where it is, is framed and goes on `
            + `from stroke ${job.stroke + 1} once you say it is in place; another sheet is cut whole, loaded fresh.`
          : `Cut again from which sheet (1 to ${job.sheets})? Load it fresh first.`,
        String(Math.max(1, job.sheet || 1)));
        return answer === null ? null : { from_sheet: Number(answer) };
      });
      break;
    default:
      break;
  }
  if (!['done', 'cancelled', 'failed'].includes(job.state)) {
    // A cancelled job cannot be taken back: asked first.
    act('Cancel', 'cancel', () => (window.confirm(`Cancel job ${job.id} (${job.source})? It cannot be taken back.`)
      ? {} : null), { class: 'danger' });
  }
  if (job.sheets) {
    buttons.push(element('button', { type: 'button', 'data-action': 'sheets', onclick: () => showSheets(job.id) }, 'Sheets'));
    buttons.push(element('button', { type: 'button', 'data-action': 'guide', onclick: () => showGuide(job.id) }, 'Guide'));
  }
  return buttons;
}

// What the plan warned of (narrow bands, glued crossings, ...), folded under the state.
function warningsOf(job) {
  const warnings = (job.summary && job.summary.warnings) || [];
  if (!warnings.length) return null;
  return element('details', { class: 'warnings' },
    element('summary', {}, `${warnings.length} warning${warnings.length === 1 ? '' : 's'} from planning`),
    element('ul', {}, ...warnings.map((text) => element('li', {}, text))));
}

export function renderJobs() {
  const body = $('jobs-body');
  body.replaceChildren();
  for (const job of state.jobs) {
    const row = element('tr', { 'data-job': job.id, draggable: 'true', 'data-state': job.state },
      element('td', {}, String(job.id)),
      element('td', {}, job.source || '', cutWith(job)),
      element('td', {}, element('span', { class: `state ${job.state}` }, job.state),
              element('span', { class: 'message' }, job.waiting_for_next ? waitingSaid(job) : job.message || ''),
              warningsOf(job)),
      element('td', {}, job.owner || ''),
      // On a shared store, the host that plans or cuts it: laser2@room-2.
      element('td', {}, (job.device || '–') + (job.host ? `@${job.host}` : '')),
      element('td', { class: 'sheets' }, sheetsDone(job)),
      element('td', { class: 'time-left' }, timeLeft(job)),
      element('td', {}, element('div', { class: 'actions' }, ...actionsOf(job))));
    row.addEventListener('dragstart', (event) => {
      event.dataTransfer.setData('text/plain', String(job.id));
      event.dataTransfer.effectAllowed = 'move';
    });
    row.addEventListener('dragover', (event) => { event.preventDefault(); row.classList.add('drag-over'); });
    row.addEventListener('dragleave', () => row.classList.remove('drag-over'));
    row.addEventListener('drop', (event) => {
      event.preventDefault();
      row.classList.remove('drag-over');
      const moved = Number(event.dataTransfer.getData('text/plain'));
      if (!moved || moved === job.id) return;
      // Dragged up, it goes before the row it is dropped on; down, after it
      // (before the next, or below the last at a lower priority).
      const from = state.jobs.findIndex((known) => known.id === moved);
      const to = state.jobs.findIndex((known) => known.id === job.id);
      const next = state.jobs[to + 1];
      const place = from > to ? { before: job.id }
        : next ? (next.id === moved ? null : { before: next.id }) : { priority: (job.priority || 0) - 1 };
      if (!place) return;
      attempt(async () => {
        await api('POST', `/api/jobs/${moved}/move`, place);
        await refreshJobs();
      });
    });
    body.append(row);
  }
  $('jobs-empty').hidden = state.jobs.length > 0;
  fillJobChoices();
  renderDevices();  // a device's card says when its job waits for the next sheet
}

export async function refreshJobs() {
  const answer = await api('GET', '/api/jobs');
  state.jobs = answer.jobs || [];
  renderJobs();
}

// Job transitions come by the event stream; the queue is read again at
// most once a second however many come.
let jobsTimer = null;
let jobsRead = 0;
export function jobsChanged() {
  if (jobsTimer) return;
  const wait = Math.max(0, 1000 - (Date.now() - jobsRead));
  jobsTimer = setTimeout(() => {
    jobsTimer = null;
    jobsRead = Date.now();
    refreshJobs().catch((failure) => showError(failure.message));
  }, wait);
}
