// Submitting a mesh: the drop box (or file chooser) and the new job's options.

import { api, attempt, Refused } from './api.js';
import { $ } from './dom.js';
import { jobsChanged, renderJobs } from './queue.js';
import { state } from './state.js';

const dropZone = $('drop-zone');
const meshInput = $('mesh-file');
let dropped = null;
function meshChosen(file) {
  dropped = file;
  $('drop-text').textContent = file ? `${file.name} (${Math.ceil(file.size / 1024)} KB)`
    : 'Drop a mesh here (OBJ, OFF, PLY, STL, …) or choose one';
}
meshInput.addEventListener('change', () => meshChosen(meshInput.files[0] || null));
for (const type of ['dragenter', 'dragover']) {
  dropZone.addEventListener(type, (event) => { event.preventDefault(); dropZone.classList.add('over'); });
}
dropZone.addEventListener('dragleave', () => dropZone.classList.remove('over'));
dropZone.addEventListener('drop', (event) => {
  event.preventDefault();
  dropZone.classList.remove('over');
  if (event.dataTransfer.files.length) meshChosen(event.dataTransfer.files[0]);
});

$('submit-form').addEventListener('submit', (event) => {
  event.preventDefault();
  attempt(async () => {
    const file = dropped || meshInput.files[0];
    if (!file) throw new Refused('choose a mesh first (drop it on the box, or click it)');
    const options = { structure: $('opt-structure').value };
    if ($('opt-size').value.trim()) options.size = $('opt-size').value.trim();
    if ($('opt-panels').value.trim()) options.panels = $('opt-panels').value.trim();
    if ($('opt-material').value.trim()) options.material = $('opt-material').value.trim();
    if ($('opt-units').value) options.units = $('opt-units').value;
    const form = new FormData();
    form.append('file', file, file.name);
    form.append('options', JSON.stringify(options));
    if ($('opt-device').value) form.append('device', $('opt-device').value);
    $('submit-button').disabled = true;
    try {
      const job = await api('POST', '/api/jobs', form);
      meshChosen(null);
      meshInput.value = '';
      state.jobs = state.jobs.filter((known) => known.id !== job.id).concat([job]);
      renderJobs();
      jobsChanged();
    } finally {
      $('submit-button').disabled = false;
    }
  });
});
