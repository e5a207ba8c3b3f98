// The custom problem: f and p typed as expressions, and its exact value if known. Events only
// dispatch (edit, apply); the scene is built and validated by the core in a worker (main.js).
// sync(state) shows the core's parse error inline: the message in #custom-error, the offending
// field marked invalid, and the expression repeated under it with the reported position
// highlighted.
import { inputErrorWords } from '../claims.js';

const $ = (id) => document.getElementById(id);

export function mountCustom(store) {
  const { dispatch } = store;
  for (const field of ['f', 'p', 'exact']) {
    const input = $(`custom-${field}`);
    input.addEventListener('input', () => dispatch({ type: 'custom/edit', payload: { field, value: input.value } }));
    // Enter applies the problem (instead of submitting the form, which would start a run).
    input.addEventListener('keydown', (e) => {
      if (e.key === 'Enter') {
        e.preventDefault();
        dispatch({ type: 'custom/apply' });
      }
    });
  }
  $('custom-apply').addEventListener('click', () => dispatch({ type: 'custom/apply' }));
}

/** The expression with the 1-based `position` wrapped in <mark> (a marked blank past its end). */
function markAt(pre, text, position) {
  const i = Math.max(0, Math.min(text.length, position - 1));
  const mark = document.createElement('mark');
  mark.textContent = i < text.length ? text[i] : ' ';
  const caret = `${' '.repeat(i)}^ position ${position}`;
  pre.replaceChildren(text.slice(0, i), mark, text.slice(i + 1), `\n${caret}`);
}

let shownError = null;

export function syncCustom(state) {
  const c = state.custom;
  for (const field of ['f', 'p', 'exact']) {
    const input = $(`custom-${field}`);
    if (document.activeElement !== input && input.value !== c[field]) input.value = c[field];
  }
  $('custom-apply').disabled = c.pending;
  const err = c.error;
  if (err === shownError) return;
  shownError = err;
  $('custom-error').textContent = err ? inputErrorWords(err.message, err.field) : '';
  $('custom-exact').setAttribute('aria-invalid', String(Boolean(err && err.field === 'exact')));
  for (const field of ['f', 'p']) {
    const input = $(`custom-${field}`);
    const pre = $(`custom-${field}-mark`);
    const bad = Boolean(err && err.field === field);
    input.setAttribute('aria-invalid', String(bad));
    if (bad && err.position) {
      markAt(pre, c[field], err.position);
      const i = Math.max(0, Math.min(input.value.length, err.position - 1));
      try { input.setSelectionRange(i, Math.min(input.value.length, i + 1)); } catch { /* not focusable yet */ }
    } else {
      pre.replaceChildren();
    }
  }
}
