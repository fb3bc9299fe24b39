// How a job's numbers read on the page: lengths, durations, sheets cut, and the
// time left (scaled to the device's own pace).

import { state } from './state.js';

// A length in inches as the job shows its lengths (its summary's "units",
// make's --units or the daemon's `units:`): "1005 in", "25527 mm".
export function length(inches, job) {
  const units = job && job.summary && job.summary.units === 'mm' ? 'mm' : 'in';
  return units === 'mm' ? `${(inches * 25.4).toFixed(0)} mm` : `${inches.toFixed(0)} in`;
}

export function duration(seconds) {
  if (seconds === undefined || seconds === null || !isFinite(seconds)) return '–';
  seconds = Math.max(0, Math.round(seconds));
  if (seconds < 60) return `${seconds} s`;
  const minutes = Math.floor(seconds / 60);
  if (minutes < 60) return `${minutes} min ${seconds % 60} s`;
  return `${Math.floor(minutes / 60)} h ${minutes % 60} min`;
}

export function sheetsDone(job) {
  if (!job.sheets) return '–';
  return `${job.sheets_cut || 0}/${job.sheets}`;
}

// Each sheet's estimate in real time: the profile's estimates scaled as
// the device's own estimate of the sheet being cut is (a simulator runs
// faster than the machine it stands for).
export const realTimeScale = new Map();  // job id -> seconds on the device per estimated second

export function timeLeft(job) {
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
