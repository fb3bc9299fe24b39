// The workshop page (docs/daemon.md, "The workshop page"): the queue, the machines, the sheets and
// the assembly guide, over the daemon's documented API (docs/API.md) and its
// event stream. Every button calls the API; a refusal shows the API's own words.
//
// The entry module of the page (index.html loads it after three.js); the
// parts are modules beside it: api.js (requests, session, refusals),
// events.js (the event stream), queue.js, machines.js, submit.js, tabs.js,
// sheets.js, guide.js with guide-data.js and guide-view.js, and the shared
// dom.js, state.js and words.js.

import { attempt, session, signedOut } from './api.js';
import { listen } from './events.js';
import './guide.js';
import { refreshDevices } from './machines.js';
import { refreshJobs, renderJobs } from './queue.js';
import './sheets.js';
import { state } from './state.js';
import './submit.js';
import './tabs.js';

// ---- start ----

if (!session()) {
  signedOut('This browser has no session with the daemon yet.');
} else {
  attempt(async () => {
    await Promise.all([refreshDevices(), refreshJobs()]);
    renderJobs();  // (with the devices known: no Start for one that cannot cut)
    listen();
    // What the other hosts do (their devices, the jobs they cut) comes with no event here: looked at again every few seconds.
    setInterval(() => {
      if (state.hosts.length) Promise.all([refreshDevices(), refreshJobs()]).catch(() => {});
    }, 3000);
  });
}
