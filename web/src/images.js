// The images of a render study: the reference, and per estimator the image of its latest level
// (replicate 0) with its false-colour relative error against the reference, updated as levels
// finish; before a run, a quick image of the scene. A pure render of the state (state.run,
// state.scenePreview) into #render-images; the PNGs come base64-encoded from the render core
// (options.previews). An <img> gets a new src only when its picture changed.
import { colorAt } from './palette.js';
import { el } from './dom.js';
import { referenceText } from './state.js';

const PNG = 'data:image/png;base64,';

let layoutSig = null;
const shown = new Map(); // img key -> base64 last set

function setImage(img, key, base64) {
  if (!img) return;
  const want = base64 || null;
  if (shown.get(key) === want) return;
  shown.set(key, want);
  if (want) {
    img.src = PNG + want;
    img.hidden = false;
    img.dataset.drawn = 'true';
  } else {
    img.removeAttribute('src');
    img.hidden = true;
    img.dataset.drawn = 'false';
  }
}

function picture(role, name, caption, alt) {
  const img = el('img', { alt, className: 'render-image', hidden: true, dataset: { role, estimator: name || '', drawn: 'false' } });
  // A button around it: a click (or Enter) enlarges the image (main.js opens #image-zoom).
  const zoom = el('button', { type: 'button', className: 'zoom-button', title: 'enlarge', ariaLabel: `Enlarge: ${alt}` }, img);
  return el('figure', { className: 'render-figure', dataset: { kind: role } }, zoom,
    el('figcaption', { className: 'cap', dataset: { caption: role } }, caption));
}

/**
 * The whole factor an image of w pixels is scaled up by: at least 256 px on screen (one square
 * per pixel, no smoothing), never scaled down.
 */
export function imageScale(w) {
  return Math.max(1, Math.ceil(256 / Math.max(1, w)));
}

/** The whole factor that fits a w x h image into a box of boxW x boxH pixels (at least 1). */
export function zoomScale(w, h, boxW, boxH) {
  return Math.max(1, Math.floor(Math.min(boxW / Math.max(1, w), boxH / Math.max(1, h))));
}

function colorOf(run, name) {
  return colorAt(run.colors && name in run.colors ? run.colors[name] : run.order.indexOf(name));
}

/** A card's downloads: its image as PNG (tone-mapped, as shown) and as Radiance HDR (linear). */
function exports(which, label) {
  const button = (format, text, title) => el('button', {
    type: 'button', className: 'png', disabled: true, title, ariaLabel: `${title}: ${label}`,
    dataset: { exportImage: which, format },
  }, text);
  return el('div', { className: 'image-exports' },
    button('png', 'PNG', 'download the image as PNG (tone-mapped sRGB, as shown)'),
    button('hdr', 'HDR', 'download the image as Radiance HDR (linear radiance)'),
    which === 'reference' ? null : button('error', 'error PNG', 'download the relative-error image as PNG'));
}

/** The cards: the reference (or the scene's quick preview), then one per estimator of the run. */
function layout(container, run, size) {
  const cards = [el('div', { className: 'image-card', dataset: { card: 'reference' } },
    el('h3', {}, el('span', { dataset: { title: 'reference' } }, 'Reference'), el('span', { className: 'muted small', dataset: { info: 'reference' } }, '')),
    el('div', { className: 'pair' }, picture('reference', '', 'reference image', 'reference image')),
    exports('reference', 'the reference'),
    el('p', { className: 'cap', dataset: { wait: 'reference' } }, ''))];
  for (const name of run.order) {
    cards.push(el('div', { className: 'image-card', dataset: { card: name } },
      el('h3', {}, el('span', { className: 'swatch', style: `background: ${colorOf(run, name)}` }), name,
        el('span', { className: 'muted small', dataset: { info: name } }, '')),
      el('div', { className: 'pair' },
        picture('preview', name, 'image (replicate 0)', `${name}: image of the latest level`),
        picture('error', name, '|relative error|', `${name}: relative error against the reference`)),
      exports(name, name)));
  }
  container.replaceChildren(...cards);
  container.style.setProperty('--image-width', `${size}px`);
}

/**
 * The panel's own controls, wired once: "Show" (image, relative error or both per card: a data
 * attribute the stylesheet reads; the pictures keep their sources) and the enlarged view (a
 * click on an image opens #image-zoom with it at the largest whole factor that fits).
 */
export function mountImages(dom, onExport = () => {}) {
  dom.images.addEventListener('click', (e) => {
    const b = e.target && e.target.closest ? e.target.closest('button[data-export-image]') : null;
    if (b && !b.disabled) onExport(b.dataset.exportImage, b.dataset.format);
  });
  const view = document.querySelector('.image-view');
  if (view) {
    view.addEventListener('change', (e) => {
      if (e.target && e.target.name === 'image-view') dom.images.dataset.view = e.target.value;
    });
  }
  const dialog = document.getElementById('image-zoom');
  const big = document.getElementById('zoom-image');
  const caption = document.getElementById('zoom-caption');
  if (!dialog || !big) return;
  dom.images.addEventListener('click', (e) => {
    const button = e.target && e.target.closest ? e.target.closest('.zoom-button') : null;
    const img = button && button.querySelector('img');
    if (!img || !img.src || img.hidden) return;
    big.src = img.src;
    big.alt = img.alt;
    const card = button.closest('.image-card');
    const title = card && card.querySelector('h3') ? card.querySelector('h3').textContent.trim() : '';
    const cap = button.closest('figure') && button.closest('figure').querySelector('figcaption');
    caption.textContent = `${title}${cap && cap.textContent ? ` · ${cap.textContent}` : ''} · ${img.naturalWidth}×${img.naturalHeight} px`;
    const k = zoomScale(img.naturalWidth, img.naturalHeight, window.innerWidth * 0.9, window.innerHeight * 0.8);
    big.style.width = `${img.naturalWidth * k}px`;
    if (typeof dialog.showModal === 'function') dialog.showModal();
    else dialog.setAttribute('open', '');
  });
}

/** The view the images panel's "Show" choice gives: 'image', 'error' or 'both'. */
export function imageView() {
  const checked = document.querySelector('input[name="image-view"]:checked');
  return checked ? checked.value : 'image';
}

/** Sets the "Show" choice (a shared link's): the radio button and what the cards show. */
export function setImageView(value) {
  const radio = [...document.querySelectorAll('input[name="image-view"]')].find((r) => r.value === value);
  if (!radio) return;
  radio.checked = true;
  const grid = document.getElementById('render-images');
  if (grid) grid.dataset.view = value;
}

/** Draws the images of state.run into dom.images (the #render-images grid). */
export function renderImages(state, dom) {
  if (!dom.images) return;
  const run = state.run;
  const render = state.sceneInfo && state.sceneInfo.kind === 'render';
  if (!render) {
    if (layoutSig !== null) {
      dom.images.replaceChildren();
      layoutSig = null;
      shown.clear();
    }
    return;
  }
  const order = run.kind === 'render' ? run.order : [];
  const w = (run.kind === 'render' && run.settings && run.settings.width) || state.params.width || 64;
  // Small images are scaled up by whole factors (pixelated), to at least 256 px.
  const size = w * imageScale(w);
  const sig = JSON.stringify([run.id, order, run.colors, size]);
  if (sig !== layoutSig) {
    layoutSig = sig;
    shown.clear();
    layout(dom.images, { ...run, order }, size);
  }
  const q = (sel) => dom.images.querySelector(sel);

  // The reference: the study's, else the quick image of the scene (before or during a run).
  const preview = state.scenePreview;
  const refPng = run.kind === 'render' ? run.referencePng : null;
  const ref = refPng || (preview && preview.png) || null;
  setImage(q('img[data-role="reference"]'), 'reference', ref);
  const refInfo = q('[data-info="reference"]');
  const wait = q('[data-wait="reference"]');
  let info = '';
  let waitText = '';
  if (refPng) {
    const r = run.result && run.result.scene && run.result.scene.reference;
    info = r && r.spp ? ` ${r.spp} spp${r.estimator ? `, ${r.estimator.strategy}` : ''}${r.source === 'supplied' ? ', shipped with the site' : ''}` : '';
  } else if (preview && preview.png) {
    info = ` ${preview.estimator}, ${preview.spp} spp`;
    const doing = referenceText(run);
    waitText = run.status === 'running' ? `${doing[0].toUpperCase()}${doing.slice(1)}; it is shown here with the first level.`
      : 'Press Run: the study compares every image with a reference rendered at many spp.';
  } else {
    waitText = preview && preview.status === 'error' ? `No image: ${preview.message}` : 'Rendering a quick image of the scene…';
  }
  if (refInfo && refInfo.textContent !== info) refInfo.textContent = info;
  if (wait && wait.textContent !== waitText) wait.textContent = waitText;
  const title = q('[data-title="reference"]');
  const titleText = refPng || !(preview && preview.png) ? 'Reference' : 'The scene';
  if (title && title.textContent !== titleText) title.textContent = titleText;
  const caption = q('[data-caption="reference"]');
  const captionText = refPng ? 'the study\'s reference image' : preview && preview.png ? 'a quick image, not the reference' : '';
  if (caption && caption.textContent !== captionText) caption.textContent = captionText;

  const enable = (which, format, on) => {
    const b = q(`button[data-export-image="${CSS.escape(which)}"][data-format="${format}"]`);
    if (b && b.disabled === on) b.disabled = !on;
  };
  // The reference's files once the study has it (a quick preview is not the reference).
  enable('reference', 'png', Boolean(refPng));
  enable('reference', 'hdr', Boolean(refPng) && run.status !== 'running');
  for (const name of order) {
    const r = run.records[name];
    enable(name, 'png', Boolean(r && r.preview_png));
    enable(name, 'hdr', Boolean(r && r.preview_png) && run.status !== 'running');
    enable(name, 'error', Boolean(r && r.error_png));
    setImage(q(`img[data-role="preview"][data-estimator="${CSS.escape(name)}"]`), `preview:${name}`, r && r.preview_png);
    setImage(q(`img[data-role="error"][data-estimator="${CSS.escape(name)}"]`), `error:${name}`, r && r.error_png);
    const last = r && r.levels.length ? r.levels[r.levels.length - 1] : null;
    const text = last ? ` ${last.n} spp` : run.status === 'running' ? ' waiting for the first level…' : '';
    const span = q(`[data-info="${CSS.escape(name)}"]`);
    if (span && span.textContent !== text) span.textContent = text;
  }
}
