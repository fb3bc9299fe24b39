// The daemon's API: requests with the session a login link gave this page,
// the page shown signed out when the daemon refuses the session, and a
// refusal shown in the API's own words.

import { $ } from './dom.js';

export class Refused extends Error {}
export class SignedOut extends Refused {}

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
export const session = () => localStorage.getItem(kSessionKey) || '';

export async function api(method, path, body) {
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
export function signedOut(why) {
  $('signed-out-why').textContent = linkUsed && !session()
    ? 'That login link has been used already, or is more than five minutes old.'
    : why;
  $('signed-out').hidden = false;
  document.body.classList.add('signed-out');
  $('connection').textContent = 'signed out';
  $('connection').className = 'connection lost';
}

export function showError(text) {
  $('error-text').textContent = text;
  $('error').hidden = false;
}
function clearError() {
  $('error').hidden = true;
  $('error-text').textContent = '';
}
$('error-close').addEventListener('click', clearError);

// Runs an action; a refusal is shown as the API said it.
export async function attempt(work) {
  try {
    clearError();
    return await work();
  } catch (failure) {
    if (!(failure instanceof SignedOut)) showError(failure instanceof Refused ? failure.message : String(failure));
    return undefined;
  }
}
