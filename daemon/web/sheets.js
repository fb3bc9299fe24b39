// The sheets: each sheet drawn as the laser burns it, in its operations'
// colours, with the stroke being cut highlighted.

import { api, attempt } from './api.js';
import { $, element } from './dom.js';
import { state } from './state.js';
import { duration, length } from './words.js';

$('sheets-job-select').addEventListener('change', () => {
  const id = Number($('sheets-job-select').value);
  if (id) openSheets(id, 1);
});

export async function openSheets(jobId, sheet) {
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
  Object.entries({ x: 0, y: 0, width: path.width, height: path.height, fill: kSheetColour, stroke: '#999', 'stroke-width': 0.02 })
    .forEach(([k, v]) => bed.setAttribute(k, v));
  svg.append(bed);
  // Sheet coordinates have y up.
  const flip = document.createElementNS(svgNS, 'g');
  flip.setAttribute('transform', `translate(0 ${path.height}) scale(1 -1)`);
  // A group per operation (the strokes come operation by operation).
  const groups = new Map();
  const groupOf = (operation) => {
    if (!groups.has(operation)) {
      const group = document.createElementNS(svgNS, 'g');
      group.setAttribute('data-operation', operation);
      flip.append(group);
      groups.set(operation, group);
    }
    return groups.get(operation);
  };
  path.strokes.forEach((stroke, index) => {
    const line = document.createElementNS(svgNS, 'polyline');
    line.setAttribute('points', stroke.points.map((p) => `${p[0]},${p[1]}`).join(' '));
    line.setAttribute('fill', 'none');
    line.setAttribute('stroke', readable(path.colours[stroke.operation] || '#000'));
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
    `Sheet ${sheet}: ${path.strokes.length} strokes, ${length(path.burn_length, state.jobs.find((known) => known.id === jobId))} burnt, about ${duration(path.seconds)} to cut.`;
  const legend = $('sheet-legend');
  legend.replaceChildren();
  for (const [operation, colour] of Object.entries(path.colours)) {
    if (!path.strokes.some((stroke) => stroke.operation === operation)) continue;
    legend.append(element('span', {}, element('span', { class: 'swatch', style: `background:${readable(colour)}` }), ` ${operation}`));
  }
  highlightStroke();
}

// The sheet's colour on the page.
const kSheetColour = '#fbfaf7';

// WCAG 2's relative luminance of "#rrggbb", and the contrast ratio of two.
function luminance(colour) {
  const value = parseInt(colour.slice(1), 16);
  const linear = (c) => (c <= 0.03928 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);
  return 0.2126 * linear(((value >> 16) & 255) / 255) + 0.7152 * linear(((value >> 8) & 255) / 255) +
    0.0722 * linear((value & 255) / 255);
}
export function contrast(a, b) {
  const [light, dark] = [luminance(a), luminance(b)].sort((x, y) => y - x);
  return (light + 0.05) / (dark + 0.05);
}

// The machine's colour for an operation, darkened (its hue kept) until it
// stands out from the sheet by WCAG's 3:1 for graphics: the yellow of an
// etch reads as a dark gold.
function readable(colour) {
  const value = parseInt(colour.slice(1), 16);
  let [r, g, b] = [(value >> 16) & 255, (value >> 8) & 255, value & 255];
  const hex = () => `#${[r, g, b].map((c) => Math.round(c).toString(16).padStart(2, '0')).join('')}`;
  while (contrast(hex(), kSheetColour) < 3 && r + g + b > 0) [r, g, b] = [r * 0.9, g * 0.9, b * 0.9];
  return hex();
}

// The stroke being cut (progress counts those finished), the ones before it faded.
export function highlightStroke() {
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
