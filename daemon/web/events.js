// The daemon's event stream: jobs, progress and devices as they change,
// and the connection's state; opened again when the daemon is back.

import { api, session, showError, SignedOut } from './api.js';
import { $ } from './dom.js';
import { refreshDevices, renderDevices } from './machines.js';
import { jobsChanged, refreshJobs, renderJobs } from './queue.js';
import { highlightStroke, openSheets } from './sheets.js';
import { state } from './state.js';
import { realTimeScale, sheetsDone, timeLeft } from './words.js';

export function listen() {
  const events = new EventSource(`/api/events?session=${encodeURIComponent(session())}`);
  const status = $('connection');
  events.onopen = () => {
    status.textContent = 'live';
    status.className = 'connection live';
    // What happened while the stream was down.
    refreshJobs().catch((failure) => showError(failure.message));
    refreshDevices().catch((failure) => showError(failure.message));
  };
  events.onerror = () => {
    status.textContent = 'reconnecting…';
    status.className = 'connection lost';
    if (events.readyState !== EventSource.CLOSED) return;  // the browser tries again itself
    // Refused (a session the daemon no longer knows) or gone: asked once
    // every 3 s which, and the stream opened again when it answers.
    setTimeout(() => {
      api('GET', '/api/jobs').then(() => listen(), (failure) => {
        if (failure instanceof SignedOut) return;
        status.textContent = 'the daemon does not answer; trying again';
        events.onerror();
      });
    }, 3000);
  };
  events.addEventListener('job', (event) => {
    const job = JSON.parse(event.data);
    if (!['running', 'paused'].includes(job.state)) state.progress.delete(job.id);
    const known = state.jobs.findIndex((other) => other.id === job.id);
    if (known >= 0) state.jobs[known] = { ...state.jobs[known], ...job };
    renderJobs();
    jobsChanged();
  });
  events.addEventListener('progress', (event) => {
    const progress = JSON.parse(event.data);
    state.progress.set(progress.job, progress);
    const cutting = state.jobs.find((known) => known.id === progress.job);
    const estimates = cutting && cutting.summary && cutting.summary.cost && cutting.summary.cost.sheet_cutting_seconds;
    if (progress.phase === 'cutting' && progress.stroke === 0 && estimates && estimates[progress.sheet - 1] > 0) {
      realTimeScale.set(progress.job, progress.seconds_left / estimates[progress.sheet - 1]);
    }
    const row = document.querySelector(`tr[data-job="${progress.job}"]`);
    const job = state.jobs.find((known) => known.id === progress.job);
    if (row && job) {
      if (progress.phase === 'cutting') job.sheet = progress.sheet;
      row.querySelector('.time-left').textContent = timeLeft(job);
      row.querySelector('.sheets').textContent = sheetsDone(job);
    }
    renderDevices();
    if (state.sheets.job === progress.job && progress.phase === 'cutting') {
      if (progress.sheet !== state.sheets.sheet && state.tab === 'sheets') {
        openSheets(progress.job, progress.sheet);
      } else {
        highlightStroke();
      }
    }
  });
  events.addEventListener('device', (event) => {
    const device = JSON.parse(event.data);
    const known = state.devices.findIndex((other) => other.name === device.name);
    if (known >= 0) state.devices[known] = device;
    else state.devices.push(device);
    renderDevices();
    renderJobs();  // what a job's row offers depends on its device's state
  });
}
