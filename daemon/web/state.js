// What the page knows, shared by every part of it: the queue, the devices
// and hosts, the last progress of each job, the sheet shown, the guide and
// the tab open.

export const state = {
  jobs: [],
  devices: [],
  hosts: [],  // on a shared store: every host, up or gone
  progress: new Map(),  // job id -> its last progress event
  sheets: { job: null, sheet: 1, path: null, lines: [] },
  guide: null,
  tab: 'queue',
};
