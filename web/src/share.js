// The link "Copy link" gives: the comparison (state.js: stateToQuery) and how its plots were
// being looked at: the estimators hidden from the plots, the z-score histogram's N, the sample
// view's number of points, the render images' view, the race card's inputs, and run=1, which
// has the page run the study as soon as the link opens (a shared link shows its plots). The
// address bar carries the comparison only. Pure: no DOM (web/test/share.test.mjs).
import { stateToQuery, SAMPLE_SIZES, LIMITS } from './state.js';
import { RACE_DEFAULTS } from './race.js';

/** The view's keys in the link, in the order shareQuery writes them. */
export const VIEW_KEYS = Object.freeze(['hide', 'cal', 'points', 'image_view', 'race_rel', 'race_abs', 'race_runs', 'race_seconds', 'run']);

/** The render images' views (index.html's radio group "image-view"); the first is the default. */
export const IMAGE_VIEWS = Object.freeze(['image', 'error', 'both']);

// race input field -> its key in the link
const RACE_KEYS = Object.freeze({ relTol: 'race_rel', absTol: 'race_abs', runs: 'race_runs', maxSeconds: 'race_seconds' });

const NAME_RE = /^[A-Za-z0-9_.-]{1,100}$/;
const MAX_HIDDEN = 64; // hidden names a link may carry (a scene has far fewer estimators)
// What a race input may hold in a link (the race card checks the value itself).
const RACE_TEXT_RE = /^[0-9eE+.-]{0,24}$/;

function enc(value) {
  return encodeURIComponent(value).replace(/%2C/g, ',');
}

/** The view when nothing is said of it: all estimators shown, z pooled over N, 256 points. */
export function defaultView() {
  return { hidden: [], calibration: 'all', points: 256, imageView: IMAGE_VIEWS[0], race: {}, run: false };
}

/**
 * The view's part of a link ('hide=a,b&cal=1024&...'), the values that differ from the
 * defaults only, and run=1 when `run`: view is {hidden: [names], calibration: 'all' | N,
 * points, imageView, race: {relTol, absTol, runs, maxSeconds} (the card's texts), run}.
 */
export function viewToQuery(view) {
  const v = { ...defaultView(), ...(view || {}) };
  const parts = [];
  const hidden = (Array.isArray(v.hidden) ? v.hidden : []).filter((n) => NAME_RE.test(n));
  if (hidden.length) parts.push(`hide=${enc(hidden.join(','))}`);
  if (v.calibration !== 'all' && Number.isSafeInteger(v.calibration) && v.calibration > 0) parts.push(`cal=${v.calibration}`);
  if (v.points !== 256 && SAMPLE_SIZES.includes(v.points)) parts.push(`points=${v.points}`);
  if (v.imageView !== IMAGE_VIEWS[0] && IMAGE_VIEWS.includes(v.imageView)) parts.push(`image_view=${v.imageView}`);
  for (const [field, key] of Object.entries(RACE_KEYS)) {
    const text = v.race && typeof v.race[field] === 'string' ? v.race[field].trim() : null;
    if (text !== null && text !== RACE_DEFAULTS[field] && RACE_TEXT_RE.test(text)) parts.push(`${key}=${enc(text)}`);
  }
  if (v.run) parts.push('run=1');
  return parts.join('&');
}

/** The whole query of a shared link: the comparison of `state`, then `view` (viewToQuery). */
export function shareQuery(state, view) {
  const base = stateToQuery(state);
  if (!base) return '';
  const more = viewToQuery(view);
  return more ? `${base}&${more}` : base;
}

/**
 * The view a link asks for (defaultView where it says nothing or something unusable): hidden
 * estimator names as spelt (the scene decides which exist), the histogram's N (a power of two
 * in the core's range), the points of the sample view, the images' view, the race inputs it
 * gives (as texts), and whether to run at once.
 */
export function queryToView(search) {
  const out = defaultView();
  let q;
  try {
    q = new URLSearchParams(typeof search === 'string' ? search : '');
  } catch {
    return out;
  }
  const hide = q.get('hide');
  // At most MAX_HIDDEN names (a scene has far fewer estimators): a crafted link is bounded.
  if (hide !== null) out.hidden = [...new Set(hide.split(',', MAX_HIDDEN).map((s) => s.trim()).filter((s) => NAME_RE.test(s)))];
  const cal = q.get('cal');
  if (cal !== null && /^\d{1,12}$/.test(cal)) {
    const n = Number(cal);
    if (Number.isSafeInteger(n) && n >= 1 && n <= LIMITS.nMax && Number.isInteger(Math.log2(n))) out.calibration = n;
  }
  const points = Number(q.get('points'));
  if (SAMPLE_SIZES.includes(points)) out.points = points;
  const iv = q.get('image_view');
  if (IMAGE_VIEWS.includes(iv)) out.imageView = iv;
  for (const [field, key] of Object.entries(RACE_KEYS)) {
    const text = q.get(key);
    if (text !== null && RACE_TEXT_RE.test(text.trim())) out.race[field] = text.trim();
  }
  out.run = q.get('run') === '1';
  return out;
}

/** Does a query carry any of the view's keys (a link made by "Copy link")? */
export function hasView(search) {
  try {
    const q = new URLSearchParams(typeof search === 'string' ? search : '');
    return VIEW_KEYS.some((k) => q.has(k));
  } catch {
    return false;
  }
}
