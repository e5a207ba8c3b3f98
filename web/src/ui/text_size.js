// The large-text mode, for a projector (1024 x 768) or a reader who wants it: every text of the
// page at least LARGE_MIN_PX CSS pixels, the plots' canvas-drawn ticks, titles and labels
// included. A toggle in the header says so; the choice is remembered (localStorage). The CSS
// half is style.css's --min-text (16px under html.large-text); the canvas half is textPx(),
// read whenever a plot sets a font. No DOM at import (web/test imports the plot modules).

export const LARGE_MIN_PX = 16;
const KEY = 'mcplay.largeText';
let large = false;
const listeners = new Set();

/** Is the large-text mode on? */
export const largeText = () => large;

/** A font size in CSS pixels for text drawn on a canvas: at least LARGE_MIN_PX in large-text
 *  mode, else `px` unchanged. */
export function textPx(px) {
  return large ? Math.max(px, LARGE_MIN_PX) : px;
}

/** Calls fn() after every change of the mode (the plots rebuild their fonts). */
export function onTextSize(fn) {
  listeners.add(fn);
  return () => listeners.delete(fn);
}

function storage() {
  try {
    return window.localStorage;
  } catch {
    return null; // storage refused (a sandboxed frame, privacy settings): the mode is not kept
  }
}

/** Sets the mode (html.large-text), remembers it, and tells the listeners when it changed. */
export function setLargeText(on) {
  const next = Boolean(on);
  document.documentElement.classList.toggle('large-text', next);
  try {
    storage()?.setItem(KEY, next ? '1' : '0');
  } catch { /* full or refused: the mode still applies to this page */ }
  if (next === large) return;
  large = next;
  for (const fn of listeners) fn(large);
}

/** Reads the remembered mode and wires the toggle (a checkbox). */
export function mountLargeText(toggle) {
  let saved = null;
  try {
    saved = storage()?.getItem(KEY) ?? null;
  } catch { /* refused */ }
  setLargeText(saved === '1');
  if (!toggle) return;
  toggle.checked = large;
  toggle.addEventListener('change', () => setLargeText(toggle.checked));
}
