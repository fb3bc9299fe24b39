// The workshop page (README, "The workshop page"): the queue, the machines, the sheets and
// the assembly guide, over the daemon's documented API (docs/API.md) and its
// event stream. Every button calls the API; a refusal shows the API's own words.
'use strict';

(() => {
  const $ = (id) => document.getElementById(id);
  const state = {
    jobs: [],
    devices: [],
    hosts: [],  // on a shared store: every host, up or gone
    progress: new Map(),  // job id -> its last progress event
    sheets: { job: null, sheet: 1, path: null, lines: [] },
    guide: null,
    tab: 'queue',
  };

  // ---- the API ----

  class Refused extends Error {}
  class SignedOut extends Refused {}

  // The session a login link gave this page, kept in this origin's storage
  // (no other port's page reads it) and sent as a bearer token.
  const kSessionKey = 'rotafab-session';
  let linkUsed = false;
  {
    const hash = new URLSearchParams(window.location.hash.slice(1));
    if (hash.get('session')) localStorage.setItem(kSessionKey, hash.get('session'));
    linkUsed = hash.get('signin') === 'used';
    if (window.location.hash) history.replaceState(null, '', window.location.pathname);
  }
  const session = () => localStorage.getItem(kSessionKey) || '';

  async function api(method, path, body) {
    const init = { method, headers: {} };
    if (session()) init.headers.Authorization = `Bearer ${session()}`;
    if (body instanceof FormData) {
      init.body = body;
    } else if (body !== undefined) {
      init.body = JSON.stringify(body);
      init.headers['Content-Type'] = 'application/json';
    }
    let response;
    try {
      response = await fetch(path, init);
    } catch (failure) {
      throw new Refused(`the daemon does not answer (${failure.message}): is rotafabd running?`);
    }
    const type = response.headers.get('Content-Type') || '';
    const data = type.includes('json') ? await response.json().catch(() => ({})) : await response.text();
    if (!response.ok) {
      const words = data && data.error ? data.error : `${response.status} ${response.statusText}`;
      if (response.status === 401) {
        signedOut(words);
        throw new SignedOut(words);
      }
      throw new Refused(words);
    }
    return data;
  }

  // Without a session (none yet, or the daemon started again): what to do,
  // in place of a page that would look live and is not.
  function signedOut(why) {
    $('signed-out-why').textContent = linkUsed && !session()
      ? 'That login link has been used already, or is more than five minutes old.'
      : why;
    $('signed-out').hidden = false;
    document.body.classList.add('signed-out');
    $('connection').textContent = 'signed out';
    $('connection').className = 'connection lost';
  }

  function showError(text) {
    $('error-text').textContent = text;
    $('error').hidden = false;
  }
  function clearError() {
    $('error').hidden = true;
    $('error-text').textContent = '';
  }
  $('error-close').addEventListener('click', clearError);

  // Runs an action; a refusal is shown as the API said it.
  async function attempt(work) {
    try {
      clearError();
      return await work();
    } catch (failure) {
      if (!(failure instanceof SignedOut)) showError(failure instanceof Refused ? failure.message : String(failure));
      return undefined;
    }
  }

  // ---- words ----

  function duration(seconds) {
    if (seconds === undefined || seconds === null || !isFinite(seconds)) return '–';
    seconds = Math.max(0, Math.round(seconds));
    if (seconds < 60) return `${seconds} s`;
    const minutes = Math.floor(seconds / 60);
    if (minutes < 60) return `${minutes} min ${seconds % 60} s`;
    return `${Math.floor(minutes / 60)} h ${minutes % 60} min`;
  }

  function sheetsDone(job) {
    if (!job.sheets) return '–';
    if (job.state === 'done') return `${job.sheets}/${job.sheets}`;
    if (['running', 'paused', 'interrupted', 'failed'].includes(job.state)) {
      return `${Math.max(0, (job.sheet || 0) - 1)}/${job.sheets}`;
    }
    return `0/${job.sheets}`;
  }

  // Each sheet's estimate in real time: the profile's estimates scaled as
  // the device's own estimate of the sheet being cut is (a simulator runs
  // faster than the machine it stands for).
  const realTimeScale = new Map();  // job id -> seconds on the device per estimated second

  function timeLeft(job) {
    const progress = state.progress.get(job.id) || job.progress;
    const cost = job.summary && job.summary.cost;
    const perSheet = (cost && cost.sheet_cutting_seconds) || [];
    if (progress && progress.phase === 'cutting' && progress.seconds_left !== undefined) {
      const scale = realTimeScale.get(job.id) || 1;
      const later = perSheet.slice(progress.sheet).reduce((a, b) => a + b, 0) * scale;
      return duration(progress.seconds_left + later);
    }
    if (progress && progress.phase && ['queued', 'planning'].includes(job.state)) {
      const part = progress.total && progress.done < progress.total
        ? ` ${Math.round((100 * progress.done) / progress.total)}%` : '';
      return `planning: ${progress.step || progress.phase}${part}`;
    }
    if (cost && ['ready', 'queued'].includes(job.state)) return duration(cost.cutting_seconds);
    if (['interrupted', 'failed', 'paused'].includes(job.state) && perSheet.length) {
      return duration(perSheet.slice(Math.max(0, job.sheet - 1)).reduce((a, b) => a + b, 0));
    }
    return job.state === 'done' ? '0 s' : '–';
  }

  function element(tag, attributes = {}, ...children) {
    const node = document.createElement(tag);
    for (const [key, value] of Object.entries(attributes)) {
      if (key === 'class') node.className = value;
      else if (key.startsWith('on')) node.addEventListener(key.slice(2), value);
      else if (value !== undefined && value !== null && value !== false) node.setAttribute(key, value === true ? '' : value);
    }
    for (const child of children) {
      if (child !== null && child !== undefined) node.append(child);
    }
    return node;
  }

  // ---- the queue ----

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
    switch (job.state) {
      case 'ready':
        act('Start', 'start', {}, { class: 'primary' });
        break;
      case 'running':
        if (job.waiting_for_next) act('Next sheet loaded', 'next', {}, { class: 'primary' });
        act('Pause', 'pause');
        break;
      case 'paused':
        act('Resume', 'resume', {}, { class: 'primary' });
        break;
      case 'interrupted':
      case 'failed':
        // Only a cut that was under way goes on; a plan that failed has no sheets.
        if (!job.sheets || !job.sheet) break;
        act('Resume from sheet…', 'resume', () => {
          const answer = window.prompt(`Cut again from which sheet (1 to ${job.sheets})? Load it fresh first.`,
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

  function renderJobs() {
    const body = $('jobs-body');
    body.replaceChildren();
    for (const job of state.jobs) {
      const row = element('tr', { 'data-job': job.id, draggable: 'true', 'data-state': job.state },
        element('td', {}, String(job.id)),
        element('td', {}, job.source || ''),
        element('td', {}, element('span', { class: `state ${job.state}` }, job.state),
                element('span', { class: 'message' }, job.waiting_for_next
                  ? `sheet ${job.sheet} cut: load sheet ${job.sheet + 1}, then press “Next sheet loaded”`
                  : job.message || ''),
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

  async function refreshJobs() {
    const answer = await api('GET', '/api/jobs');
    state.jobs = answer.jobs || [];
    renderJobs();
  }

  // Job transitions come by the event stream; the queue is read again at
  // most once a second however many come.
  let jobsTimer = null;
  let jobsRead = 0;
  function jobsChanged() {
    if (jobsTimer) return;
    const wait = Math.max(0, 1000 - (Date.now() - jobsRead));
    jobsTimer = setTimeout(() => {
      jobsTimer = null;
      jobsRead = Date.now();
      refreshJobs().catch((failure) => showError(failure.message));
    }, wait);
  }

  // ---- the machines ----

  // The job on a device that waits between sheets for the operator, if any.
  function waitingJob(device) {
    const job = device.job ? state.jobs.find((known) => known.id === device.job) : null;
    return job && job.waiting_for_next ? job : null;
  }

  function renderDevices() {
    const cards = $('devices');
    cards.replaceChildren();
    for (const device of state.devices) {
      const progress = device.job ? state.progress.get(device.job) : null;
      const cutting = progress && progress.phase === 'cutting';
      const fraction = cutting && progress.strokes ? progress.stroke / progress.strokes : null;
      cards.append(element('article', { class: 'device', 'data-device': device.name, 'data-state': device.state },
        element('h3', {}, device.name, element('span', { class: `state ${device.state}` }, device.state)),
        state.hosts.length ? element('p', { class: 'device-host' }, `on host ${device.host}`) : null,
        element('p', {}, `${device.machine || '?'} · ${device.material || ''} · ${device.uri}`),
        device.message ? element('p', { class: 'device-message' }, device.message) : null,
        device.job ? element('p', {}, `job ${device.job}` + (cutting ? `, sheet ${progress.sheet} of ${progress.sheets}` : '')) : null,
        waitingJob(device) ? element('p', { class: 'waiting' },
          `waiting for sheet ${waitingJob(device).sheet + 1} to be loaded`) : null,
        fraction !== null
          ? element('progress', { max: '1', value: String(fraction), 'data-percent': String(Math.round(fraction * 100)) })
          : null,
        cutting ? element('p', { class: 'progress-text' },
          `${Math.round(fraction * 100)}% of the sheet · ${duration(progress.seconds_left)} left`) : null));
    }
    // On a shared store, every host and whether it is there.
    const hosts = $('hosts');
    hosts.hidden = state.hosts.length === 0;
    hosts.replaceChildren(...state.hosts.map((host) => element('span', { class: `host ${host.state}`, 'data-host': host.name },
      host.state === 'gone' ? `${host.name}: gone, last heard ${host.seen}` : `${host.name}: up`)));
    const choose = $('opt-device');
    const chosen = choose.value;
    choose.replaceChildren(element('option', { value: '' }, 'any that fits'));
    for (const device of state.devices) {
      choose.append(element('option', { value: device.name }, `${device.name} (${device.machine})`));
    }
    choose.value = chosen;
  }

  async function refreshDevices() {
    const answer = await api('GET', '/api/devices');
    state.devices = answer.devices || [];
    state.hosts = answer.hosts || [];
    renderDevices();
  }

  // ---- submitting a mesh ----

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

  // ---- the sheets ----

  function plannedJobs() {
    return state.jobs.filter((job) => job.sheets > 0);
  }

  function fillJobChoices() {
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

  function showSheets(jobId) {
    showTab('sheets');
    $('sheets-job-select').value = String(jobId);
    openSheets(jobId, 1);
  }
  $('sheets-job-select').addEventListener('change', () => {
    const id = Number($('sheets-job-select').value);
    if (id) openSheets(id, 1);
  });

  async function openSheets(jobId, sheet) {
    const job = state.jobs.find((known) => known.id === jobId);
    if (!job) return;
    state.sheets.job = jobId;
    const buttons = $('sheet-buttons');
    buttons.replaceChildren();
    const perSheet = (job.summary && job.summary.cost && job.summary.cost.sheet_cutting_seconds) || [];
    for (let n = 1; n <= job.sheets; n += 1) {
      buttons.append(element('button', {
        type: 'button', 'data-sheet': n, 'aria-pressed': String(n === sheet),
        title: perSheet[n - 1] !== undefined ? `about ${duration(perSheet[n - 1])} to cut` : '',
        onclick: () => openSheets(jobId, n),
      }, `Sheet ${n}`));
    }
    await attempt(() => drawSheet(jobId, sheet));
  }

  async function drawSheet(jobId, sheet) {
    const path = await api('GET', `/api/jobs/${jobId}/sheets/${sheet}`);
    state.sheets = { job: jobId, sheet, path, lines: [] };
    const svgNS = 'http://www.w3.org/2000/svg';
    const svg = document.createElementNS(svgNS, 'svg');
    svg.setAttribute('viewBox', `0 0 ${path.width} ${path.height}`);
    svg.setAttribute('data-job', jobId);
    svg.setAttribute('data-sheet', sheet);
    const bed = document.createElementNS(svgNS, 'rect');
    Object.entries({ x: 0, y: 0, width: path.width, height: path.height, fill: '#fbfaf7', stroke: '#999', 'stroke-width': 0.02 })
      .forEach(([k, v]) => bed.setAttribute(k, v));
    svg.append(bed);
    // Sheet coordinates have y up.
    const flip = document.createElementNS(svgNS, 'g');
    flip.setAttribute('transform', `translate(0 ${path.height}) scale(1 -1)`);
    // A group per operation (the strokes come operation by operation), so
    // that a pale colour can be edged as a whole.
    const groups = new Map();
    const groupOf = (operation) => {
      if (!groups.has(operation)) {
        const group = document.createElementNS(svgNS, 'g');
        group.setAttribute('data-operation', operation);
        if (pale(path.colours[operation] || '#000')) group.setAttribute('class', 'pale');
        flip.append(group);
        groups.set(operation, group);
      }
      return groups.get(operation);
    };
    path.strokes.forEach((stroke, index) => {
      const line = document.createElementNS(svgNS, 'polyline');
      line.setAttribute('points', stroke.points.map((p) => `${p[0]},${p[1]}`).join(' '));
      line.setAttribute('fill', 'none');
      line.setAttribute('stroke', path.colours[stroke.operation] || '#000');
      // Visible on a screen, unlike the cut file's hairlines: 1.5 px whatever the zoom.
      line.setAttribute('stroke-width', '1.5');
      line.setAttribute('vector-effect', 'non-scaling-stroke');
      line.setAttribute('data-stroke', index);
      line.setAttribute('data-operation', stroke.operation);
      groupOf(stroke.operation).append(line);
      state.sheets.lines.push(line);
    });
    svg.append(flip);
    $('sheet-view').replaceChildren(svg);
    $('sheet-info').textContent =
      `Sheet ${sheet}: ${path.strokes.length} strokes, ${path.burn_length.toFixed(0)} in burnt, about ${duration(path.seconds)} to cut.`;
    const legend = $('sheet-legend');
    legend.replaceChildren();
    for (const [operation, colour] of Object.entries(path.colours)) {
      if (!path.strokes.some((stroke) => stroke.operation === operation)) continue;
      legend.append(element('span', {}, element('span', { class: 'swatch', style: `background:${colour}` }), ` ${operation}`));
    }
    highlightStroke();
  }

  // Whether a colour "#rrggbb" is too light to see on the bed as it is.
  function pale(colour) {
    const value = parseInt(colour.slice(1), 16);
    const r = (value >> 16) & 255;
    const g = (value >> 8) & 255;
    const b = value & 255;
    return 0.2126 * r + 0.7152 * g + 0.0722 * b > 160;
  }

  // The stroke being cut (progress counts those finished), the ones before it faded.
  function highlightStroke() {
    const { job, sheet, lines } = state.sheets;
    const progress = state.progress.get(job);
    const jobNow = state.jobs.find((known) => known.id === job);
    let done = 0;
    let current = -1;
    if (progress && progress.phase === 'cutting' && progress.sheet === sheet) {
      done = progress.stroke;
      current = progress.stroke < progress.strokes ? progress.stroke : -1;
    } else if (jobNow && (jobNow.state === 'done' || (jobNow.sheet > sheet))) {
      done = lines.length;
    }
    lines.forEach((line, index) => {
      line.classList.toggle('done', index < done);
      line.setAttribute('stroke-opacity', index < done ? '0.35' : '1');
      if (index === current) {
        line.setAttribute('stroke-width', '5');
        line.setAttribute('data-current', 'true');
      } else if (line.hasAttribute('data-current')) {
        line.setAttribute('stroke-width', '1.5');
        line.removeAttribute('data-current');
      }
    });
    const view = $('sheet-view').firstElementChild;
    if (view) view.setAttribute('data-current-stroke', String(current));
  }

  // ---- the event stream ----

  function listen() {
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
    });
  }

  // ---- the assembly guide ----

  function showGuide(jobId) {
    showTab('guide');
    $('guide-job-select').value = String(jobId);
    attempt(() => openGuide(jobId));
  }
  $('guide-job-select').addEventListener('change', () => {
    const id = Number($('guide-job-select').value);
    if (id) attempt(() => openGuide(id));
  });

  // structure.obj: each panel's vertices, then its faces under `g panel-N`.
  function parseStructure(text) {
    const positions = [];
    const index = [];
    const ranges = new Map();  // panel id -> [first vertex, end vertex)
    const triangles = new Map();  // panel id -> [first index, end index)
    let panel = null;
    let panelFirst = 0;
    let trianglesFirst = 0;
    let lineStart = 0;
    let vertices = 0;
    const close = () => {
      ranges.set(panel, [panelFirst, vertices]);
      triangles.set(panel, [trianglesFirst, index.length]);
      panel = null;
      panelFirst = vertices;
    };
    while (lineStart < text.length) {
      let lineEnd = text.indexOf('\n', lineStart);
      if (lineEnd < 0) lineEnd = text.length;
      const line = text.slice(lineStart, lineEnd);
      lineStart = lineEnd + 1;
      if (line.startsWith('v ')) {
        if (panel !== null) close();
        const parts = line.split(' ');
        positions.push(Number(parts[1]), Number(parts[2]), Number(parts[3]));
        vertices += 1;
      } else if (line.startsWith('g panel-')) {
        if (panel !== null) close();
        panel = Number(line.slice(8));
        trianglesFirst = index.length;
      } else if (line.startsWith('f ')) {
        const corners = line.split(' ').slice(1).map((word) => Number(word.split('/')[0]) - 1);
        for (let k = 1; k + 1 < corners.length; k += 1) index.push(corners[0], corners[k], corners[k + 1]);
      }
    }
    if (panel !== null) close();
    return { positions, index, ranges, triangles };
  }

  // A panel drawn coarsely while the view moves: its outline, simplified by
  // Douglas-Peucker to a tenth of its size, as a fan from its middle. A
  // browser without a graphics card (software WebGL) draws the bunny's
  // 180,000 triangles a few times a second; these, many times fewer, fast.
  function coarseStructure(structure) {
    const positions = [];
    const index = [];
    const ranges = new Map();
    const point = (v) => [structure.positions[3 * v], structure.positions[3 * v + 1], structure.positions[3 * v + 2]];
    const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    const offLine = (p, a, b) => {
      const ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
      const ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
      const length = Math.hypot(...ab);
      if (length === 0) return Math.hypot(...ap);
      const cross = [ab[1] * ap[2] - ab[2] * ap[1], ab[2] * ap[0] - ab[0] * ap[2], ab[0] * ap[1] - ab[1] * ap[0]];
      return Math.hypot(...cross) / length;
    };
    const simplify = (loop, from, to, tolerance, kept) => {
      let worst = -1;
      let far = 0;
      for (let k = from + 1; k < to; k += 1) {
        const d = offLine(loop[k], loop[from], loop[to % loop.length]);
        if (d > far) {
          far = d;
          worst = k;
        }
      }
      if (worst < 0 || far <= tolerance) return;
      simplify(loop, from, worst, tolerance, kept);
      kept.push(worst);
      simplify(loop, worst, to, tolerance, kept);
    };
    for (const [id, [first, end]] of structure.triangles) {
      const [v0, v1] = structure.ranges.get(id);
      const count = v1 - v0;
      // The boundary: the edges of one triangle only, in the triangles' direction.
      const used = new Map();
      for (let t = first; t < end; t += 3) {
        for (let k = 0; k < 3; k += 1) {
          const a = structure.index[t + k] - v0;
          const b = structure.index[t + ((k + 1) % 3)] - v0;
          const key = Math.min(a, b) * count + Math.max(a, b);
          used.set(key, used.has(key) ? null : [a, b]);
        }
      }
      const next = new Map();
      for (const edge of used.values()) if (edge) next.set(edge[0], edge[1]);
      let longest = [];
      const seen = new Set();
      for (const start of next.keys()) {
        if (seen.has(start)) continue;
        const loop = [];
        for (let v = start; v !== undefined && !seen.has(v); v = next.get(v)) {
          seen.add(v);
          loop.push(v);
        }
        if (loop.length > longest.length) longest = loop;
      }
      if (longest.length < 3) continue;
      const loop = longest.map((v) => point(v + v0));
      let size = 0;
      let opposite = 0;
      for (let k = 1; k < loop.length; k += 1) {
        const d = distance(loop[0], loop[k]);
        if (d > size) {
          size = d;
          opposite = k;
        }
      }
      const kept = [0];
      simplify(loop, 0, opposite, size / 6, kept);
      kept.push(opposite);
      simplify(loop, opposite, loop.length, size / 6, kept);
      if (kept.length < 3) continue;
      const firstVertex = positions.length / 3;
      const middle = [0, 0, 0];
      for (const k of kept) for (let axis = 0; axis < 3; axis += 1) middle[axis] += loop[k][axis] / kept.length;
      positions.push(...middle);
      for (const k of kept) positions.push(...loop[k]);
      for (let k = 0; k < kept.length; k += 1) {
        index.push(firstVertex, firstVertex + 1 + k, firstVertex + 1 + ((k + 1) % kept.length));
      }
      ranges.set(id, [firstVertex, positions.length / 3]);
    }
    return { positions, index, ranges };
  }

  const colours = {
    placed: [0.79, 0.66, 0.42],
    next: [1.0, 0.42, 0.0],
    later: [0.78, 0.8, 0.83],
  };

  class Guide {
    constructor(container) {
      this.container = container;
      this.views = [];
      this.showing = false;
      this.frames = 0;
      this.spin = 0;
      this.loop = this.loop.bind(this);
      // Without WebGL (or three.js) the steps are still told, in words.
      try {
        if (typeof THREE === 'undefined') throw new Error('three.js is not installed (Debian package libjs-three)');
        this.renderer = new THREE.WebGLRenderer({ antialias: false });
      } catch (failure) {
        this.renderer = null;
        container.replaceChildren(element('p', { class: 'no-3d' },
          `No 3D view in this browser (${failure.message || failure}); the steps, panels and holes are told beside it.`));
        return;
      }
      this.renderer.setClearColor(0xf0f2f4);
      container.append(this.renderer.domElement);
      this.scene = new THREE.Scene();
      this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1e5);
      this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
      this.controls.enableDamping = true;
      this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 0.8));
      this.light = new THREE.DirectionalLight(0xffffff, 0.6);
      this.scene.add(this.light);
      new ResizeObserver(() => this.resize()).observe(container);
    }

    resize() {
      const width = this.container.clientWidth;
      const height = this.container.clientHeight;
      if (!width || !height) return;
      this.renderer.setSize(width, height);
      this.camera.aspect = width / height;
      this.camera.updateProjectionMatrix();
      this.dirty = true;
    }

    visible(on) {
      if (!this.renderer) return;
      const was = this.showing;
      this.showing = on;
      if (on && !was) {
        this.resize();
        requestAnimationFrame(this.loop);
      }
    }

    loop() {
      if (!this.showing) return;
      requestAnimationFrame(this.loop);
      if (this.spin) {
        // For the frame-rate measure: orbit without a hand on the mouse.
        this.controls.autoRotate = true;
        this.controls.autoRotateSpeed = this.spin;
      }
      if (this.goal) {
        // Towards the next panel, a fifth of the way each frame.
        this.controls.target.lerp(this.goal.target, 0.2);
        this.camera.position.lerp(this.goal.position, 0.2);
        if (this.camera.position.distanceTo(this.goal.position) < this.goal.near) this.goal = null;
      }
      const moved = this.controls.update();
      // Coarse while the view moves and a few frames after; the panels
      // themselves once it rests. Nothing is drawn while nothing changes.
      if (moved) this.moving = 6;
      const inMotion = this.moving > 0;
      const coarse = inMotion && this.views.length > 1;
      if (this.moving > 0) this.moving -= 1;
      if (!moved && !this.dirty && !inMotion && this.drewFull) return;
      // Half the pixels each way while it moves (software WebGL fills
      // pixels slowly), all of them once it rests.
      const ratio = (window.devicePixelRatio || 1) * (inMotion ? 0.5 : 1);
      if (this.renderer.getPixelRatio() !== ratio) this.renderer.setPixelRatio(ratio);
      this.views.forEach((view, k) => { view.mesh.visible = k === (coarse ? 1 : 0); });
      this.light.position.copy(this.camera.position);
      this.renderer.render(this.scene, this.camera);
      this.frames += 1;
      this.drewFull = !inMotion;
      this.dirty = false;
    }

    // A mesh of the structure, its colours kept per vertex and its panels' vertex ranges.
    makeView(structure) {
      const geometry = new THREE.BufferGeometry();
      const vertexCount = structure.positions.length / 3;
      const IndexArray = vertexCount > 65535 ? Uint32Array : Uint16Array;
      geometry.setIndex(new THREE.BufferAttribute(new IndexArray(structure.index), 1));
      geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(structure.positions), 3));
      const colour = new Float32Array(vertexCount * 3);
      geometry.setAttribute('color', new THREE.BufferAttribute(colour, 3));
      geometry.computeVertexNormals();
      geometry.computeBoundingSphere();
      const material = new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors, side: THREE.DoubleSide });
      const mesh = new THREE.Mesh(geometry, material);
      this.scene.add(mesh);
      return { mesh, colour, ranges: structure.ranges };
    }

    load(structure, manifest) {
      // Assembly order: the manifest's `order`, else the panels' own.
      this.panels = [...manifest.panels].sort((a, b) => (a.order || a.id) - (b.order || b.id));
      this.byId = new Map(manifest.panels.map((panel) => [panel.id, panel]));
      this.step = 0;
      if (!this.renderer) {
        this.goTo(1);
        return;
      }
      for (const view of this.views) {
        this.scene.remove(view.mesh);
        view.mesh.geometry.dispose();
      }
      this.views = [this.makeView(structure)];
      // Small structures are drawn whole even while they move.
      if (structure.index.length / 3 > 20000) this.views.push(this.makeView(coarseStructure(structure)));
      const sphere = this.views[0].mesh.geometry.boundingSphere;
      this.controls.target.copy(sphere.center);
      this.camera.near = sphere.radius / 100;
      this.camera.far = sphere.radius * 100;
      this.camera.position.copy(this.wholeView().position);
      this.camera.updateProjectionMatrix();
      this.controls.update();
      this.paint(0, this.panels.length, 'later');
      this.goTo(1);
    }

    // Colours the panels at steps [from, to) (0-based) as `kind`, in every view.
    paint(from, to, kind) {
      const [r, g, b] = colours[kind];
      for (const view of this.views) {
        for (let k = from; k < to; k += 1) {
          const range = view.ranges.get(this.panels[k].id);
          if (!range) continue;
          for (let v = range[0]; v < range[1]; v += 1) {
            view.colour[3 * v] = r;
            view.colour[3 * v + 1] = g;
            view.colour[3 * v + 2] = b;
          }
        }
        view.mesh.geometry.attributes.color.needsUpdate = true;
      }
      this.dirty = true;
    }

    goTo(step) {
      step = Math.max(1, Math.min(this.panels.length, step));
      const before = this.step;
      // Only the panels whose colour changes are painted again.
      if (step > before) {
        this.paint(Math.max(0, before - 1), step - 1, 'placed');
      } else if (before > 0) {
        this.paint(step, before, 'later');
      }
      this.paint(step - 1, step, 'next');
      this.step = step;
      if (this.renderer && $('guide-follow').checked) this.focusOn(this.panels[step - 1].id);
      this.describe();
    }

    // The whole structure in view, from the front and a little above.
    wholeView() {
      const sphere = this.views[0].mesh.geometry.boundingSphere;
      const position = sphere.center.clone()
        .add(new THREE.Vector3(0.4, 0.5, 1).normalize().multiplyScalar(sphere.radius * 3));
      return { target: sphere.center.clone(), position, near: sphere.radius / 100 };
    }

    showWhole() {
      if (!this.renderer || !this.views.length) return;
      this.goal = this.wholeView();
      this.dirty = true;
    }

    // The view turned to face the panel from outside the structure, close
    // enough to see it and its neighbours.
    focusOn(id) {
      const range = this.views[0].ranges.get(id);
      if (!range) return;
      const geometry = this.views[0].mesh.geometry;
      const position = geometry.attributes.position.array;
      const normal = geometry.attributes.normal.array;
      const centre = new THREE.Vector3();
      const facing = new THREE.Vector3();
      for (let v = range[0]; v < range[1]; v += 1) {
        centre.x += position[3 * v];
        centre.y += position[3 * v + 1];
        centre.z += position[3 * v + 2];
        facing.x += normal[3 * v];
        facing.y += normal[3 * v + 1];
        facing.z += normal[3 * v + 2];
      }
      centre.divideScalar(range[1] - range[0]);
      let size = 0;
      for (let v = range[0]; v < range[1]; v += 1) {
        size = Math.max(size, centre.distanceTo(new THREE.Vector3(position[3 * v], position[3 * v + 1], position[3 * v + 2])));
      }
      const sphere = geometry.boundingSphere;
      const outwards = centre.clone().sub(sphere.center);
      if (facing.lengthSq() === 0) facing.copy(outwards);
      if (facing.dot(outwards) < 0) facing.negate();
      facing.normalize();
      const distance = Math.min(Math.max(size * 12, sphere.radius * 0.5), sphere.radius * 3);
      this.goal = { target: centre, position: centre.clone().addScaledVector(facing, distance), near: distance / 200 };
      this.dirty = true;
    }

    describe() {
      const panel = this.panels[this.step - 1];
      $('guide-step').textContent = String(this.step);
      $('guide-steps').textContent = String(this.panels.length);
      $('guide-panel-number').textContent = String(panel.id);
      $('guide-panel-sheet').textContent = panel.sheet ? String(panel.sheet) : '–';
      const placedBefore = (other) => (other.order || other.id) < (panel.order || panel.id);
      const neighbours = (panel.neighbors || []).map((id) => this.byId.get(id)).filter(Boolean);
      $('guide-panel-neighbours').textContent = neighbours.length
        ? neighbours.map((other) => `${other.id}${placedBefore(other) ? ' (placed)' : ''}`).join(', ')
        : '–';
      const holes = $('guide-panel-holes');
      holes.replaceChildren();
      for (const other of neighbours) {
        const shared = sharedHoles(panel, other);
        if (!shared.length) continue;
        holes.append(element('li', {}, `with ${other.id}: ${shared.map((s) => `edge ${s.edge} (${s.count} hole${s.count === 1 ? '' : 's'})`).join(', ')}`));
      }
      if (this.renderer) this.renderer.domElement.setAttribute('data-highlighted', String(panel.id));
    }

    // The panel whose vertices are painted as the next one, read from what is drawn.
    highlighted() {
      if (!this.renderer) return [];
      const [r, g, b] = colours.next;
      const found = [];
      const { colour, ranges } = this.views[0];
      for (const [id, range] of ranges) {
        const v = range[0];
        if (range[1] > v && colour[3 * v] === Math.fround(r) && colour[3 * v + 1] === Math.fround(g) &&
            colour[3 * v + 2] === Math.fround(b)) {
          found.push(id);
        }
      }
      return found;
    }

    // Frames drawn per second over `milliseconds`, orbiting.
    measure(milliseconds) {
      return new Promise((resolve) => {
        this.spin = 30;
        const start = performance.now();
        const frames = this.frames;
        setTimeout(() => {
          const rate = ((this.frames - frames) * 1000) / (performance.now() - start);
          this.spin = 0;
          this.controls.autoRotate = false;
          resolve(rate);
        }, milliseconds);
      });
    }
  }

  // The holes two panels share: by edge, those on both.
  function sharedHoles(panel, other) {
    const count = (holes) => {
      const counts = new Map();
      for (const hole of holes || []) {
        if (hole.edge !== undefined) counts.set(hole.edge, (counts.get(hole.edge) || 0) + 1);
      }
      return counts;
    };
    const mine = count(panel.holes);
    const theirs = count(other.holes);
    const shared = [];
    for (const [edge, n] of mine) {
      if (theirs.has(edge)) shared.push({ edge, count: Math.min(n, theirs.get(edge)) });
    }
    return shared;
  }

  async function openGuide(jobId) {
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
    for (const panel of state.guide.panels) {
      const neighbours = (panel.neighbors || []).map((id) => state.guide.byId.get(id)).filter(Boolean);
      const joins = neighbours
        .filter((other) => (other.order || other.id) < (panel.order || panel.id))
        .map((other) => `${other.id} (${sharedHoles(panel, other).map((s) => `edge ${s.edge}`).join(', ') || 'no holes'})`);
      const first = panel === state.guide.panels[0];
      steps.append(element('li', {}, `Panel ${panel.id}, sheet ${panel.sheet}` + (joins.length ? `: joins ${joins.join('; ')}`
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

  // ---- start ----

  if (!session()) {
    signedOut('This browser has no session with the daemon yet.');
  } else {
    attempt(async () => {
      await Promise.all([refreshDevices(), refreshJobs()]);
      listen();
      // What the other hosts do (their devices, the jobs they cut) comes with no event here: looked at again every few seconds.
      setInterval(() => {
        if (state.hosts.length) Promise.all([refreshDevices(), refreshJobs()]).catch(() => {});
      }, 3000);
    });
  }
})();
