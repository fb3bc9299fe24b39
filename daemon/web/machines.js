// The machines: a card per device with its state, job and progress, the
// hosts of a shared store, and the devices a new job may be sent to.

import { api } from './api.js';
import { $, element } from './dom.js';
import { state } from './state.js';
import { duration } from './words.js';

// The job on a device that waits between sheets for the operator, if any.
function waitingJob(device) {
  const job = device.job ? state.jobs.find((known) => known.id === device.job) : null;
  return job && job.waiting_for_next ? job : null;
}

export function renderDevices() {
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
      // What the controller said it is when the daemon checked it.
      device.checked && !device.message ? element('p', { class: 'device-checked' }, device.checked) : null,
      device.job ? element('p', {}, `job ${device.job}` + (cutting ? `, sheet ${progress.sheet} of ${progress.sheets}` : '')) : null,
      waitingJob(device) ? element('p', { class: 'waiting' },
        `waiting for ${waitingJob(device).waiting_for || `sheet ${waitingJob(device).sheet + 1} to be loaded`}`) : null,
      progress && progress.phase === 'framing'
        ? element('p', { class: 'waiting' }, `framing sheet ${progress.sheet} (${device.frame_light || 'laser off'})`) : null,
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

export async function refreshDevices() {
  const answer = await api('GET', '/api/devices');
  state.devices = answer.devices || [];
  state.hosts = answer.hosts || [];
  renderDevices();
}
