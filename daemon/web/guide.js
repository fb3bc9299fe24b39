// The assembly guide tab: a job's guide opened, its steps stepped through,
// a panel found by its number, and the steps listed for printing.

import { api, attempt, Refused } from './api.js';
import { $, element } from './dom.js';
import { parseStructure, sharedHoles } from './guide-data.js';
import { Guide } from './guide-view.js';
import { state } from './state.js';

$('guide-job-select').addEventListener('change', () => {
  const id = Number($('guide-job-select').value);
  if (id) attempt(() => openGuide(id));
});

export async function openGuide(jobId) {
  const [manifest, text] = await Promise.all([
    api('GET', `/api/jobs/${jobId}/manifest`),
    api('GET', `/api/jobs/${jobId}/files/structure.obj`),
  ]);
  if (!state.guide) state.guide = new Guide($('guide-view'));
  state.guide.load(state.guide.renderer ? parseStructure(text) : null, manifest);
  state.guide.job = jobId;
  state.guide.visible(state.tab === 'guide');
  const steps = $('guide-print-steps');
  steps.replaceChildren();
  const job = state.jobs.find((known) => known.id === jobId);
  $('guide-print-title').textContent = `Assembly of job ${jobId}${job ? `, ${job.source}` : ''}: ${manifest.panels.length} panels in order`;
  // The steps of manifest.txt: each panel in assembly order, its sheet, and the placed panels it joins.
  for (const panel of state.guide.panels) {
    const neighbours = (panel.neighbors || []).map((id) => state.guide.byId.get(id)).filter(Boolean);
    const joins = neighbours
      .filter((other) => other.id < panel.id)
      .map((other) => `${other.id} (${sharedHoles(panel, other).map((s) => `edge ${s.edge}`).join(', ') || 'no holes'})`);
    const first = panel === state.guide.panels[0];
    steps.append(element('li', { 'data-panel': String(panel.id), 'data-sheet': String(panel.sheet) },
      `Step ${panel.id}: panel ${panel.id} (sheet ${panel.sheet})` + (joins.length ? `: joins ${joins.join('; ')}`
        : first ? ': the first' : ': joins no panel placed yet (a new piece, joined to the rest later)')));
  }
  window.rotafabGuide = {
    job: jobId,
    step: () => state.guide.step,
    panel: () => state.guide.panels[state.guide.step - 1].id,
    highlighted: () => state.guide.highlighted(),
    fps: (milliseconds) => state.guide.measure(milliseconds || 2000),
    whole: () => state.guide.showWhole(),
    panels: state.guide.panels.length,
    triangles: state.guide.views.map((view) => view.mesh.geometry.index.count / 3),
  };
}

const stepBy = (delta) => { if (state.guide) state.guide.goTo(state.guide.step + delta); };
$('guide-first').addEventListener('click', () => state.guide && state.guide.goTo(1));
$('guide-prev').addEventListener('click', () => stepBy(-1));
$('guide-next').addEventListener('click', () => stepBy(1));
$('guide-last').addEventListener('click', () => state.guide && state.guide.goTo(state.guide.panels.length));
document.addEventListener('keydown', (event) => {
  if (state.tab !== 'guide' || event.target.closest('input, select')) return;
  if (event.key === 'ArrowRight') stepBy(1);
  if (event.key === 'ArrowLeft') stepBy(-1);
});
$('guide-find').addEventListener('submit', (event) => {
  event.preventDefault();
  attempt(async () => {
    if (!state.guide) throw new Refused('choose a job first');
    const id = Number($('guide-find-number').value);
    const step = state.guide.panels.findIndex((panel) => panel.id === id);
    if (step < 0) throw new Refused(`there is no panel ${id} in job ${state.guide.job} (1 to ${state.guide.panels.length})`);
    state.guide.goTo(step + 1);
  });
});
$('guide-print').addEventListener('click', () => window.print());
$('guide-whole').addEventListener('click', () => state.guide && state.guide.showWhole());
