// The tabs (queue, sheets, assembly guide), the planned jobs each of the
// latter two may show, and a job's sheets or guide opened from its row.

import { attempt } from './api.js';
import { $, element } from './dom.js';
import { openGuide } from './guide.js';
import { openSheets } from './sheets.js';
import { state } from './state.js';

function plannedJobs() {
  return state.jobs.filter((job) => job.sheets > 0);
}

export function fillJobChoices() {
  for (const id of ['sheets-job-select', 'guide-job-select']) {
    const select = $(id);
    const chosen = select.value;
    select.replaceChildren(element('option', { value: '' }, 'choose a planned job'));
    for (const job of plannedJobs()) {
      select.append(element('option', { value: String(job.id) }, `${job.id}: ${job.source} (${job.sheets} sheets)`));
    }
    select.value = chosen;
  }
}

function showTab(name) {
  state.tab = name;
  if (name === 'sheets' && !state.sheets.job) {
    // The job being cut, else the last one planned.
    const job = state.jobs.find((known) => known.state === 'running' && known.sheets)
      || plannedJobs()[plannedJobs().length - 1];
    if (job) {
      $('sheets-job-select').value = String(job.id);
      openSheets(job.id, Math.max(1, job.state === 'running' ? job.sheet : 1));
    }
  }
  for (const tab of document.querySelectorAll('.tab')) {
    tab.setAttribute('aria-selected', String(tab.dataset.tab === name));
  }
  for (const page of document.querySelectorAll('.tab-page')) page.hidden = page.id !== `tab-${name}`;
  if (state.guide) state.guide.visible(name === 'guide');
}
for (const tab of document.querySelectorAll('.tab')) tab.addEventListener('click', () => showTab(tab.dataset.tab));

export function showSheets(jobId) {
  showTab('sheets');
  $('sheets-job-select').value = String(jobId);
  openSheets(jobId, 1);
}

export function showGuide(jobId) {
  showTab('guide');
  $('guide-job-select').value = String(jobId);
  attempt(() => openGuide(jobId));
}
