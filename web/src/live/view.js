// The live view's DOM: its controls dispatch actions to the view's store (model.js), syncLive()
// writes the state back into them, renderLive() draws what changed in one animation frame: each
// image (tone-mapped, or its relative error map) with putImageData at its own size, scaled up by
// the zoom without smoothing; the wipe (two canvases, the right one clipped); the curves
// (charts.js). The pixels live in wiring.js (`px`), not in the state.
import { el } from '../dom.js';
import { colorAt } from '../palette.js';
import {
  LONG_SIDES, LIVE_SAMPLERS, SAMPLER_WHY, MAX_SPP_CHOICES, MAX_LIVE_ESTIMATORS, toneMap, errorMap, wipeClip,
  wipeFromPointer, commonSpp, zoomStep, duration, liveActive, relmseText, compareText,
} from './model.js';
import { renderLiveCharts } from './charts.js';

const $ = (id) => document.getElementById(id);

function option(value, text) {
  const o = document.createElement('option');
  o.value = String(value);
  o.textContent = text;
  return o;
}

/** Wires the controls once. `hooks`: {start(), pause(), resume(), cancel(), runStudy()}. */
export function mountLive(store, hooks) {
  const { dispatch } = store;
  $('live-size').replaceChildren(...LONG_SIDES.map((n) => option(n, `${n}${n === 256 ? ' (default)' : ''}`)));
  $('live-sampler').replaceChildren(...LIVE_SAMPLERS.map((n) => option(n, n === 'padded_sobol' ? 'padded_sobol (Owen-scrambled Sobol\')' : 'independent')));
  $('live-sampler').title = SAMPLER_WHY;
  $('live-sampler-why').textContent = SAMPLER_WHY;
  $('live-max').replaceChildren(...MAX_SPP_CHOICES.map((n) => option(n, String(n))));
  $('live-size').addEventListener('change', (e) => dispatch({ type: 'live/choose', payload: { longSide: Number(e.target.value) } }));
  $('live-sampler').addEventListener('change', (e) => dispatch({ type: 'live/choose', payload: { sampler: e.target.value } }));
  $('live-max').addEventListener('change', (e) => dispatch({ type: 'live/choose', payload: { maxSpp: Number(e.target.value) } }));
  $('live-estimators').addEventListener('change', () => {
    const chosen = [...$('live-estimators').querySelectorAll('input:checked')].map((b) => b.value);
    dispatch({ type: 'live/choose', payload: { estimators: chosen } });
  });
  $('live-form').addEventListener('submit', (e) => {
    e.preventDefault();
    hooks.start();
  });
  $('live-pause').addEventListener('click', () => {
    if (store.getState().status === 'paused') hooks.resume();
    else hooks.pause();
  });
  $('live-cancel').addEventListener('click', () => hooks.cancel());
  $('live-run-study').addEventListener('click', () => hooks.runStudy());
  $('live-errors').addEventListener('change', (e) => dispatch({ type: 'live/view', payload: { errors: e.target.checked } }));
  const zoom = (dir) => dispatch({ type: 'live/view', payload: { zoom: zoomStep(store.getState().view.zoom, dir) } });
  $('live-zoom-in').addEventListener('click', () => zoom(1));
  $('live-zoom-out').addEventListener('click', () => zoom(-1));
  for (const box of [$('live-images'), $('live-wipe-box')]) {
    box.addEventListener('wheel', (e) => {
      if (!e.target.closest('canvas')) return;
      e.preventDefault();
      zoom(e.deltaY < 0 ? 1 : -1);
    }, { passive: false });
  }
  $('live-wipe-a').addEventListener('change', (e) => dispatch({ type: 'live/view', payload: { wipeA: e.target.value } }));
  $('live-wipe-b').addEventListener('change', (e) => dispatch({ type: 'live/view', payload: { wipeB: e.target.value } }));
  $('live-wipe').addEventListener('input', (e) => dispatch({ type: 'live/view', payload: { wipe: Number(e.target.value) } }));
  // dragging over the wipe moves it too (the range input is its keyboard control)
  const box = $('live-wipe-box');
  const drag = (e) => {
    const r = box.getBoundingClientRect();
    dispatch({ type: 'live/view', payload: { wipe: Math.round(wipeFromPointer(e.clientX, r.left, r.width)) } });
  };
  box.addEventListener('pointerdown', (e) => {
    box.setPointerCapture(e.pointerId);
    drag(e);
  });
  box.addEventListener('pointermove', (e) => {
    if (box.hasPointerCapture(e.pointerId)) drag(e);
  });
}

let estimatorsSig = null;

/** Writes the state into the controls. `scene`: {names (the scene's estimators), render}. */
export function syncLive(live, scene) {
  $('live-section').hidden = !scene.render;
  if (!scene.render) return;
  const chosen = live.choice.estimators || [];
  const sig = JSON.stringify(scene.names);
  if (sig !== estimatorsSig) {
    estimatorsSig = sig;
    $('live-estimators').replaceChildren(...scene.names.map((n, i) => {
      const box = el('input', { type: 'checkbox', value: n, id: `live-est-${i}` });
      return el('label', { htmlFor: box.id }, box, el('span', { className: 'swatch', style: `background:${colorAt(i)}` }), n);
    }));
  }
  const full = chosen.length >= MAX_LIVE_ESTIMATORS;
  for (const box of $('live-estimators').querySelectorAll('input')) {
    box.checked = chosen.includes(box.value);
    box.disabled = full && !box.checked;
  }
  const set = (id, v) => {
    if ($(id).value !== String(v)) $(id).value = String(v);
  };
  set('live-size', live.choice.longSide);
  set('live-sampler', live.choice.sampler);
  set('live-max', live.choice.maxSpp);
  const active = liveActive(live);
  $('live-start').disabled = !chosen.length;
  $('live-start').textContent = active ? 'Restart' : 'Start';
  $('live-pause').disabled = !(live.status === 'running' || live.status === 'paused');
  $('live-pause').textContent = live.status === 'paused' ? 'Resume' : 'Pause';
  $('live-cancel').disabled = !active;
  const names = ['reference', ...live.order];
  for (const id of ['live-wipe-a', 'live-wipe-b']) {
    const want = JSON.stringify(names);
    if ($(id).dataset.sig !== want) {
      $(id).dataset.sig = want;
      $(id).replaceChildren(...names.map((n) => option(n, n)));
    }
  }
  if (live.view.wipeA) set('live-wipe-a', live.view.wipeA);
  if (live.view.wipeB) set('live-wipe-b', live.view.wipeB);
  set('live-wipe', live.view.wipe);
  $('live-errors').checked = live.view.errors;
  $('live-zoom').textContent = `${live.view.zoom}×`;
}

function statusText(live) {
  const s = live.status;
  if (s === 'idle') return 'not started';
  if (s === 'starting') return 'opening the sessions…';
  if (s === 'error') return 'error';
  const spp = live.order.map((n) => live.estimators[n].spp);
  const lo = spp.length ? Math.min(...spp) : 0;
  const what = lo ? `${lo} spp` : 'first pass…';
  return { running: `running: ${what}`, paused: `paused at ${what}`, done: `done: ${what}`, cancelled: `cancelled at ${what}` }[s] || s;
}

// ---------------------------------------------------------------------------------------------
// Drawing

let layoutSig = null;
const drawn = new Map(); // canvas key -> what it shows (name, spp, mode)
let zoomShown = null;

function card(key, title, color, w, h) {
  const canvas = el('canvas', { className: 'live-canvas', width: w, height: h, role: 'img', ariaLabel: `${title}: no image yet` });
  canvas.dataset.live = key;
  return el('figure', { className: 'live-card', dataset: { card: key } },
    el('figcaption', {}, color ? el('span', { className: 'swatch', style: `background:${color}` }) : null,
      el('span', { className: 'name' }, title), el('span', { className: 'facts', dataset: { facts: key } }, '')),
    el('div', { className: 'live-scroll' }, canvas));
}

function layout(live, px) {
  const cards = [card('reference', 'Reference', null, px.width, px.height),
    ...live.order.map((n) => card(n, n, colorAt(live.colors[n] ?? 0), px.width, px.height))];
  $('live-images').replaceChildren(...cards);
  for (const id of ['live-wipe-left', 'live-wipe-right']) {
    $(id).width = px.width;
    $(id).height = px.height;
  }
  drawn.clear();
  zoomShown = null;
}

/** RGBA of an image (tone-mapped, or its error map against the reference) into a canvas. */
function paint(canvas, rgb, ref, errors, exposure) {
  const ctx = canvas.getContext('2d');
  const img = ctx.createImageData(canvas.width, canvas.height);
  if (errors && ref) errorMap(rgb, ref, img.data);
  else toneMap(rgb, img.data, exposure);
  ctx.putImageData(img, 0, 0);
}

/** The pixels of `name` at `spp` (null spp: its latest), or null. */
function imageAt(px, name, spp = null) {
  if (name === 'reference') return px.reference;
  const im = px.images.get(name);
  if (!im) return null;
  return spp === null ? im.rgb : im.history.get(spp) || null;
}

/** Draws what changed since the last frame; `px` is wiring.js's pixel store. */
export function renderLive(live, px, dom) {
  $('live-status').textContent = statusText(live);
  $('live-error').textContent = live.status === 'error' ? live.message : '';
  $('live-notice').textContent = live.notice || '';
  $('live-workers').textContent = live.workers
    ? `${live.workers} worker${live.workers > 1 ? 's' : ''}, each image split in ${px.bands || '…'} row bands${px.width ? `; ${px.width} × ${px.height} pixels` : ''}`
    : '';
  const ref = live.reference;
  $('live-ref-block').hidden = ref.status !== 'rendering';
  $('live-ref-progress').value = ref.progress || 0;
  $('live-ref-text').textContent = ref.status === 'ready'
    ? `Reference: ${ref.spp ? `${ref.spp} spp, ` : ''}${ref.source === 'supplied' || ref.source === 'shipped' ? 'shipped with the site' : ref.source === 'rendered' ? 'rendered in the background' : ref.source || 'ready'}.`
    : ref.status === 'rendering' ? `Rendering the reference at ${px.width} × ${px.height} in the background (${Math.round(100 * (ref.progress || 0))}%): the curves start once it is done.`
      : ref.status === 'error' ? `No reference: ${ref.message || 'it failed'}` : '';
  $('live-error-note').hidden = !live.view.errors;
  if (!px.width) return;
  const sig = JSON.stringify([live.id, live.order, px.width, px.height]);
  if (sig !== layoutSig) {
    layoutSig = sig;
    layout(live, px);
  }
  if (zoomShown !== live.view.zoom) {
    zoomShown = live.view.zoom;
    for (const c of document.querySelectorAll('#live-section canvas.live-canvas')) {
      c.style.width = `${px.width * zoomShown}px`;
      c.style.height = `${px.height * zoomShown}px`;
    }
  }
  // the cards: each canvas redrawn when its image, its spp or the mode changed
  for (const key of ['reference', ...live.order]) {
    const canvas = document.querySelector(`canvas[data-live="${CSS.escape(key)}"]`);
    const rgb = imageAt(px, key);
    const errors = live.view.errors && key !== 'reference' && Boolean(px.reference);
    const what = rgb ? `${key === 'reference' ? 'ref' : px.images.get(key).spp}:${errors}` : null;
    if (canvas && rgb && drawn.get(key) !== what) {
      drawn.set(key, what);
      paint(canvas, rgb, px.reference, errors, px.exposure);
      canvas.dataset.spp = key === 'reference' ? '' : String(px.images.get(key).spp);
      canvas.setAttribute('aria-label', key === 'reference' ? `reference image, ${px.width} by ${px.height} pixels`
        : `${key}: ${errors ? 'relative error map' : 'image'} at ${px.images.get(key).spp} spp`);
    }
    const facts = document.querySelector(`[data-facts="${CSS.escape(key)}"]`);
    if (!facts) continue;
    let text = '';
    if (key === 'reference') text = px.reference ? (ref.spp ? `${ref.spp} spp` : '') : ref.status === 'rendering' ? 'rendering…' : 'none yet';
    else {
      const e = live.estimators[key];
      const last = e && e.points.length ? e.points[e.points.length - 1] : null;
      const rel = last && last.spp === e.spp ? last.relmse : null;
      // the relative MSE less the reference's own variance: below the reference's own noise the
      // image is as close to the truth as the reference can tell, and has no number
      const relText = rel === null ? '' : ` · relMSE ${relmseText(rel, ref.floor)}`;
      text = e && e.spp ? `${e.spp} spp · ${duration(e.seconds)}${relText}` : 'waiting…';
    }
    if (facts.textContent !== text) facts.textContent = text;
    const tip = key === 'reference' ? 'the reference the relative MSE is measured against'
      : `seconds: the sum of this image's bands' own rendering seconds (one thread each) divided by the ${live.workers} workers`;
    if (facts.title !== tip) facts.title = tip;
  }
  // the wipe: both sides at the largest spp they share
  const a = live.view.wipeA;
  const b = live.view.wipeB;
  const levels = (n) => (n === 'reference' ? null : px.images.has(n) ? [...px.images.get(n).history.keys()].sort((x, y) => x - y) : []);
  if (a && b) {
    const spp = commonSpp(levels(a), levels(b));
    const sppOf = (n) => (n === 'reference' ? null : spp);
    const sides = [[$('live-wipe-left'), a], [$('live-wipe-right'), b]];
    for (const [canvas, name] of sides) {
      const rgb = spp === null ? null : imageAt(px, name, sppOf(name));
      const errors = live.view.errors && name !== 'reference' && Boolean(px.reference);
      const what = rgb ? `${name}:${sppOf(name)}:${errors}` : null;
      if (rgb && drawn.get(canvas.id) !== what) {
        drawn.set(canvas.id, what);
        paint(canvas, rgb, px.reference, errors, px.exposure);
        canvas.dataset.spp = String(sppOf(name) ?? '');
        canvas.setAttribute('aria-label', `${canvas.id === 'live-wipe-left' ? 'left' : 'right'} of the wipe: ${name}${sppOf(name) ? ` at ${spp} spp` : ''}`);
      }
    }
    const out = spp === null ? 'no common spp yet' : spp === Infinity ? 'both: the reference' : `both at ${spp} spp`;
    if ($('live-wipe-spp').textContent !== out) $('live-wipe-spp').textContent = out;
  }
  const clip = wipeClip(live.view.wipe);
  if ($('live-wipe-right').style.clipPath !== clip) $('live-wipe-right').style.clipPath = clip;
  $('live-wipe-line').style.left = `${live.view.wipe}%`;
  // the curves and their legend
  const counts = renderLiveCharts(dom, live);
  for (const [id, c] of [['live-plot-spp', counts.spp], ['live-plot-seconds', counts.seconds]]) {
    $(id).dataset.points = String(c.points);
    $(id).dataset.noise = String(c.noise);
    $(id).dataset.lowest = c.lowest === null ? '' : String(c.lowest);
  }
  const compare = compareText(live.order, live.estimators, ref.floor);
  if ($('live-compare').textContent !== compare) $('live-compare').textContent = compare;
  const legendSig = JSON.stringify(live.order);
  if ($('live-legend').dataset.sig !== legendSig) {
    $('live-legend').dataset.sig = legendSig;
    $('live-legend').replaceChildren(...live.order.map((n) => el('li', {},
      el('span', { className: 'swatch', style: `background:${colorAt(live.colors[n] ?? 0)}` }), el('span', { className: 'name' }, n))));
  }
}
