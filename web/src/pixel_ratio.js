// Exports at a chosen pixel ratio. uPlot 1.6 reads the device's pixel ratio (devicePixelRatio)
// when it loads and again only when a resolution media query it watches changes; its charts then
// draw again at the new ratio (same size on screen, more device pixels). This module, imported
// before uPlot, keeps those media-query listeners and lets withPixelRatio(k, fn) present k as the
// device's ratio, tell uPlot (its own listener: the charts redraw), run fn, and put the device's
// ratio back. Nothing changes on screen but the canvases' resolution while fn runs.

const resolutionListeners = new Set();
let forced = null;

if (typeof window !== 'undefined' && typeof window.matchMedia === 'function') {
  const own = Object.getOwnPropertyDescriptor(window, 'devicePixelRatio')
    || Object.getOwnPropertyDescriptor(Object.getPrototypeOf(window), 'devicePixelRatio');
  const deviceRatio = () => (own && own.get ? own.get.call(window) : own ? own.value : 1) || 1;
  try {
    Object.defineProperty(window, 'devicePixelRatio', {
      configurable: true, enumerable: true, get: () => forced ?? deviceRatio(),
    });
  } catch {
    // a browser that refuses: exports stay at the device's ratio
  }
  const matchMedia = window.matchMedia.bind(window);
  window.matchMedia = (query) => {
    const list = matchMedia(query);
    if (/resolution/.test(String(query))) {
      const add = list.addEventListener.bind(list);
      const remove = list.removeEventListener.bind(list);
      list.addEventListener = (type, fn, options) => {
        if (type === 'change') resolutionListeners.add(fn);
        add(type, fn, options);
      };
      list.removeEventListener = (type, fn, options) => {
        if (type === 'change') resolutionListeners.delete(fn);
        remove(type, fn, options);
      };
    }
    return list;
  };
}

function announce() {
  for (const fn of [...resolutionListeners]) fn();
}

/** The device's pixel ratio (not a forced one). */
export function devicePixelRatioNow() {
  const k = forced;
  forced = null;
  const r = window.devicePixelRatio || 1;
  forced = k;
  return r;
}

/**
 * Runs fn (which may return a promise) with `ratio` as the device's pixel ratio: uPlot's charts
 * redraw at it first (awaited: uPlot draws in a microtask), and again at the device's after.
 */
export async function withPixelRatio(ratio, fn) {
  if (typeof window === 'undefined' || !resolutionListeners.size) return fn();
  forced = ratio;
  announce();
  try {
    await new Promise((resolve) => requestAnimationFrame(() => resolve()));
    return await fn();
  } finally {
    forced = null;
    announce();
  }
}
