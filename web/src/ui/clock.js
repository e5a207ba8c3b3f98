// The clock banner (#clock-banner, above the plots) and the clock's clauses in the static notes of
// the time plot (#time-clock-note) and the race card (#race-clock-note), from clockClaim
// (claims/clock.js) of the run worker's measured step and cross-origin isolation. Written only
// when the clock changes; before the worker has answered, the static texts stay.
import { clockClaim } from '../claims.js';

let last = null;

export function syncClock(state) {
  if (state.isolated === null && state.clockStep === null) return; // not measured yet
  const key = `${state.clockStep}|${state.isolated}`;
  if (key === last) return;
  last = key;
  const claim = clockClaim({ stepMs: state.clockStep, isolated: state.isolated });
  const banner = document.getElementById('clock-banner');
  if (banner) {
    banner.textContent = claim.banner || '';
    banner.hidden = !claim.banner;
    banner.dataset.severity = claim.severity;
  }
  const timeNote = document.getElementById('time-clock-note');
  if (timeNote) timeNote.textContent = claim.timeNote;
  const raceNote = document.getElementById('race-clock-note');
  if (raceNote) raceNote.textContent = claim.raceNote;
}
